"""Write docs/images/texture-filters.png, the README's horizon plane under each texture filter:
the built-in `checker_horizon` (a checkerboard plane to the horizon) drawn on the GPU path
(EGL, llvmpipe) at 320 x 240, one sample per pixel, with each filter on its material
(renderer/study/texture_report.py with_texture_setting), beside the report's ground truth of
the scene (renderer/study/ground_truth.py: the texture integrated over each pixel), each panel
labelled with its filter and its RMSE against that truth (linear colour in [0, 1]). The
anisotropic filter's degree 2 to 16 draws the same image on llvmpipe (its level comes from the
footprint's minor axis whatever the degree): one panel. Deterministic output (the truth takes
about a minute).

    PYTHONPATH=. .venv/bin/python tools/make_texture_figure.py [--out PATH.png]
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from contact_sheet import contact_sheet, out_option, write_figure

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images" / "texture-filters.png"
SIZE = (320, 240)
FILTERS = (("nearest", 1), ("bilinear", 1), ("mip-nearest", 1), ("trilinear", 1), ("anisotropic", 16))
LABEL_HEIGHT = 22


def panels() -> list[tuple[str, np.ndarray]]:
    """(label, (H, W, 3) float64 linear colour in [0, 1]) per filter, then the truth's."""
    from renderer.core.builtin import builtin_scenes
    from renderer.core.scene_file import load_scene
    from renderer.gpu.context import make_context
    from renderer.methods import open_renderer
    from renderer.study.ground_truth import render_truth
    from renderer.study.texture_report import filter_name, with_texture_setting

    scene = load_scene(builtin_scenes()["checker_horizon"])
    truth = render_truth(scene, *SIZE)
    ctx = make_context("egl")
    out = []
    for setting in FILTERS:
        with open_renderer(with_texture_setting(scene, "filter", setting), SIZE, context=ctx) as gpu:
            image = np.clip(gpu.render(linear=True).linear[..., :3], 0.0, 1.0)
        rmse = math.sqrt(float(np.mean((image - truth) ** 2)))
        name = "anisotropic 2 to 16" if setting[0] == "anisotropic" else filter_name(setting)
        out.append((f"{name}: RMSE {rmse:.4f}", image))
    out.append(("ground truth: texels integrated over pixels", truth))
    return out


def main(argv: list[str] | None = None) -> None:
    out = out_option(OUT, argv, "Write docs/images/texture-filters.png.")
    from renderer.core.gl_rules import to_unorm8
    sheet = [(label, to_unorm8(image)) for label, image in panels()]
    write_figure(out, contact_sheet(sheet, columns=3, label_height=LABEL_HEIGHT, font_size=14), ROOT)


if __name__ == "__main__":
    main()
