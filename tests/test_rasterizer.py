"""The rasterisation rules of reference/rasterizer.py, checked against llvmpipe itself.

docs/conventions.md states llvmpipe's rules; these tests are the evidence:
- fill rule: a pixel centre exactly on a left or bottom edge is covered, on a right or top
  edge it is not (GL window coordinates, y up), so a shared edge is drawn once;
- snapping: vertices are snapped to 1/256 pixel (8 sub-pixel bits), rounding to nearest;
- facing: counter-clockwise in window coordinates is gl_FrontFacing.
Each case renders tiny triangles through the real GL (moderngl on EGL, llvmpipe) with the
pass-through shaders in tests/glsl/ and compares coverage pixel for pixel with the
reference rasteriser given the same window coordinates. Sizes are powers of two so that
window -> NDC -> window is exact in float32.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reference.rasterizer import is_drawn, rasterize, setup_triangles
from renderer.core.gl_rules import SUBPIXEL_BITS

GLSL = Path(__file__).parent / "glsl"


# --- the reference side ---------------------------------------------------------------

def reference_coverage(triangles, width: int, height: int, subpixel_bits: int = SUBPIXEL_BITS):
    """Per-pixel cover count and facing (GL rows, bottom first) of triangles given in
    window coordinates (T, 3, 2)."""
    xy = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 2)
    ndc = xy / [width, height] * 2.0 - 1.0
    gl_Position = np.concatenate([ndc, np.zeros(xy.shape[:2] + (1,)), np.ones(xy.shape[:2] + (1,))], -1)
    tris = setup_triangles(gl_Position, width, height, subpixel_bits)
    tris = tris.select(is_drawn(tris.area2, "none"))
    count = np.zeros((height, width), dtype=int)
    front = np.zeros((height, width), dtype=bool)
    for fragments in rasterize(tris, width, height):
        np.add.at(count, (fragments.y, fragments.x), 1)
        front[fragments.y, fragments.x] = fragments.gl_FrontFacing
    return count, front


def picture(count: np.ndarray) -> list[str]:
    """Coverage as text, top row first: '#' covered once, '2' twice, '.' not covered."""
    return ["".join(".#23456789"[c] for c in row) for row in count[::-1]]


# --- the GL side ----------------------------------------------------------------------

class LlvmpipeRasterizer:
    """Draws one triangle at a time into a small RGBA8 framebuffer and reads coverage back."""

    def __init__(self, ctx):
        import moderngl
        self.moderngl = moderngl
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=(GLSL / "coverage.vert").read_text(),
                                   fragment_shader=(GLSL / "coverage.frag").read_text())

    def coverage(self, triangles, width: int, height: int):
        """Cover count and facing like reference_coverage, drawing each triangle alone."""
        xy = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 2)
        ndc = (xy / [width, height] * 2.0 - 1.0).astype(np.float32)
        fbo = self.ctx.simple_framebuffer((width, height), components=4)
        fbo.use()
        count = np.zeros((height, width), dtype=int)
        front = np.zeros((height, width), dtype=bool)
        for triangle in ndc:
            fbo.clear(0.0, 0.0, 0.0, 0.0)
            vbo = self.ctx.buffer(triangle.tobytes())
            vao = self.ctx.vertex_array(self.program, [(vbo, "2f", "in_position")])
            vao.render(self.moderngl.TRIANGLES)
            rgba = np.frombuffer(fbo.read(components=4), np.uint8).reshape(height, width, 4)
            covered = rgba[..., 0] > 0                 # GL rows: row 0 is the bottom
            count += covered
            front[covered] = rgba[covered, 1] > 0
            vao.release()
            vbo.release()
        fbo.release()
        return count, front


@pytest.fixture(scope="module")
def llvmpipe():
    moderngl = pytest.importorskip("moderngl")
    try:
        ctx = moderngl.create_standalone_context(backend="egl")
    except Exception as error:  # no EGL, no Mesa: nothing to compare against
        pytest.skip(f"cannot start an EGL context for llvmpipe: {error}")
    yield LlvmpipeRasterizer(ctx)
    ctx.release()


# --- hand-checked: the rule as a picture ------------------------------------------------

RIGHT_TRIANGLE = [(1.5, 1.5), (5.5, 1.5), (1.5, 5.5)]        # vertices on pixel centres
UPPER_TRIANGLE = [(5.5, 1.5), (5.5, 5.5), (1.5, 5.5)]        # shares the diagonal


def test_fill_rule_by_hand():
    """Left and bottom edges through pixel centres are drawn, the hypotenuse (a right/top
    edge) is not; the partner triangle draws the hypotenuse and not its right or top edge;
    together they cover the 4x4 square exactly once."""
    count, _ = reference_coverage([RIGHT_TRIANGLE], 8, 8)
    assert picture(count) == ["........",
                              "........",
                              "........",
                              ".#......",
                              ".##.....",
                              ".###....",
                              ".####...",
                              "........"]
    count, _ = reference_coverage([UPPER_TRIANGLE], 8, 8)
    assert picture(count) == ["........",
                              "........",
                              "........",
                              "..###...",
                              "...##...",
                              "....#...",
                              "........",
                              "........"]
    count, _ = reference_coverage([RIGHT_TRIANGLE, UPPER_TRIANGLE], 8, 8)
    assert picture(count) == ["........",
                              "........",
                              "........",
                              ".####...",
                              ".####...",
                              ".####...",
                              ".####...",
                              "........"]


def test_snapping_by_hand():
    """A left edge 0.49/256 px right of a pixel centre snaps onto it (covered); 0.51/256 px
    does not (not covered); with 4 sub-pixel bits 6/256 px would still snap onto it."""
    def left_edge_covers_centre(offset, bits=8):
        x0 = 2.5 + offset
        quad = [[(x0, 0.25), (6.0, 0.25), (6.0, 7.75)], [(x0, 0.25), (6.0, 7.75), (x0, 7.75)]]
        count, _ = reference_coverage(quad, 8, 8, bits)
        return bool(count[4, 2])

    assert left_edge_covers_centre(0.49 / 256)
    assert not left_edge_covers_centre(0.51 / 256)
    assert not left_edge_covers_centre(6 / 256)
    assert left_edge_covers_centre(6 / 256, bits=4)


# --- against llvmpipe ----------------------------------------------------------------

def test_pixel_centre_edges_match_llvmpipe(llvmpipe):
    """The hand-checked triangles, both windings, and the pair sharing the diagonal."""
    for triangles in ([RIGHT_TRIANGLE], [RIGHT_TRIANGLE[::-1]], [UPPER_TRIANGLE],
                      [UPPER_TRIANGLE[::-1]], [RIGHT_TRIANGLE, UPPER_TRIANGLE],
                      [RIGHT_TRIANGLE[::-1], UPPER_TRIANGLE[::-1]]):
        gl_count, gl_front = llvmpipe.coverage(triangles, 8, 8)
        ref_count, ref_front = reference_coverage(triangles, 8, 8)
        assert picture(gl_count) == picture(ref_count), triangles
        assert np.array_equal(gl_front, ref_front), triangles
    gl_count, _ = llvmpipe.coverage([RIGHT_TRIANGLE, UPPER_TRIANGLE], 8, 8)
    assert gl_count.max() == 1 and gl_count.sum() == 16         # drawn once, no gap


def test_facing_matches_llvmpipe(llvmpipe):
    """Counter-clockwise in window coordinates (y up) is gl_FrontFacing, clockwise is not."""
    _, front = llvmpipe.coverage([RIGHT_TRIANGLE], 8, 8)
    assert front[2, 2]
    _, front = llvmpipe.coverage([RIGHT_TRIANGLE[::-1]], 8, 8)
    assert not front[2, 2]


def test_half_pixel_grid_triangles_match_llvmpipe(llvmpipe):
    """Random triangles with vertices on pixel centres and corners: edges pass through many
    pixel centres, horizontal, vertical and diagonal, in both windings; degenerate ones
    draw nothing on either side."""
    rng = np.random.default_rng(7)
    triangles = rng.integers(0, 33, size=(160, 3, 2)) / 2.0
    gl_count, gl_front = llvmpipe.coverage(triangles, 16, 16)
    ref_count, ref_front = reference_coverage(triangles, 16, 16)
    assert np.array_equal(gl_count, ref_count)
    assert np.array_equal(gl_front, ref_front)
    for triangle in triangles[:40]:                    # and one at a time, facing included
        gl = llvmpipe.coverage([triangle], 16, 16)
        ref = reference_coverage([triangle], 16, 16)
        assert np.array_equal(gl[0], ref[0]), triangle.tolist()
        assert np.array_equal(gl[1] & (gl[0] > 0), ref[1] & (ref[0] > 0)), triangle.tolist()


def test_fan_around_a_pixel_centre_matches_llvmpipe(llvmpipe):
    """A fan of 12 triangles around a pixel centre (every edge goes through it): llvmpipe
    and the reference both cover every pixel of the fan exactly once."""
    centre = np.array([8.5, 8.5])
    ring = [(15.5, 8.5), (14.5, 12.5), (12.5, 14.5), (8.5, 15.5), (4.5, 14.5), (2.5, 12.5),
            (1.5, 8.5), (2.5, 4.5), (4.5, 2.5), (8.5, 1.5), (12.5, 2.5), (14.5, 4.5)]
    fan = [[centre, ring[k], ring[(k + 1) % len(ring)]] for k in range(len(ring))]
    gl_count, _ = llvmpipe.coverage(fan, 16, 16)
    ref_count, _ = reference_coverage(fan, 16, 16)
    assert np.array_equal(gl_count, ref_count)
    assert ref_count.max() == 1 and ref_count[8, 8] == 1


def test_snapping_matches_llvmpipe(llvmpipe):
    """Edges a fraction of 1/256 px off a pixel centre: llvmpipe snaps like the reference,
    8 sub-pixel bits, round to nearest (0.49/256 snaps onto the centre, 0.51/256 away, and
    6/256, which 4 bits would snap onto it, does not), for left, right, bottom, top edges."""
    def probes(offset):
        a = 2.5 + offset
        left = [[(a, 0.25), (6.0, 0.25), (6.0, 7.75)], [(a, 0.25), (6.0, 7.75), (a, 7.75)]]
        right = [[(0.0, 0.25), (a, 0.25), (a, 7.75)], [(0.0, 0.25), (a, 7.75), (0.0, 7.75)]]
        bottom = [[(0.25, a), (7.75, a), (7.75, 6.0)], [(0.25, a), (7.75, 6.0), (0.25, 6.0)]]
        top = [[(0.25, 0.0), (7.75, 0.0), (7.75, a)], [(0.25, 0.0), (7.75, a), (0.25, a)]]
        return {"left": (left, (4, 2)), "right": (right, (4, 2)),
                "bottom": (bottom, (2, 4)), "top": (top, (2, 4))}

    expected_left_or_bottom = {0.49: True, -0.49: True, 0.51: False, -0.51: True, 0.5: True,
                               -0.5: True, 6.0: False, -6.0: True}
    for k, covered in expected_left_or_bottom.items():
        for edge, (quad, (row, col)) in probes(k / 256).items():
            gl_count, _ = llvmpipe.coverage(quad, 8, 8)
            ref_count, _ = reference_coverage(quad, 8, 8)
            assert gl_count[row, col] == ref_count[row, col], (edge, k)
            # a right or top edge at the same place covers exactly the complement
            expect = covered if edge in ("left", "bottom") else not covered
            assert bool(ref_count[row, col]) == expect, (edge, k)


def test_random_subpixel_triangles_match_llvmpipe(llvmpipe):
    """Random vertices on a 1/1024 px grid (so snapping often rounds, ties included)."""
    rng = np.random.default_rng(11)
    triangles = rng.integers(0, 32 * 1024 + 1, size=(120, 3, 2)) / 1024.0
    gl_count, _ = llvmpipe.coverage(triangles, 32, 32)
    ref_count, _ = reference_coverage(triangles, 32, 32)
    assert np.array_equal(gl_count, ref_count)
