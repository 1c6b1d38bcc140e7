"""Write docs/images/texture-filters.png, the README's horizon plane under each texture filter:
the built-in `checker_horizon` (a checkerboard plane to the horizon) drawn on the GPU path
(EGL, llvmpipe) at 320 x 240, one sample per pixel, with each filter on its material
(renderer/study/texture_report.py with_texture_setting), beside the report's ground truth of
the scene (renderer/study/ground_truth.py: the texture integrated over each pixel), each panel
labelled with its filter and its RMSE against that truth (linear colour in [0, 1]). The
anisotropic filter's degree 2 to 16 draws the same image on llvmpipe (its level comes from the
footprint's minor axis whatever the degree): one panel. Deterministic output (the truth takes
about a minute).

    PYTHONPATH=. .venv/bin/python tools/make_texture_figure.py
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images" / "texture-filters.png"
SIZE = (320, 240)
FILTERS = (("nearest", 1), ("bilinear", 1), ("mip-nearest", 1), ("trilinear", 1), ("anisotropic", 16))
LABEL_HEIGHT = 22


def panels() -> list[tuple[str, np.ndarray]]:
    """(label, (H, W, 3) float64 linear colour in [0, 1]) per filter, then the truth's."""
    from renderer.core.builtin import builtin_scenes
    from renderer.core.scene_file import load_scene
    from renderer.gpu import GpuRenderer
    from renderer.gpu.context import make_context
    from renderer.study.ground_truth import render_truth
    from renderer.study.texture_report import filter_name, with_texture_setting

    scene = load_scene(builtin_scenes()["checker_horizon"])
    truth = render_truth(scene, *SIZE)
    ctx = make_context("egl")
    out = []
    for setting in FILTERS:
        with GpuRenderer(with_texture_setting(scene, "filter", setting), *SIZE, context=ctx) as gpu:
            image = np.clip(gpu.render(linear=True).linear[..., :3], 0.0, 1.0)
        rmse = math.sqrt(float(np.mean((image - truth) ** 2)))
        name = "anisotropic 2 to 16" if setting[0] == "anisotropic" else filter_name(setting)
        out.append((f"{name}: RMSE {rmse:.4f}", image))
    out.append(("ground truth: texels integrated over pixels", truth))
    return out


def figure(images: list[tuple[str, np.ndarray]], columns: int = 3) -> bytes:
    """PNG bytes: the panels in rows of `columns`, each under its label."""
    from PIL import Image, ImageDraw, ImageFont

    from renderer.core.gl_rules import to_unorm8

    width, height = SIZE
    rows = math.ceil(len(images) / columns)
    sheet = Image.new("RGB", (columns * width, rows * (height + LABEL_HEIGHT)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default(size=14)
    for k, (label, image) in enumerate(images):
        x, y = (k % columns) * width, (k // columns) * (height + LABEL_HEIGHT)
        draw.text((x + 6, y + 3), label, fill=(0, 0, 0), font=font)
        sheet.paste(Image.fromarray(to_unorm8(image), "RGB"), (x, y + LABEL_HEIGHT))
    buffer = io.BytesIO()
    sheet.save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def main() -> None:
    data = figure(panels())
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_bytes(data)
    print(f"{OUT.relative_to(ROOT)}: {len(data):,} bytes")


if __name__ == "__main__":
    main()
