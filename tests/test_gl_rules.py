"""renderer/core/gl_rules.py: GL's fixed-function rules, a hand-checked case each, and proof that
each is written in that one place (the literals it replaced appear nowhere else).

What llvmpipe itself does with these rules is checked elsewhere: the fill rule and snapping in
tests/test_rasterizer.py, depth and clip control in tests/test_extremes.py, unorm8 in
tests/test_reference_stages.py, GL_SUBPIXEL_BITS in tests/test_gpu.py.
"""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from renderer.core import gl_rules, transforms
from renderer.core.gl_rules import (REVERSED_Z_DEPTH, STANDARD_DEPTH, depth_mapping, inside_columns, is_inside_edge,
                                    is_left_or_bottom_edge, pixel_centre, snap_to_subpixel_grid,
                                    to_unorm8)

ROOT = Path(__file__).resolve().parents[1]


# --- the depth mapping ----------------------------------------------------------------------

def test_gl_default_depth_maps_minus_one_to_one_onto_zero_to_one():
    m = STANDARD_DEPTH
    assert depth_mapping(False) is m
    assert [m.window_depth(z) for z in (-1.0, 0.0, 1.0)] == [0.0, 0.5, 1.0]
    assert m.ndc_from_window == (2.0, -1.0)
    assert (m.clear_depth, m.depth_func, m.clip_control) == (1.0, "<", gl_rules.GL_NEGATIVE_ONE_TO_ONE)
    assert m.clip_z_min_w == 1.0                                  # -w <= z_clip
    assert m.depth_key(0.25) == 0.25


def test_reversed_z_keeps_z_ndc_and_tests_greater():
    m = REVERSED_Z_DEPTH
    assert depth_mapping(True) is m
    assert [m.window_depth(z) for z in (0.0, 1e-30, 1.0)] == [0.0, 1e-30, 1.0]   # z_w = z_ndc
    assert m.ndc_from_window == (1.0, 0.0)
    assert (m.clear_depth, m.depth_func, m.clip_control) == (0.0, ">", gl_rules.GL_ZERO_TO_ONE)
    assert m.clip_z_min_w == 0.0 and not np.signbit(m.clip_z_min_w)    # 0 <= z_clip, +0.0
    assert m.depth_key(0.25) == -0.25                     # GL_GREATER as GL_LESS on -z_w


@pytest.mark.parametrize("mapping", (STANDARD_DEPTH, REVERSED_Z_DEPTH), ids=lambda m: m.name)
def test_window_depth_and_its_inverse_round_trip(mapping):
    z_ndc = np.linspace(mapping.ndc_min, 1.0, 9)
    s, t = mapping.ndc_from_window
    np.testing.assert_allclose(s * mapping.window_depth(z_ndc) + t, z_ndc, atol=1e-15)


@pytest.mark.parametrize("perspective", (True, False), ids=("perspective", "parallel"))
@pytest.mark.parametrize("mapping", (STANDARD_DEPTH, REVERSED_Z_DEPTH), ids=lambda m: m.name)
def test_the_projection_puts_near_and_far_where_the_mapping_says(mapping, perspective):
    near, far = 0.5, 40.0
    row = transforms.depth_row(near, far, perspective=perspective, reversed_z=mapping.greater)
    for z_eye, expected in ((-near, mapping.ndc_near), (-far, mapping.ndc_far)):
        w = -z_eye if perspective else 1.0
        assert (row[2] * z_eye + row[3]) / w == pytest.approx(expected, abs=1e-12)
    # and window depth runs from near to far the way the depth test expects
    at_near = mapping.window_depth(mapping.ndc_near)
    assert mapping.depth_key(at_near) < mapping.depth_key(mapping.clear_depth)


# --- the sub-pixel grid and the fill rule ---------------------------------------------------

def test_snapping_rounds_to_the_nearest_256th_with_ties_to_even():
    assert gl_rules.SUBPIXEL_BITS == 8
    x = np.array([0.0, 1.0 / 512, 3.0 / 512, 1.0 / 256 + 1e-9, 2.5])
    assert snap_to_subpixel_grid(x, 8).tolist() == [0, 0, 2, 1, 640]


def test_pixel_centres_are_at_half_integers():
    assert pixel_centre(np.array([0, 1, 7]), 8).tolist() == [128, 384, 1920]      # (i + 1/2) 256


def test_fill_rule_left_and_bottom_edges_are_inclusive():
    # Counter-clockwise triangle, interior on the left of each edge.
    dx = np.array([0, 0, 3, -3, 2, -2])
    dy = np.array([-1, 1, 0, 0, 5, -5])
    #              left  right bottom top  right left
    assert is_left_or_bottom_edge(dx, dy).tolist() == [True, False, True, False, False, True]
    on_edge = np.zeros(2, dtype=np.int64)
    assert is_inside_edge(on_edge, np.array([True, False])).tolist() == [True, False]
    assert is_inside_edge(np.array([1, -1]), np.array([False, True])).tolist() == [True, False]


def test_the_fill_rule_solved_for_columns_gives_the_columns_that_pass_it():
    """inside_columns(k, b): the columns i whose centre cx = 256 i + 128 (8 bits) passes
    is_inside_edge(k - b cx). By hand: k = 640, b = 1: value 640 - cx is 0 at column 2's
    centre (640): inclusive -> columns ..2, exclusive -> ..1; b = -1, k = -640: value
    cx - 640 -> columns 2.. / 3..; b = 0: all columns for k >= 0 (inclusive), none for k = 0
    exclusive. Then every (k, b, inclusive) of a grid against testing columns -8..8."""
    lo, hi = inside_columns(np.array([640, 640, -640, -640]), np.array([1, 1, -1, -1]),
                            np.array([True, False, True, False]), 8)
    assert hi[:2].tolist() == [2, 1] and lo[2:].tolist() == [2, 3]
    lo, hi = inside_columns(np.array([0, 0]), np.array([0, 0]), np.array([True, False]), 8)
    assert hi[0] >= 8 and lo[0] <= -8 and hi[1] < lo[1]
    k, b, inclusive = (a.ravel() for a in np.meshgrid(np.arange(-3000, 3000, 37), np.arange(-700, 700, 13),
                                                       [True, False], indexing="ij"))
    lo, hi = inside_columns(k, b, inclusive, 8)
    columns = np.arange(-8, 9)
    tested = is_inside_edge(k[:, None] - b[:, None] * pixel_centre(columns, 8), inclusive[:, None])
    solved = (columns >= lo[:, None]) & (columns <= hi[:, None])
    assert (tested == solved).all()


def test_unorm8_is_round_half_up_of_the_clamped_value():
    c = np.array([-0.5, 0.5 / 255 - 1e-9, 0.5 / 255, 127.5 / 255, 1.0, 2.0])
    assert to_unorm8(c).tolist() == [0, 0, 1, 128, 255, 255]


# --- each rule in one place -----------------------------------------------------------------

# (rule, home module, pattern over code with comments and docstrings removed). Each pattern
# is a way the rule was written out before it had a home; it must not come back elsewhere.
DEFINITIONS = [
    ("clip control modes", "renderer/core/gl_rules.py", r"\b(37726|37727|0x935[EF])\b"),
    ("depth clear value", "renderer/core/gl_rules.py", r"depth=(0\.0|1\.0) if|DEPTH_CLEAR_VALUE"),
    ("depth compare", "renderer/core/gl_rules.py", r"depth_func = '[<>]'|'>' if reversed_z"),
    ("window depth", "renderer/core/gl_rules.py", r"\(z_ndc \+ 1\.0\) / 2\.0|z_ndc if reversed_z"),
    ("window depth inverse", "renderer/core/gl_rules.py", r"\(1\.0, 0\.0\) if reversed_z|\(2\.0, -1\.0\)"),
    ("depth range of clipping", "renderer/core/gl_rules.py", r"\(2, 1\.0, 0\.0\)"),
    ("sub-pixel bits", "renderer/core/gl_rules.py", r"\bSUBPIXEL_BITS = \d|subpixel_bits: int = \d"),
    ("snapping", "renderer/core/gl_rules.py", r"np\.rint\(coordinate"),
    ("fill rule", "renderer/core/gl_rules.py", r"\(dy == 0\) & \(dx > 0\)|edge_value >= 0, edge_value > 0"),
    ("unorm8", "renderer/core/gl_rules.py", r"255\.0 \+ 0\.5"),
    ("texture filter and wrap enums", "renderer/core/gl_rules.py",
     r"\b0x(2701|2703|8370|84FE)\b|\b(9985|9987|33648|34046)\b"),
    ("unorm8 texel to float", "renderer/core/gl_rules.py", r"(float32|f32)\(1 ?/ ?255(\.0)?\)"),
    ("sRGB framebuffer enums", "renderer/core/gl_rules.py", r"\b0x(8C43|8DB9)\b|\b(35907|36281)\b"),
    ("texel weight bits", "renderer/core/gl_rules.py", r"\b(TEXEL|MIP)_WEIGHT_BITS = \d"),
    ("fast log2", "renderer/core/gl_rules.py", r"\b(0x3[fF]800000|1065353216)\b"),
    ("max anisotropy", "renderer/core/gl_rules.py", r"ANISOTROPY_RANGE = \(2, 16\)|MAX_ANISOTROPY = \d"),
    ("EWA weight table", "renderer/core/gl_rules.py", r"\bWEIGHT_LUT_SIZE\b|WEIGHT_TABLE_SIZE = \d"),
    ("pipeline tolerance", "renderer/checks/tolerance.py",
     r"\b(RAW_MISMATCH_LIMIT|DEPTH_REL_LIMIT) = |DEFAULT_(THRESHOLD|DEVIATION) = \d"),
]


def code_of(source: str) -> str:
    """The source as ast.unparse writes it, without docstrings (and so without comments)."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (isinstance(body, list) and body and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str)):
            body[0] = ast.Pass()
    return ast.unparse(tree)


def redefinitions(files: dict[str, str]) -> list[str]:
    """'path: rule (pattern)' for each rule written out anywhere but its home module."""
    found = []
    for path, source in sorted(files.items()):
        code = code_of(source) if path.endswith(".py") else source
        for rule, home, pattern in DEFINITIONS:
            if path != home and re.search(pattern, code):
                found.append(f"{path}: {rule} ({re.search(pattern, code).group(0)!r}; its home is {home})")
    return found


def project_sources() -> dict[str, str]:
    paths = [*ROOT.glob("renderer/**/*.py"), *ROOT.glob("reference/**/*.py"),
             *ROOT.glob("tests/*.py"), *ROOT.glob("benchmarks/*.py")]
    return {str(p.relative_to(ROOT)): p.read_text() for p in paths
            if p.name != "test_gl_rules.py"}


def test_each_rule_is_defined_once():
    assert redefinitions(project_sources()) == []


def test_the_search_finds_the_literals_it_replaced():
    """Lines as they stood before the rules had a home: each is found, comments are not."""
    old = {
        "reference/rasterizer.py": "SUBPIXEL_BITS = 8\nz_w = z_ndc if reversed_z else (z_ndc + 1.0) / 2.0\n"
                                   "def f(dx, dy):\n    return (dy < 0) | ((dy == 0) & (dx > 0))\n",
        "renderer/gpu/pipeline.py": "GL_ZERO_TO_ONE = 0x935F\ns_ndc, t_ndc = (1.0, 0.0) if reversed_z else (2.0, -1.0)\n"
                                    "target.clear(r, g, b, 0.0, depth=0.0 if reversed_z else 1.0)\n"
                                    "ctx.depth_func = '>' if reversed_z else '<'\n",
        "reference/framebuffer.py": "u = np.floor(np.clip(c, 0.0, 1.0) * 255.0 + 0.5)\n",
        "tests/test_y.py": "ctx.enable_direct(0x8DB9)\n",
        "tests/test_x.py": "RAW_MISMATCH_LIMIT = 0.001\n",
        "reference/sampler.py": "TEXEL_WEIGHT_BITS = 8\nc = c.astype(np.float32) * np.float32(1 / 255)\n"
                                "m = (bits & 8388607 | 0x3F800000).view(np.float32)\nF = 0x2703\n"
                                "ANISOTROPY_RANGE = (2, 16)\nWEIGHT_LUT_SIZE = 1024\n",
        "reference/depth_buffer.py": '"""DEPTH_CLEAR_VALUE in a docstring is fine"""\n# (z_ndc + 1.0) / 2.0\n',
    }
    rules = sorted({line.split(": ")[1].split(" (")[0] for line in redefinitions(old)})
    assert rules == ["EWA weight table", "clip control modes", "depth clear value", "depth compare",
                     "fast log2", "fill rule", "max anisotropy", "pipeline tolerance", "sRGB framebuffer enums",
                     "sub-pixel bits",
                     "texel weight bits", "texture filter and wrap enums", "unorm8", "unorm8 texel to float",
                     "window depth", "window depth inverse"]
    assert not any(line.startswith("reference/depth_buffer.py") for line in redefinitions(old))
