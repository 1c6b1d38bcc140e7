"""The README figures' contact sheet: labelled panels in rows, pixels 1:1, written as PNG
(tools/make_texture_figure.py, tools/make_output_figure.py, tools/make_docs_images.py import it
from beside them)."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np


def contact_sheet(panels: list[tuple[str, np.ndarray]], columns: int, label_height: int,
                  font_size: int) -> bytes:
    """PNG bytes: each (label, (H, W, 3) uint8 sRGB image) under its label (lines split at
    '\\n'), in rows of `columns`; every image the size of the first."""
    from PIL import Image, ImageDraw, ImageFont

    height, width = panels[0][1].shape[:2]
    rows = math.ceil(len(panels) / columns)
    sheet = Image.new("RGB", (columns * width, rows * (height + label_height)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default(size=font_size)
    for k, (label, image) in enumerate(panels):
        x, y = (k % columns) * width, (k // columns) * (height + label_height)
        draw.multiline_text((x + 6, y + 3), label, fill=(0, 0, 0), font=font, spacing=2)
        sheet.paste(Image.fromarray(np.ascontiguousarray(image), "RGB"), (x, y + label_height))
    buffer = io.BytesIO()
    sheet.save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def write_figure(out: Path, data: bytes, root: Path) -> None:
    """Write `data` to `out` (its folder made) and say so, the path relative to `root` when
    it lies under it."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(data)
    shown = out.resolve().relative_to(root) if out.resolve().is_relative_to(root) else out
    print(f"{shown}: {len(data):,} bytes")


def out_option(default: Path, argv: list[str] | None, description: str) -> Path:
    """The path a figure script writes: its --out PATH, else `default` (tests make the
    figure again elsewhere: tests/test_docs_images.py)."""
    import argparse
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", type=Path, default=default, metavar="PATH.png",
                        help=f"the file to write (default: {default.name} in docs/images/)")
    return parser.parse_args(argv).out
