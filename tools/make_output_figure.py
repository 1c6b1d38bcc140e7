"""Write docs/images/output-methods.png, the README's one scene at 1 bit per channel in each
output method: the built-in scene SCENE drawn on the GPU path (EGL, llvmpipe) at 256 x 192, one
sample per pixel, its linear colour through the GPU output stage (renderer/gpu/output.py) with
the sRGB transfer at 1 bit per channel by each method, and beside them the frame at 8 bits
(what the file would hold without the output options) and the mistake the stage avoids,
blue noise applied to the encoded values (renderer/study/code_value_dither.py). Each panel is
labelled with the report's measures of it (renderer/study/output_report.py): the PSNR of its
luminance after the eye's low-pass and the bias of its 8 x 8 blocks' mean luminance, in levels
of 1/255. Pixels are shown 1:1 (a scaled view averages the pattern away). Deterministic.

    PYTHONPATH=. .venv/bin/python tools/make_output_figure.py
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images" / "output-methods.png"
SCENE = "coloured_lights"
SIZE = (256, 192)
METHODS = ("none", "bayer2", "bayer4", "bayer8", "blue-noise", "floyd-steinberg",
           "jarvis-judice-ninke", "halftone")
LABEL_HEIGHT = 34
COLUMNS = 5


def panels() -> list[tuple[str, np.ndarray]]:
    """(label, (H, W, 3) uint8 sRGB-encoded image) per panel."""
    from renderer.core.scene_file import load_scene
    from renderer.gpu import GpuRenderer
    from renderer.gpu.output import OutputPass
    from renderer.study.code_value_dither import code_value_dither
    from renderer.study.output_report import output_errors, output_settings

    with GpuRenderer(load_scene(SCENE), *SIZE, context_kind="egl") as gpu:
        frame = gpu.render(linear=True, depth=False)
        stage = OutputPass(gpu.ctx)
        try:
            shown = [("8 bits per channel (no output options)", frame.rgba8[..., :3])]
            for method in METHODS:
                variant = ("output", "stage", method, 1)
                codes = stage.apply(frame.linear, output_settings(variant))
                shown.append((method, codes, variant))
        finally:
            stage.release()
    variant = ("output", "code-value", "blue-noise", 1)
    shown.append(("blue noise on encoded values", code_value_dither(
        frame.linear, output_settings(variant)), variant))
    out = [shown[0]]
    for label, codes, variant in shown[1:]:
        errors = output_errors(frame.linear, codes, output_settings(variant))
        measures = (f"PSNR {errors['lowpass_psnr']:.1f} dB, bias "
                    f"{errors['block_bias'] * 255:+.1f}/255")
        out.append((f"{label}, 1 bit\n{measures}", (codes[..., :3] * 255).astype(np.uint8)))
    return out


def figure(images: list[tuple[str, np.ndarray]]) -> bytes:
    """PNG bytes: the panels in rows of COLUMNS, each under its label, 1:1."""
    from PIL import Image, ImageDraw, ImageFont

    width, height = SIZE
    rows = math.ceil(len(images) / COLUMNS)
    sheet = Image.new("RGB", (COLUMNS * width, rows * (height + LABEL_HEIGHT)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default(size=12)
    for k, (label, image) in enumerate(images):
        x, y = (k % COLUMNS) * width, (k // COLUMNS) * (height + LABEL_HEIGHT)
        draw.multiline_text((x + 5, y + 3), label, fill=(0, 0, 0), font=font, spacing=2)
        sheet.paste(Image.fromarray(np.ascontiguousarray(image), "RGB"), (x, y + LABEL_HEIGHT))
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
