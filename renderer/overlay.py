"""Text drawn over the viewer's image (help, the reference view's figures): a panel of lines
rendered on the CPU by Pillow and copied to the window like any other image
(renderer/presenter.py, CpuImage). Pillow's built-in font needs no font file on the system.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from PIL import Image, ImageDraw, ImageFont

FONT_SIZE = 13
PADDING = 6
BACKGROUND = (20, 20, 24)
FOREGROUND = (235, 235, 235)


@lru_cache(maxsize=1)
def _font() -> ImageFont.ImageFont:
    return ImageFont.load_default(size=FONT_SIZE)


def text_panel(lines: list[str], max_width: int, max_height: int) -> np.ndarray | None:
    """(H, W, 3) uint8: the lines on a dark opaque panel, cut to max_width x max_height
    (a small window shows what fits); None when nothing fits or there are no lines."""
    if not lines or max_width <= 2 * PADDING or max_height <= 2 * PADDING:
        return None
    font = _font()
    line_height = FONT_SIZE + 3
    text_width = max(int(np.ceil(font.getlength(line))) for line in lines)
    width = min(max_width, text_width + 2 * PADDING)
    height = min(max_height, len(lines) * line_height + 2 * PADDING)
    image = Image.new("RGB", (width, height), BACKGROUND)
    draw = ImageDraw.Draw(image)
    for row, line in enumerate(lines):
        draw.text((PADDING, PADDING + row * line_height), line, fill=FOREGROUND, font=font)
    return np.asarray(image)
