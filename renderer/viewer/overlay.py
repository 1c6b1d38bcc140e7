"""Text drawn over the viewer's image (help, the reference view's figures): a panel of lines
rendered on the CPU by Pillow and copied to the window like any other image
(renderer/viewer/presenter.py, CpuImage). Pillow's built-in font needs no font file on the system.
"""

from __future__ import annotations

import re
from functools import lru_cache

import numpy as np
from PIL import Image, ImageDraw, ImageFont

FONT_SIZE = 13
PADDING = 6
BACKGROUND = (20, 20, 24)
FOREGROUND = (235, 235, 235)
INDENT = 12                 # pixels for a line that starts with spaces
COLUMN_GAP = 14             # pixels between aligned columns
_CELL_BREAK = re.compile(r"(?<=\S) {2,}")     # two or more spaces end a column (help_lines)


@lru_cache(maxsize=1)
def _font() -> ImageFont.ImageFont:
    return ImageFont.load_default(size=FONT_SIZE)


def _layout(lines: list[str], font) -> list[list[tuple[int, str]]]:
    """Each line as (x, text) cells. The font is proportional, so the columns that the text
    makes with runs of spaces (renderer/viewer/controls.py's help) are aligned by measured width,
    within each block of lines that have several cells."""
    rows = [(len(line) - len(line.lstrip(" ")), _CELL_BREAK.split(line.strip())) for line in lines]
    placed: list[list[tuple[int, str]]] = []
    start = 0
    while start < len(rows):
        end = start + 1
        if len(rows[start][1]) > 1:          # a block: consecutive rows with several cells
            while end < len(rows) and len(rows[end][1]) > 1:
                end += 1
        block = rows[start:end]
        widths: dict[int, float] = {}
        for _, cells in block:
            for k, cell in enumerate(cells[:-1]):
                widths[k] = max(widths.get(k, 0.0), font.getlength(cell))
        for indent, cells in block:
            x, row = PADDING + (INDENT if indent else 0), []
            for k, cell in enumerate(cells):
                row.append((round(x), cell))
                x += widths.get(k, 0.0) + COLUMN_GAP
            placed.append(row)
        start = end
    return placed


def text_panel(lines: list[str], max_width: int, max_height: int) -> np.ndarray | None:
    """(H, W, 3) uint8: the lines on a dark opaque panel, cut to max_width x max_height
    (a small window shows what fits); None when nothing fits or there are no lines."""
    if not lines or max_width <= 2 * PADDING or max_height <= 2 * PADDING:
        return None
    font = _font()
    line_height = FONT_SIZE + 3
    rows = _layout(lines, font)
    text_width = max(x + font.getlength(text) for row in rows for x, text in row)
    width = min(max_width, int(np.ceil(text_width)) + PADDING)
    height = min(max_height, len(lines) * line_height + 2 * PADDING)
    image = Image.new("RGB", (width, height), BACKGROUND)
    draw = ImageDraw.Draw(image)
    for number, row in enumerate(rows):
        for x, text in row:
            draw.text((x, PADDING + number * line_height), text, fill=FOREGROUND, font=font)
    return np.asarray(image)
