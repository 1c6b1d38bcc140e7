"""Write docs/images/output-methods.png, the README's one scene at 1 bit per channel in each
output method: the built-in scene SCENE drawn on the GPU path (EGL, llvmpipe) at 256 x 192, one
sample per pixel, its linear colour through the GPU output stage (renderer/gpu/output.py) with
the sRGB transfer at 1 bit per channel by each method, and beside them the same light at 8
bits with the sRGB transfer (what the 1-bit panels approximate on an sRGB display: the frame's
own rgba8, the linear transfer, would look darker) and the mistake the stage avoids,
blue noise applied to the encoded values (renderer/study/code_value_dither.py). Each panel is
labelled with the report's measures of it (renderer/study/output_report.py): the PSNR of its
luminance after the eye's low-pass and the bias of its 8 x 8 blocks' mean luminance, in levels
of 1/255. Pixels are shown 1:1 (a scaled view averages the pattern away). Deterministic.

    PYTHONPATH=. .venv/bin/python tools/make_output_figure.py [--out PATH.png]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from contact_sheet import contact_sheet, out_option, write_figure

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
    from renderer.core.output_settings import OutputSettings, Transfer
    from renderer.core.scene_file import load_scene
    from renderer.gpu.output import OutputPass
    from renderer.methods import open_renderer
    from renderer.study.code_value_dither import code_value_dither
    from renderer.study.output_report import output_errors, output_settings

    with open_renderer(load_scene(SCENE), SIZE, context_kind="egl") as gpu:
        frame = gpu.render(linear=True, depth=False)
        stage = OutputPass(gpu.ctx)
        try:
            eight_bits = stage.apply(frame.linear, OutputSettings(transfer=Transfer("srgb"), bits=8))
            shown = [("8 bits per channel, sRGB transfer", eight_bits[..., :3].astype(np.uint8))]
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


def main(argv: list[str] | None = None) -> None:
    out = out_option(OUT, argv, "Write docs/images/output-methods.png.")
    write_figure(out, contact_sheet(panels(), COLUMNS, LABEL_HEIGHT, font_size=12), ROOT)


if __name__ == "__main__":
    main()
