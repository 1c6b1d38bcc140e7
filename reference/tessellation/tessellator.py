"""# Twin: the fixed-function tessellator of Mesa's llvmpipe (src/gallium/auxiliary/tessellator/tessellator.cpp, D3D11's reference tessellator); no GLSL file

GL's tessellation primitive generator as llvmpipe runs it: Mesa's draw module hands each
patch's levels to CHWTessellator, Microsoft's D3D11 reference tessellator
(tessellator.cpp; the GL glue p_tessellator.cpp, the draw loop draw_tess.c), and the
evaluation shader sees the domain points it makes. This module is a line-by-line port of
CHWTessellator: the same fixed-point arithmetic (15.16, FXP = uint32), the same float-to-fixed
rounding (floatToIDotF), the same clamps (tess_fmin / tess_fmax, denormals flushed, NaN to the
lower bound), the same point order and the same triangles in the same order. Its functions
keep the C names in snake case (place_point_in_1d is PlacePointIn1D, and so on), so that the
two read side by side. The capture harness glsl/tessellation/capture.vert, capture.tesc,
capture.tese (tests/tessellation_capture.py) holds it to llvmpipe by transform feedback.

Conventions (GL's names throughout):
- `domain`: "triangles", "quads" or "isolines" (the evaluation shader's layout);
- `spacing`: "equal_spacing" (D3D's INTEGER partitioning), "fractional_even_spacing"
  (FRACTIONAL_EVEN), "fractional_odd_spacing" (FRACTIONAL_ODD);
- `order`: "ccw" (GL's default) or "cw". draw_tess.c calls p_tess_init with
  !vertex_order_cw, so GL's ccw asks D3D for TRIANGLE_CW output: D3D's clockwise is in its
  own (u right, v down) picture, which is counter-clockwise in GL's (u right, v up) domain;
- `point_mode`: points instead of triangles or lines;
- `outer`, `inner`: gl_TessLevelOuter[0..3], gl_TessLevelInner[0..1] as the control shader
  wrote them (float32). Quads read outer[0..3] as D3D's Ueq0, Veq0, Ueq1, Veq1 and inner[0..1]
  as insideU, insideV; triangles outer[0..2] as Ueq0, Veq0, Weq0 and inner[0]; isolines
  outer[0] as the line density and outer[1] as the line detail (p_tessellator.cpp).

Output, `Tessellation`: the domain points `u`, `v` (P,) float32 in the order the evaluation
shader is run on them, `indices` (I,) int32 into them, 3 a triangle, 2 a line or 1 a point, in
the order GL's later stages (transform feedback included) see them, and `primitive`
("triangles", "lines" or "points"). A patch that GL culls (an outer level it reads that is
<= 0, NaN, or denormal: see below) has no points. `tess_coord` gives gl_TessCoord as
llvmpipe's evaluation shader sees it (draw_llvm.c, draw_tes_llvm_generate): (u, v, (1 - u) - v)
for triangles, (u, v, 0) for quads and isolines; u and v being multiples of 2^-16 in [0, 1],
every one of these float32 operations is exact, so the three sum to exactly 1.

Exact: every point and index, bit for bit, for any float32 levels (held by capture over every
integer level 1 .. 64, fractional levels, mixed per-edge levels, clamps, special values, every
spacing, both orders, point mode and isolines: tests/test_tessellator.py). A point is a 15.16
fixed-point number converted to float32 (fixedToFloat), k / 65536 exactly, not the spec's
i / n rounded: equal spacing at level 3 puts the edge points at 0x5555 / 65536 and
0xaaab / 65536.

Where llvmpipe 22.3.6 departs from the D3D reference or from GL (each held by a test):
- denormals are zero (Mesa's draw_vbo sets the CPU's DAZ and FTZ bits): a positive denormal
  outer level culls the patch, where GL would clamp it to 1 and D3D's C keeps it;
- one draw is cut into runs of PATCH_RUN_VERTICES input vertices (4096 // GL_PATCH_VERTICES
  patches), and gl_PrimitiveID restarts at 0 in each run (GL counts from the draw's start);
- within a run, the patches' points go into one vertex array and the primitives' element
  indices are uint16 (draw_tess.c): past 65,536 points in a run they wrap, and later primitives
  take an earlier patch's points. `captured_draw` models both; a renderer keeps each run at
  most MAX_RUN_POINTS points.
"""

from __future__ import annotations

import functools
import math
import struct
from dataclasses import dataclass

import numpy as np

DOMAINS = ("triangles", "quads", "isolines")
SPACINGS = ("equal_spacing", "fractional_even_spacing", "fractional_odd_spacing")
ORDERS = ("ccw", "cw")

# D3D11_TESSELLATOR_PARTITIONING of each GL spacing (p_tessellator.cpp, CVT_TS_D3D_PARTITIONING)
INTEGER, FRACTIONAL_ODD, FRACTIONAL_EVEN = "integer", "fractional_odd", "fractional_even"
PARTITIONING = {"equal_spacing": INTEGER, "fractional_even_spacing": FRACTIONAL_EVEN,
                "fractional_odd_spacing": FRACTIONAL_ODD}

# D3D11_TESSELLATOR_OUTPUT_PRIMITIVE
OUTPUT_POINT, OUTPUT_LINE, OUTPUT_TRIANGLE_CW, OUTPUT_TRIANGLE_CCW = range(4)

EVEN, ODD = 0, 1                                 # TESSELLATOR_PARITY

# tessellator.hpp's limits
MIN_ODD_TESSELLATION_FACTOR = 1.0
MAX_ODD_TESSELLATION_FACTOR = 63.0
MIN_EVEN_TESSELLATION_FACTOR = 2.0
MAX_EVEN_TESSELLATION_FACTOR = 64.0
MIN_ISOLINE_DENSITY_TESSELLATION_FACTOR = 1.0
MAX_ISOLINE_DENSITY_TESSELLATION_FACTOR = 64.0
MAX_TESSELLATION_FACTOR = 64
MAX_INDEX_COUNT = MAX_TESSELLATION_FACTOR * MAX_TESSELLATION_FACTOR * 2 * 3

# 15.16 fixed point (FXP is an unsigned int: its arithmetic wraps modulo 2^32)
FXP_FRACTION_BITS = 16
FXP_FRACTION_MASK = 0x0000FFFF
FXP_INTEGER_MASK = 0x7FFF0000
FXP_ONE = 1 << FXP_FRACTION_BITS
FXP_ONE_THIRD = 0x00005555
FXP_TWO_THIRDS = 0x0000AAAA
FXP_ONE_HALF = 0x00008000
EPSILON = 2.0 ** -16                             # the least positive fixed-point fraction
MIN_ODD_TESSFACTOR_PLUS_HALF_EPSILON = MIN_ODD_TESSELLATION_FACTOR + EPSILON / 2

# s_fixedReciprocal: 1 / n in 15.16, rounded, for n segments (entry 0 unused)
FIXED_RECIPROCAL = (
    0xFFFFFFFF,
    0x10000, 0x8000, 0x5555, 0x4000, 0x3333, 0x2AAB, 0x2492, 0x2000,
    0x1C72, 0x199A, 0x1746, 0x1555, 0x13B1, 0x1249, 0x1111, 0x1000,
    0xF0F, 0xE39, 0xD79, 0xCCD, 0xC31, 0xBA3, 0xB21, 0xAAB,
    0xA3D, 0x9D9, 0x97B, 0x925, 0x8D4, 0x889, 0x842, 0x800,
    0x7C2, 0x788, 0x750, 0x71C, 0x6EB, 0x6BD, 0x690, 0x666,
    0x63E, 0x618, 0x5F4, 0x5D1, 0x5B0, 0x591, 0x572, 0x555,
    0x539, 0x51F, 0x505, 0x4EC, 0x4D5, 0x4BE, 0x4A8, 0x492,
    0x47E, 0x46A, 0x457, 0x444, 0x432, 0x421, 0x410, 0x400,
)

# StitchTransition's tables: where point i of a half edge ends up at the largest level
# (ruler-function split order), and each half level's loop bounds in it
FINAL_POINT_POSITION = (0, 32, 16, 8, 17, 4, 18, 9, 19, 2, 20, 10, 21, 5, 22, 11, 23,
                        1, 24, 12, 25, 6, 26, 13, 27, 3, 28, 14, 29, 7, 30, 15, 31)
LOOP_START = (1, 1, 17, 9, 9, 5, 5, 5, 5, 3, 3, 3, 3, 3, 3, 3, 3,
              2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2)
LOOP_END = (0, 0, 17, 17, 25, 25, 25, 25, 29, 29, 29, 29, 29, 29, 29, 29, 31,
            31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 31, 32)

# StitchRegular's diagonals
DIAGONALS_INSIDE_TO_OUTSIDE, DIAGONALS_INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE, DIAGONALS_MIRRORED = range(3)

# The edges of a patch (tessellator.hpp)
U, V = 0, 1
UEQ0, VEQ0, WEQ0 = 0, 1, 2                       # a triangle's
UEQ1, VEQ1 = 2, 3                                # a quad's: Ueq0, Veq0, Ueq1, Veq1
QUAD_EDGES, QUAD_AXES, TRI_EDGES = 4, 2, 3


# -- 32-bit integers ---------------------------------------------------------------------------

def u32(x: int) -> int:
    """x as C's unsigned int (FXP) holds it: modulo 2^32."""
    return x & 0xFFFFFFFF


def i32(x: int) -> int:
    """x as C's int holds it: two's complement, 32 bits."""
    x &= 0xFFFFFFFF
    return x - (1 << 32) if x & 0x80000000 else x


# -- D3D's float rules (tess_isNaN, tess_flush, tess_fmin, tess_fmax) -----------------------------

def float_bits(x: float) -> int:
    """The float32 bit pattern of x (a value float32 holds exactly)."""
    return struct.unpack("<I", struct.pack("<f", x))[0]


def tess_flush(a: float) -> float:
    """A denormal flushed to zero of the same sign."""
    bits = float_bits(a)
    if bits & 0x7FFFFFFF < 0x00800000:
        return -0.0 if bits & 0x80000000 else 0.0
    return a


def tess_fmin(a: float, b: float) -> float:
    """IEEE 754R min on flushed values; a NaN b gives a; of two zeros the negative."""
    fa, fb = tess_flush(a), tess_flush(b)
    if math.isnan(fb):
        return a
    if fa == 0 and fb == 0:
        return a if float_bits(fa) & 0x80000000 else b
    return a if fa < fb else b


def tess_fmax(a: float, b: float) -> float:
    """IEEE 754R max on flushed values; a NaN b gives a; of two zeros the positive."""
    fa, fb = tess_flush(a), tess_flush(b)
    if math.isnan(fb):
        return a
    if fa == 0 and fb == 0:
        return a if float_bits(fb) & 0x80000000 else b
    return a if fa >= fb else b


def clamp_factor(level: float, lower: float, upper: float) -> float:
    """tess_fmin(upper, tess_fmax(lower, level)): NaN goes to `lower`."""
    return tess_fmin(upper, tess_fmax(lower, level))


def is_even(level: float) -> bool:
    """isEven: the level truncated to int, its low bit clear."""
    return not int(level) & 1


# -- fixed point -------------------------------------------------------------------------------

def float_to_fixed(x: float) -> int:
    """floatToFixed: floatToIDotF<15, 16, unsigned> of a float32, by integer operations only.
    NaN, negative numbers and numbers below 2^-17 give 0, numbers from 2^15 up 0xFFFFFFFF
    (C's -1), the rest the nearest 15.16 value, ties to even. Returns the FXP (uint32)."""
    mantissa_bits, bias = 23, 127
    hidden, mantissa_mask, sign_bit = 1 << 23, (1 << 23) - 1, 1 << 31
    int_bits, frac_bits = 15, 16
    max_pos_float = (bias + int_bits) << mantissa_bits       # iShift < 0: nothing subtracted
    output = float_bits(x)
    exponent = ((output & 0x7F800000) >> mantissa_bits) - bias
    negative = output & sign_bit
    if exponent == bias + 1 and output & mantissa_mask:       # NaN
        return 0
    if not negative and output >= max_pos_float:              # too large: c_iMaxResult = ~0
        return 0xFFFFFFFF
    if negative:                                              # c_iMinResult = 0 (unsigned)
        return 0
    if exponent < -frac_bits - 1:                             # too small
        return 0
    output = (output & mantissa_mask) | hidden
    extra_bits = mantissa_bits - frac_bits - exponent
    if extra_bits >= 0:
        lsb = 1 << extra_bits                                 # the last bit kept
        half = lsb >> 1
        if output & lsb or output & (lsb - 1) > half:         # round to nearest even at lsb
            output += half
        output >>= extra_bits
    else:
        output <<= -extra_bits
    return u32(output)


def fixed_to_float(fxp) -> np.ndarray:
    """fixedToFloat, (float)(x >> 16) + (float)(x & 0xffff) / 65536 in float32, of FXP values."""
    fxp = np.asarray(fxp, dtype=np.uint32)
    whole = (fxp >> FXP_FRACTION_BITS).astype(np.float32)
    fraction = (fxp & FXP_FRACTION_MASK).astype(np.float32) / np.float32(1 << FXP_FRACTION_BITS)
    return whole + fraction


def fxp_ceil(x: int) -> int:
    return u32((x & FXP_INTEGER_MASK) + FXP_ONE) if x & FXP_FRACTION_MASK else x


def fxp_floor(x: int) -> int:
    return x & FXP_INTEGER_MASK


def remove_msb(val: int) -> int:
    """RemoveMSB: val (0 <= val <= 0xffffff, as the tessellator calls it) without its highest
    set bit among the 8 it checks."""
    if val <= 0x0000FFFF:
        check = 0x00000080 if val <= 0x000000FF else 0x00008000
    else:
        check = 0x00800000 if val <= 0x00FFFFFF else 0x80000000
    for _ in range(8):
        if val & check:
            return i32(val & ~check)
        check >>= 1
    return 0


@dataclass(frozen=True)
class TessFactorContext:
    """TESS_FACTOR_CONTEXT: what PlacePointIn1D needs of one level (FXP values)."""
    inv_num_segments_on_floor: int
    inv_num_segments_on_ceil: int
    half_tess_factor_fraction: int
    num_half_tess_factor_points: int
    split_point_on_floor_half_tess_factor: int


def num_points_for_tess_factor(fxp_tess_factor: int, odd: bool) -> int:
    """NumPointsForTessFactor: the points on an edge of this level, both ends included."""
    half = u32(fxp_tess_factor + 1) // 2
    if odd:
        return u32(fxp_ceil(u32(FXP_ONE_HALF + half)) * 2) >> FXP_FRACTION_BITS
    return (u32(fxp_ceil(half) * 2) >> FXP_FRACTION_BITS) + 1


def compute_tess_factor_context(fxp_tess_factor: int, odd: bool) -> TessFactorContext:
    """ComputeTessFactorContext."""
    half = u32(fxp_tess_factor + 1) // 2
    if odd or half == FXP_ONE_HALF:      # a level of 1 (1/2 here) is treated as odd
        half = u32(half + FXP_ONE_HALF)
    floor_half, ceil_half = fxp_floor(half), fxp_ceil(half)
    fraction = u32(half - floor_half)
    num_half_points = ceil_half >> FXP_FRACTION_BITS   # even: the middle point not counted
    if ceil_half == floor_half:
        split_point = num_half_points + 1              # never reached
    elif odd:
        if floor_half == FXP_ONE:
            split_point = 0
        else:
            split_point = (remove_msb(i32(u32((floor_half >> FXP_FRACTION_BITS) - 1))) << 1) + 1
    else:
        split_point = (remove_msb(floor_half >> FXP_FRACTION_BITS) << 1) + 1
    num_floor_segments = u32(floor_half * 2) >> FXP_FRACTION_BITS
    num_ceil_segments = u32(ceil_half * 2) >> FXP_FRACTION_BITS
    if odd:
        num_floor_segments -= 1
        num_ceil_segments -= 1
    return TessFactorContext(FIXED_RECIPROCAL[num_floor_segments], FIXED_RECIPROCAL[num_ceil_segments],
                             fraction, num_half_points, split_point)


def place_point_in_1d(ctx: TessFactorContext, point: int, odd: bool) -> int:
    """PlacePointIn1D: point number `point` along an edge of the context's level, as FXP: on
    the half edge, a lerp by the level's fraction between the point's place on the floor and
    on the ceiling level, mirrored on the far half."""
    if point >= ctx.num_half_tess_factor_points:
        point = (ctx.num_half_tess_factor_points << 1) - point
        if odd:
            point -= 1
        flip = True
    else:
        flip = False
    if point == ctx.num_half_tess_factor_points:
        return FXP_ONE_HALF                   # the middle, which 16-bit fixed point misses
    index_on_ceil = u32(point)
    index_on_floor = index_on_ceil
    if point > ctx.split_point_on_floor_half_tess_factor:
        index_on_floor = u32(index_on_floor - 1)
    on_floor = u32(index_on_floor * ctx.inv_num_segments_on_floor)
    on_ceil = u32(index_on_ceil * ctx.inv_num_segments_on_ceil)
    fraction = ctx.half_tess_factor_fraction
    location = u32(on_floor * u32(FXP_ONE - fraction) + on_ceil * fraction)
    location = u32(location + FXP_ONE_HALF) >> FXP_FRACTION_BITS
    return u32(FXP_ONE - location) if flip else location


# -- the tessellator ----------------------------------------------------------------------------

class _IndexPatch:
    """m_IndexPatchContext: the first kind of index patching (a ring's last edge)."""
    inside_delta = inside_bad = inside_replacement = 0
    outside_base = outside_delta = outside_bad = outside_replacement = 0


class _IndexPatch2:
    """m_IndexPatchContext2: the second kind (a degenerate middle row, the centre strip)."""
    base_index_to_invert = corner_case_bad = corner_case_replacement = inversion_end_point = 0


class HWTessellator:
    """CHWTessellator, one patch at a time. `points` (FXP u, v pairs) and `indices` after a
    tessellate_* call; `parity` is m_parity, the state Odd() reads."""

    def __init__(self, partitioning: str, output_primitive: int):
        self.partitioning = self.original_partitioning = partitioning
        self.parity = self.original_parity = {FRACTIONAL_ODD: ODD, FRACTIONAL_EVEN: EVEN}.get(
            partitioning, EVEN)   # INTEGER leaves m_parity unset in C; no path reads it then
        self.output_primitive = output_primitive
        self.points: list = []
        self.indices: list = []
        self.num_points = 0
        self.num_indices = 0
        self.using_patched = self.using_patched2 = False
        self.patch = _IndexPatch()
        self.patch2 = _IndexPatch2()

    # state queries, as the C names them
    def odd(self) -> bool:
        return self.parity == ODD

    def hw_integer_partitioning(self) -> bool:
        return self.partitioning == INTEGER

    def bounds(self) -> tuple[float, float]:
        """The clamp of the edge levels for the user's partitioning."""
        return {INTEGER: (MIN_ODD_TESSELLATION_FACTOR, MAX_EVEN_TESSELLATION_FACTOR),
                FRACTIONAL_EVEN: (MIN_EVEN_TESSELLATION_FACTOR, MAX_EVEN_TESSELLATION_FACTOR),
                FRACTIONAL_ODD: (MIN_ODD_TESSELLATION_FACTOR, MAX_ODD_TESSELLATION_FACTOR),
                }[self.original_partitioning]

    def place(self, ctx: TessFactorContext, point: int) -> int:
        return place_point_in_1d(ctx, point, self.odd())

    # storage
    def reset(self, num_points: int = 0) -> None:
        self.points = [None] * num_points
        self.indices = [None] * MAX_INDEX_COUNT
        self.num_points = num_points
        self.num_indices = 0

    def define_point(self, fxp_u: int, fxp_v: int, offset: int) -> None:
        self.points[offset] = (u32(fxp_u), u32(fxp_v))

    def define_index(self, index: int, offset: int) -> None:
        if self.using_patched or self.using_patched2:
            index = self.patch_index_value(index)
        self.indices[offset] = index

    def define_clockwise_triangle(self, i0: int, i1: int, i2: int, offset: int) -> None:
        """A triangle given clockwise (D3D's picture), stored as the output asks."""
        self.define_index(i0, offset)
        if self.output_primitive == OUTPUT_TRIANGLE_CW:
            self.define_index(i1, offset + 1)
            self.define_index(i2, offset + 2)
        else:
            self.define_index(i2, offset + 1)
            self.define_index(i1, offset + 2)

    def dump_all_points(self) -> None:
        for p in range(self.num_points):
            self.define_index(p, self.num_indices)
            self.num_indices += 1

    def dump_all_points_as_in_order_line_list(self) -> None:
        for p in range(1, self.num_points):
            self.define_index(p - 1, self.num_indices)
            self.num_indices += 1
            self.define_index(p, self.num_indices)
            self.num_indices += 1

    def patch_index_value(self, index: int) -> int:
        """PatchIndexValue: a ring's wrapped-around or inverted index made real."""
        if self.using_patched:
            c = self.patch
            if index >= c.outside_base:
                index = c.outside_replacement if index == c.outside_bad else index + c.outside_delta
            else:
                index = c.inside_replacement if index == c.inside_bad else index + c.inside_delta
        elif self.using_patched2:
            c = self.patch2
            if index >= c.base_index_to_invert:
                if index == c.corner_case_bad:
                    index = c.corner_case_replacement
                else:
                    index = c.inversion_end_point - index
            elif index == c.corner_case_bad:
                index = c.corner_case_replacement
        return index

    def finish_minimum(self, points, triangles) -> None:
        """The all-levels-1 patch: its corners, and its triangles, points or lines."""
        self.reset(len(points))
        for offset, (fxp_u, fxp_v) in enumerate(points):
            self.define_point(fxp_u, fxp_v, offset)
        if self.output_primitive in (OUTPUT_TRIANGLE_CW, OUTPUT_TRIANGLE_CCW):
            for k, triangle in enumerate(triangles):
                self.define_clockwise_triangle(*triangle, 3 * k)
            self.num_indices = 3 * len(triangles)
        elif self.output_primitive == OUTPUT_POINT:
            self.dump_all_points()
        else:
            self.dump_all_points_as_in_order_line_list()

    # -- stitching ----------------------------------------------------------------------------

    def stitch_regular(self, trapezoid: bool, diagonals: int, base_index_offset: int,
                       num_inside_edge_points: int, inside_base: int, outside_base: int) -> None:
        """StitchRegular: two rows of points, the outside one a point longer at each end when
        `trapezoid`, joined by triangles with the diagonals asked for."""
        tri = self.define_clockwise_triangle
        inside, outside, offset = inside_base, outside_base, base_index_offset
        if trapezoid:
            tri(outside, outside + 1, inside, offset)
            offset += 3
            outside += 1
        if diagonals == DIAGONALS_INSIDE_TO_OUTSIDE:
            for _ in range(num_inside_edge_points - 1):
                tri(inside, outside, outside + 1, offset)
                tri(inside, outside + 1, inside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
        elif diagonals == DIAGONALS_INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE:
            p = 0
            while p < num_inside_edge_points // 2 - 1:          # first half
                tri(outside, outside + 1, inside, offset)
                tri(inside, outside + 1, inside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
                p += 1
            tri(outside, inside + 1, inside, offset)              # middle
            tri(outside, outside + 1, inside + 1, offset + 3)
            offset += 6
            inside += 1
            outside += 1
            p += 2
            while p < num_inside_edge_points:                    # second half
                tri(outside, outside + 1, inside, offset)
                tri(inside, outside + 1, inside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
                p += 1
        elif diagonals == DIAGONALS_MIRRORED:
            p = 0
            while p < num_inside_edge_points // 2:
                tri(outside, inside + 1, inside, offset)
                tri(outside, outside + 1, inside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
                p += 1
            while p < num_inside_edge_points - 1:
                tri(inside, outside, outside + 1, offset)
                tri(inside, outside + 1, inside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
                p += 1
        if trapezoid:
            tri(outside, outside + 1, inside, offset)

    def stitch_transition(self, base_index_offset: int, inside_base: int, inside_num_half_points: int,
                          inside_parity: int, outside_base: int, outside_num_half_points: int,
                          outside_parity: int) -> None:
        """StitchTransition: the outer ring (any levels) joined to the first inner ring, points
        advanced on either row in ruler-function order."""
        tri = self.define_clockwise_triangle
        if inside_parity == ODD:
            inside_num_half_points -= 1
        if outside_parity == ODD:
            outside_num_half_points -= 1
        outside, inside, offset = outside_base, inside_base, base_index_offset
        i_start = min(LOOP_START[inside_num_half_points], LOOP_START[outside_num_half_points])
        i_end = max(LOOP_END[inside_num_half_points], LOOP_END[outside_num_half_points])

        def advance_outside():
            nonlocal outside, offset
            tri(outside, outside + 1, inside, offset)
            offset += 3
            outside += 1

        def advance_inside():
            nonlocal inside, offset
            tri(inside, outside, inside + 1, offset)
            offset += 3
            inside += 1

        if FINAL_POINT_POSITION[0] < outside_num_half_points:
            advance_outside()
        for i in range(i_start, i_end + 1):                    # first half
            if FINAL_POINT_POSITION[i] < inside_num_half_points:
                advance_inside()
            if FINAL_POINT_POSITION[i] < outside_num_half_points:
                advance_outside()
        if inside_parity != outside_parity or inside_parity == ODD:
            if inside_parity == outside_parity:                # a quad in the middle
                tri(inside, outside, inside + 1, offset)
                tri(inside + 1, outside, outside + 1, offset + 3)
                offset += 6
                inside += 1
                outside += 1
            elif inside_parity == EVEN:                        # a triangle pointing inside
                tri(inside, outside, outside + 1, offset)
                offset += 3
                outside += 1
            else:                                              # a triangle pointing outside
                tri(inside, outside, inside + 1, offset)
                offset += 3
                inside += 1
        for i in range(i_end, i_start - 1, -1):                # second half
            if FINAL_POINT_POSITION[i] < outside_num_half_points:
                advance_outside()
            if FINAL_POINT_POSITION[i] < inside_num_half_points:
                advance_inside()
        if FINAL_POINT_POSITION[0] < outside_num_half_points:
            advance_outside()

    # -- quads --------------------------------------------------------------------------------

    def tessellate_quad_domain(self, ueq0: float, veq0: float, ueq1: float, veq1: float,
                               inside_u: float, inside_v: float) -> None:
        """TessellateQuadDomain."""
        f = self.quad_process_tess_factors(ueq0, veq0, ueq1, veq1, inside_u, inside_v)
        if f is None:                                          # culled
            self.reset()
            return
        if f == "minimum":
            self.finish_minimum([(0, 0), (FXP_ONE, 0), (FXP_ONE, FXP_ONE), (0, FXP_ONE)],
                                [(0, 1, 3), (1, 2, 3)])
            return
        self.quad_generate_points(f)
        if self.output_primitive == OUTPUT_POINT:
            self.dump_all_points()
            return
        if self.output_primitive == OUTPUT_LINE:
            self.dump_all_points_as_in_order_line_list()
            return
        self.quad_generate_connectivity(f)

    def quad_process_tess_factors(self, ueq0, veq0, ueq1, veq1, inside_u, inside_v):
        """QuadProcessTessFactors: None for a culled patch, "minimum" for all levels 1, else
        the processed levels (a dict of PROCESSED_TESS_FACTORS_QUAD's fields)."""
        outside = [ueq0, veq0, ueq1, veq1]
        if not all(level > 0 for level in outside):            # NaN culls too
            return None
        lower, upper = self.bounds()
        outside = [clamp_factor(level, lower, upper) for level in outside]
        if self.hw_integer_partitioning():
            outside = [float(math.ceil(level)) for level in outside]
        if self.original_partitioning == FRACTIONAL_ODD:
            # a level above 1 after the conversion to fixed point forces a picture frame
            if any(level > MIN_ODD_TESSFACTOR_PLUS_HALF_EPSILON for level in outside + [inside_u, inside_v]):
                lower = MIN_ODD_TESSELLATION_FACTOR + EPSILON
        inside = [clamp_factor(level, lower, upper) for level in (inside_u, inside_v)]
        if self.hw_integer_partitioning():
            inside = [float(math.ceil(level)) for level in inside]
        self.reset()
        if self.hw_integer_partitioning():
            outside_parity = [EVEN if is_even(level) else ODD for level in outside]
            inside_parity = [EVEN if is_even(level) or level == 1.0 else ODD for level in inside]
        else:
            outside_parity = [self.original_parity] * QUAD_EDGES
            inside_parity = [self.original_parity] * QUAD_AXES
        outside_fxp = [float_to_fixed(level) for level in outside]
        inside_fxp = [float_to_fixed(level) for level in inside]
        if self.hw_integer_partitioning() or self.odd():
            if all(fxp == FXP_ONE for fxp in inside_fxp + outside_fxp):
                return "minimum"
        outside_ctx = [compute_tess_factor_context(fxp, parity == ODD)
                       for fxp, parity in zip(outside_fxp, outside_parity)]
        inside_ctx = [compute_tess_factor_context(fxp, parity == ODD)
                      for fxp, parity in zip(inside_fxp, inside_parity)]
        num_outside = [num_points_for_tess_factor(fxp, parity == ODD)
                       for fxp, parity in zip(outside_fxp, outside_parity)]
        num_points = sum(num_outside) - 4
        # max(): a degenerate transition region where an inside level is 1
        num_inside = [max(4 if parity == ODD else 3, num_points_for_tess_factor(fxp, parity == ODD))
                      for fxp, parity in zip(inside_fxp, inside_parity)]
        inside_edge_point_base = num_points
        num_points += (num_inside[U] - 2) * (num_inside[V] - 2)
        self.reset(num_points)
        return dict(outside_parity=outside_parity, inside_parity=inside_parity, outside_ctx=outside_ctx,
                    inside_ctx=inside_ctx, num_outside=num_outside, num_inside=num_inside,
                    inside_edge_point_base=inside_edge_point_base)

    def quad_generate_points(self, f: dict) -> None:
        """QuadGeneratePoints: the outer ring clockwise (D3D's picture) from (0, 1)... then
        the inner rings spiralling in, then an even level's middle row."""
        offset = 0
        for edge in range(QUAD_EDGES):                         # the outer ring
            end = f["num_outside"][edge] - 1
            for p in range(end):                               # each edge's end starts the next
                q = p if edge in (1, 2) else end - p
                self.parity = f["outside_parity"][edge]
                param = self.place(f["outside_ctx"][edge], q)
                if edge & 1:
                    self.define_point(param, FXP_ONE if edge == 3 else 0, offset)
                else:
                    self.define_point(FXP_ONE if edge == 2 else 0, param, offset)
                offset += 1
        num_inside, inside_ctx, inside_parity = f["num_inside"], f["inside_ctx"], f["inside_parity"]
        num_rings = min(num_inside) >> 1                       # even: the centre not counted
        for ring in range(1, num_rings):
            start = ring
            end = [num_inside[U] - 1 - start, num_inside[V] - 1 - start]
            for edge in range(QUAD_EDGES):
                axis = [edge & 1, (edge + 1) & 1]
                perpendicular_point = start if edge < 2 else end[axis[0]]
                self.parity = inside_parity[axis[0]]
                perpendicular = self.place(inside_ctx[axis[0]], perpendicular_point)
                self.parity = inside_parity[axis[1]]
                for p in range(start, end[axis[1]]):
                    q = p if edge in (1, 2) else end[axis[1]] - (p - start)
                    param = self.place(inside_ctx[axis[1]], q)
                    if axis[1]:
                        self.define_point(perpendicular, param, offset)
                    else:
                        self.define_point(param, perpendicular, offset)
                    offset += 1
        # an even level's innermost "ring" is a row of points
        if num_inside[U] > num_inside[V] and inside_parity[V] == EVEN:
            start, end = num_rings, num_inside[U] - 1 - num_rings
            self.parity = inside_parity[U]
            for p in range(start, end + 1):
                self.define_point(self.place(inside_ctx[U], p), FXP_ONE_HALF, offset)
                offset += 1
        elif num_inside[V] >= num_inside[U] and inside_parity[U] == EVEN:
            start, end = num_rings, num_inside[V] - 1 - num_rings
            self.parity = inside_parity[V]
            for p in range(end, start - 1, -1):
                self.define_point(FXP_ONE_HALF, self.place(inside_ctx[V], p), offset)
                offset += 1

    def quad_generate_connectivity(self, f: dict) -> None:
        """QuadGenerateConnectivity: each ring's edges stitched to the ring inside it, the
        first by StitchTransition, the others by StitchRegular, then the centre strip."""
        num_inside, inside_parity, inside_ctx = f["num_inside"], f["inside_parity"], f["inside_ctx"]
        rows_to_centre = [(num_inside[U] + 1) >> 1, (num_inside[V] + 1) >> 1]   # even: centre included
        num_rings = min(rows_to_centre)
        # an even level's degenerate middle row breaks the ring's point order here
        degenerate_ring = [rows_to_centre[V] - 1 if inside_parity[V] == EVEN else -1,
                           rows_to_centre[U] - 1 if inside_parity[U] == EVEN else -1]
        outside_ctx = list(f["outside_ctx"])
        outside_parity = list(f["outside_parity"])
        num_outside = list(f["num_outside"])
        inside_base_offset = f["inside_edge_point_base"]
        outside_base_offset = 0
        for ring in range(1, num_rings):
            num_inside_edge = [num_inside[U] - 2 * ring, num_inside[V] - 2 * ring]
            edge0_inside_base, edge0_outside_base = inside_base_offset, outside_base_offset
            for edge in range(QUAD_EDGES):
                parity = (edge + 1) & 1
                num_triangles = num_inside_edge[parity] + num_outside[edge] - 2
                if edge == 3:          # the ring's last edge wraps round to its first point
                    if ring == degenerate_ring[parity]:
                        c = self.patch2
                        c.base_index_to_invert = inside_base_offset + 1
                        c.corner_case_bad = outside_base_offset + num_outside[edge] - 1
                        c.corner_case_replacement = edge0_outside_base
                        c.inversion_end_point = (c.base_index_to_invert << 1) - 1
                        inside_base, outside_base = c.base_index_to_invert, outside_base_offset
                        self.using_patched2 = True
                    else:
                        c = self.patch
                        c.inside_delta = inside_base_offset
                        c.inside_bad = num_inside_edge[parity] - 1
                        c.inside_replacement = edge0_inside_base
                        c.outside_base = c.inside_bad + 1
                        c.outside_delta = outside_base_offset - c.outside_base
                        c.outside_bad = c.outside_base + num_outside[edge] - 1
                        c.outside_replacement = edge0_outside_base
                        inside_base, outside_base = 0, c.outside_base
                        self.using_patched = True
                elif edge == 2 and ring == degenerate_ring[parity]:
                    c = self.patch2
                    c.base_index_to_invert = inside_base_offset
                    c.corner_case_bad = -1
                    c.corner_case_replacement = -1
                    c.inversion_end_point = c.base_index_to_invert << 1
                    inside_base, outside_base = c.base_index_to_invert, outside_base_offset
                    self.using_patched2 = True
                else:
                    inside_base, outside_base = inside_base_offset, outside_base_offset
                if ring == 1:
                    self.stitch_transition(self.num_indices, inside_base,
                                           inside_ctx[parity].num_half_tess_factor_points, inside_parity[parity],
                                           outside_base, outside_ctx[edge].num_half_tess_factor_points,
                                           outside_parity[edge])
                else:
                    self.stitch_regular(True, DIAGONALS_MIRRORED, self.num_indices,
                                        num_inside_edge[parity], inside_base, outside_base)
                self.using_patched = self.using_patched2 = False
                self.num_indices += num_triangles * 3
                outside_base_offset += num_outside[edge] - 1
                if edge == 2 and ring == degenerate_ring[parity]:
                    inside_base_offset -= num_inside_edge[parity] - 1
                else:
                    inside_base_offset += num_inside_edge[parity] - 1
                num_outside[edge] = num_inside_edge[parity]
            if ring == 1:
                outside_ctx = [inside_ctx[edge & 1] for edge in range(QUAD_EDGES)]
                outside_parity = [inside_parity[edge & 1] for edge in range(QUAD_EDGES)]
        # the centre: a strip of quads where the narrower level is odd
        c = self.patch2
        if num_inside[U] > num_inside[V] and inside_parity[V] == ODD:
            self.using_patched2 = True
            strip_quads = (((num_inside[U] >> 1) - (num_inside[V] >> 1)) << 1) + \
                (2 if inside_parity[U] == EVEN else 1)
            c.base_index_to_invert = outside_base_offset + strip_quads + 2
            c.corner_case_bad = c.base_index_to_invert
            c.corner_case_replacement = outside_base_offset
            c.inversion_end_point = c.base_index_to_invert + c.base_index_to_invert + strip_quads
            self.stitch_regular(False, DIAGONALS_INSIDE_TO_OUTSIDE, self.num_indices, strip_quads + 1,
                                c.base_index_to_invert, outside_base_offset + 1)
            self.using_patched2 = False
            self.num_indices += strip_quads * 6
        elif num_inside[V] >= num_inside[U] and inside_parity[U] == ODD:
            self.using_patched2 = True
            strip_quads = (((num_inside[V] >> 1) - (num_inside[U] >> 1)) << 1) + \
                (2 if inside_parity[V] == EVEN else 1)
            c.base_index_to_invert = outside_base_offset + strip_quads + 1
            c.corner_case_bad = -1
            # cornerCaseReplacementValue is left as the last patch set it (never read: bad is -1)
            c.inversion_end_point = c.base_index_to_invert + c.base_index_to_invert + strip_quads
            diagonals = DIAGONALS_INSIDE_TO_OUTSIDE if inside_parity[V] == EVEN else \
                DIAGONALS_INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE
            self.stitch_regular(False, diagonals, self.num_indices, strip_quads + 1,
                                c.base_index_to_invert, outside_base_offset)
            self.using_patched2 = False
            self.num_indices += strip_quads * 6

    # -- triangles ----------------------------------------------------------------------------

    def tessellate_tri_domain(self, ueq0: float, veq0: float, weq0: float, inside: float) -> None:
        """TessellateTriDomain."""
        f = self.tri_process_tess_factors(ueq0, veq0, weq0, inside)
        if f is None:
            self.reset()
            return
        if f == "minimum":
            self.finish_minimum([(0, FXP_ONE), (0, 0), (FXP_ONE, 0)], [(0, 1, 2)])
            return
        self.tri_generate_points(f)
        if self.output_primitive == OUTPUT_POINT:
            self.dump_all_points()
            return
        if self.output_primitive == OUTPUT_LINE:
            self.dump_all_points_as_in_order_line_list()
            return
        self.tri_generate_connectivity(f)

    def tri_process_tess_factors(self, ueq0, veq0, weq0, inside):
        """TriProcessTessFactors: None (culled), "minimum" (all levels 1) or the processed
        levels (PROCESSED_TESS_FACTORS_TRI's fields)."""
        outside = [ueq0, veq0, weq0]
        if not all(level > 0 for level in outside):
            return None
        lower, upper = self.bounds()
        outside = [clamp_factor(level, lower, upper) for level in outside]
        if self.hw_integer_partitioning():
            outside = [float(math.ceil(level)) for level in outside]
        if self.original_partitioning == FRACTIONAL_ODD:
            # (the inside level is not looked at here, unlike the quad's)
            if any(level > MIN_ODD_TESSFACTOR_PLUS_HALF_EPSILON for level in outside):
                lower = MIN_ODD_TESSELLATION_FACTOR + EPSILON
        inside = clamp_factor(inside, lower, upper)
        if self.hw_integer_partitioning():
            inside = float(math.ceil(inside))
        self.reset()
        if self.hw_integer_partitioning():
            outside_parity = [EVEN if is_even(level) else ODD for level in outside]
            inside_parity = EVEN if is_even(inside) or inside == 1.0 else ODD
        else:
            outside_parity = [self.original_parity] * TRI_EDGES
            inside_parity = self.original_parity
        outside_fxp = [float_to_fixed(level) for level in outside]
        inside_fxp = float_to_fixed(inside)
        if self.hw_integer_partitioning() or self.odd():
            if inside_fxp == FXP_ONE and all(fxp == FXP_ONE for fxp in outside_fxp):
                return "minimum"
        outside_ctx = [compute_tess_factor_context(fxp, parity == ODD)
                       for fxp, parity in zip(outside_fxp, outside_parity)]
        inside_ctx = compute_tess_factor_context(inside_fxp, inside_parity == ODD)
        num_outside = [num_points_for_tess_factor(fxp, parity == ODD)
                       for fxp, parity in zip(outside_fxp, outside_parity)]
        num_points = sum(num_outside) - 3
        self.parity = inside_parity
        num_inside = max(4 if self.odd() else 3, num_points_for_tess_factor(inside_fxp, self.odd()))
        inside_edge_point_base = num_points
        rings = (num_inside >> 1) - 1
        if self.odd():
            num_points += TRI_EDGES * (rings * (rings + 1) - rings)
        else:
            num_points += TRI_EDGES * (rings * (rings + 1)) + 1
        self.reset(num_points)
        return dict(outside_parity=outside_parity, inside_parity=inside_parity, outside_ctx=outside_ctx,
                    inside_ctx=inside_ctx, num_outside=num_outside, num_inside=num_inside,
                    inside_edge_point_base=inside_edge_point_base)

    def tri_generate_points(self, f: dict) -> None:
        """TriGeneratePoints: the outer ring from V (the U = 0 edge first), then the inner
        rings spiralling in, then an even level's centre point."""
        offset = 0
        for edge in range(TRI_EDGES):
            end = f["num_outside"][edge] - 1
            for p in range(end):
                q = p if edge & 1 else end - p
                self.parity = f["outside_parity"][edge]
                param = self.place(f["outside_ctx"][edge], q)
                if edge == 0:
                    self.define_point(0, param, offset)
                else:
                    self.define_point(param, u32(FXP_ONE - param) if edge == 2 else 0, offset)
                offset += 1
        self.parity = f["inside_parity"]
        ctx, num_inside = f["inside_ctx"], f["num_inside"]
        num_rings = num_inside >> 1
        for ring in range(1, num_rings):
            start, end = ring, num_inside - 1 - ring
            for edge in range(TRI_EDGES):
                perpendicular = self.place(ctx, start)
                perpendicular = u32(perpendicular * FXP_TWO_THIRDS)    # to barycentric size
                perpendicular = u32(perpendicular + FXP_ONE_HALF) >> FXP_FRACTION_BITS
                half_perpendicular = u32(perpendicular + 1) // 2        # deriv = 2, rounded
                for p in range(start, end):
                    q = p if edge & 1 else end - (p - start)
                    param = self.place(ctx, q)
                    along = u32(param - half_perpendicular)
                    if edge == 0:
                        self.define_point(perpendicular, along, offset)
                    elif edge == 1:
                        self.define_point(along, perpendicular, offset)
                    else:
                        self.define_point(along, u32(FXP_ONE - along - perpendicular), offset)
                    offset += 1
        if not self.odd():
            self.define_point(FXP_ONE_THIRD, FXP_ONE_THIRD, offset)

    def tri_generate_connectivity(self, f: dict) -> None:
        """TriGenerateConnectivity: the rings stitched as the quad's, then an odd level's
        centre triangle."""
        num_inside, inside_ctx, inside_parity = f["num_inside"], f["inside_ctx"], f["inside_parity"]
        num_rings = (num_inside + 1) >> 1                     # even: the centre point included
        outside_ctx = list(f["outside_ctx"])
        outside_parity = list(f["outside_parity"])
        num_outside = list(f["num_outside"])
        inside_base_offset = f["inside_edge_point_base"]
        outside_base_offset = 0
        for ring in range(1, num_rings):
            num_inside_edge = num_inside - 2 * ring
            edge0_inside_base, edge0_outside_base = inside_base_offset, outside_base_offset
            for edge in range(TRI_EDGES):
                num_triangles = num_inside_edge + num_outside[edge] - 2
                if edge == 2:
                    c = self.patch
                    c.inside_delta = inside_base_offset
                    c.inside_bad = num_inside_edge - 1
                    c.inside_replacement = edge0_inside_base
                    c.outside_base = c.inside_bad + 1
                    c.outside_delta = outside_base_offset - c.outside_base
                    c.outside_bad = c.outside_base + num_outside[edge] - 1
                    c.outside_replacement = edge0_outside_base
                    self.using_patched = True
                    inside_base, outside_base = 0, c.outside_base
                else:
                    inside_base, outside_base = inside_base_offset, outside_base_offset
                if ring == 1:
                    self.stitch_transition(self.num_indices, inside_base, inside_ctx.num_half_tess_factor_points,
                                           inside_parity, outside_base,
                                           outside_ctx[edge].num_half_tess_factor_points, outside_parity[edge])
                else:
                    self.stitch_regular(True, DIAGONALS_MIRRORED, self.num_indices, num_inside_edge,
                                        inside_base, outside_base)
                if edge == 2:
                    self.using_patched = False
                self.num_indices += num_triangles * 3
                outside_base_offset += num_outside[edge] - 1
                inside_base_offset += num_inside_edge - 1
                num_outside[edge] = num_inside_edge
            if ring == 1:
                outside_ctx = [inside_ctx] * TRI_EDGES
                outside_parity = [inside_parity] * TRI_EDGES
        if self.odd():                                        # the centre triangle
            self.define_clockwise_triangle(outside_base_offset, outside_base_offset + 1,
                                           outside_base_offset + 2, self.num_indices)
            self.num_indices += 3

    # -- isolines -----------------------------------------------------------------------------

    def tessellate_iso_line_domain(self, density: float, detail: float) -> None:
        """TessellateIsoLineDomain(TessFactor_V_LineDensity, TessFactor_U_LineDetail)."""
        if not (density > 0 and detail > 0):
            self.reset()
            return
        lower, upper = self.bounds()
        density = clamp_factor(density, MIN_ISOLINE_DENSITY_TESSELLATION_FACTOR,
                               MAX_ISOLINE_DENSITY_TESSELLATION_FACTOR)
        detail = clamp_factor(detail, lower, upper)
        if self.hw_integer_partitioning():
            detail = float(math.ceil(detail))
            detail_parity = EVEN if is_even(detail) else ODD
        else:
            detail_parity = self.original_parity
        detail_fxp = float_to_fixed(detail)
        self.parity = detail_parity
        detail_ctx = compute_tess_factor_context(detail_fxp, self.odd())
        points_per_line = num_points_for_tess_factor(detail_fxp, self.odd())
        self.partitioning = INTEGER                           # OverridePartitioning: density
        density = float(math.ceil(density))
        density_parity = EVEN if is_even(density) else ODD
        self.parity = density_parity
        density_fxp = float_to_fixed(density)
        density_ctx = compute_tess_factor_context(density_fxp, self.odd())
        num_lines = num_points_for_tess_factor(density_fxp, self.odd()) - 1   # no line at v = 1
        self.partitioning = self.original_partitioning        # RestorePartitioning
        self.reset(points_per_line * num_lines)
        offset = 0                                            # IsoLineGeneratePoints
        for line in range(num_lines):
            for point in range(points_per_line):
                self.parity = density_parity
                fxp_v = self.place(density_ctx, line)
                self.parity = detail_parity
                fxp_u = self.place(detail_ctx, point)
                self.define_point(fxp_u, fxp_v, offset)
                offset += 1
        offset = 0                                            # IsoLineGenerateConnectivity
        for line in range(num_lines):
            for point in range(points_per_line):
                if self.output_primitive == OUTPUT_POINT:
                    self.define_index(offset, self.num_indices)
                    self.num_indices += 1
                elif point > 0:
                    self.define_index(offset - 1, self.num_indices)
                    self.define_index(offset, self.num_indices + 1)
                    self.num_indices += 2
                offset += 1


# -- the API -----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Tessellation:
    """One patch's tessellation: domain points `u`, `v` (P,) float32 in the order the
    evaluation shader runs on them; `indices` (I,) int32 into them, in primitive order;
    `primitive` "triangles", "lines" or "points"; `domain` the patch's. Arrays read-only."""
    domain: str
    u: np.ndarray
    v: np.ndarray
    indices: np.ndarray
    primitive: str

    @property
    def vertices_per_primitive(self) -> int:
        return {"triangles": 3, "lines": 2, "points": 1}[self.primitive]


def output_primitive(domain: str, order: str, point_mode: bool) -> int:
    """p_tessellator.cpp's choice: points, isolines' lines, else triangles, D3D clockwise for
    GL's ccw (draw_tess.c passes !vertex_order_cw as tes_vertex_order_cw)."""
    if point_mode:
        return OUTPUT_POINT
    if domain == "isolines":
        return OUTPUT_LINE
    return OUTPUT_TRIANGLE_CW if order == "ccw" else OUTPUT_TRIANGLE_CCW


def tessellate(domain: str, spacing: str, outer, inner=(), order: str = "ccw",
               point_mode: bool = False) -> Tessellation:
    """The tessellation of one patch whose control shader wrote `outer`
    (gl_TessLevelOuter, the first 4, 3 or 2 the domain reads) and `inner` (gl_TessLevelInner,
    2, 1 or none), each rounded to float32 first."""
    if domain not in DOMAINS:
        raise ValueError(f"unknown domain {domain!r}: one of {', '.join(DOMAINS)}")
    if spacing not in SPACINGS:
        raise ValueError(f"unknown spacing {spacing!r}: one of {', '.join(SPACINGS)}")
    if order not in ORDERS:
        raise ValueError(f"unknown vertex order {order!r}: one of {', '.join(ORDERS)}")
    outer_read, inner_read = {"quads": (4, 2), "triangles": (3, 1), "isolines": (2, 0)}[domain]
    outer, inner = tuple(outer), tuple(inner)
    if len(outer) < outer_read or len(inner) < inner_read:
        raise ValueError(f"{domain} read {outer_read} outer and {inner_read} inner levels, "
                         f"not {len(outer)} and {len(inner)}")
    with np.errstate(over="ignore"):                  # a level beyond float32 is its infinity
        levels32 = np.array(outer[:outer_read] + inner[:inner_read], dtype=np.float64).astype(np.float32)
    bits = tuple(int(b) for b in levels32.view(np.uint32))
    return _tessellate(domain, spacing, order, bool(point_mode), bits)


@functools.lru_cache(maxsize=1024)
def _tessellate(domain: str, spacing: str, order: str, point_mode: bool, bits: tuple) -> Tessellation:
    """tessellate() on the levels' float32 bit patterns (a NaN is a key like any other)."""
    # Denormals are zero: Mesa's draw_vbo runs the draw module, the tessellator included, with
    # the CPU's DAZ and FTZ bits set (util_fpstate_set_denorms_to_zero, "the behavior required
    # by D3D10"), so a denormal level reads as a zero of its sign everywhere, and a positive
    # denormal outer level culls the patch (the C's `!(level > 0)`), as a zero one does.
    levels = [tess_flush(struct.unpack("<f", struct.pack("<I", b))[0]) for b in bits]
    tessellator = HWTessellator(PARTITIONING[spacing], output_primitive(domain, order, point_mode))
    {"quads": tessellator.tessellate_quad_domain, "triangles": tessellator.tessellate_tri_domain,
     "isolines": tessellator.tessellate_iso_line_domain}[domain](*levels)
    points, count = tessellator.points, tessellator.num_indices
    indices, beyond = tessellator.indices[:count], tessellator.indices[count:]
    # the port's own bookkeeping: every point defined, every index slot up to the count written
    # and none after it
    assert len(points) == tessellator.num_points and None not in points, "a point left undefined"
    assert None not in indices and beyond.count(None) == len(beyond), "index count mismatch"
    fxp = np.array(points, dtype=np.uint32).reshape(-1, 2)
    u, v = fixed_to_float(fxp[:, 0]), fixed_to_float(fxp[:, 1])
    index_array = np.array(indices, dtype=np.int32)
    for array in (u, v, index_array):
        array.flags.writeable = False
    primitive = "points" if point_mode else "lines" if domain == "isolines" else "triangles"
    return Tessellation(domain, u, v, index_array, primitive)


def tess_coord(tessellation: Tessellation) -> np.ndarray:
    """(P, 3) float32: gl_TessCoord at each domain point as llvmpipe's evaluation shader
    builds it from the tessellator's (u, v): (u, v, (1 - u) - v) for triangles, each step
    rounded to float32; (u, v, 0) for quads and isolines."""
    u, v = tessellation.u, tessellation.v
    if tessellation.domain == "triangles":
        w = (np.float32(1) - u) - v
    else:
        w = np.zeros_like(u)
    return np.stack([u, v, w], axis=1)


def primitive_vertices(tessellation: Tessellation) -> np.ndarray:
    """(I, 3) float32: gl_TessCoord of each primitive's vertices in order, as transform
    feedback captures them from an evaluation shader that writes gl_TessCoord."""
    return tess_coord(tessellation)[tessellation.indices]


# -- one draw of many patches (draw_tess.c) ---------------------------------------------------------

PATCH_RUN_VERTICES = 4096          # llvmpipe cuts a draw of patches into runs of this many input vertices
ELEMENT_INDEX_BITS = 16            # draw_tess.c's element indices are ushort
MAX_RUN_POINTS = 1 << ELEMENT_INDEX_BITS


def patch_runs(count: int, patch_vertices: int = 1) -> list[range]:
    """The runs (patch numbers) llvmpipe's draw module cuts an array draw of `count` patches of
    `patch_vertices` vertices into: PATCH_RUN_VERTICES // patch_vertices patches each (measured
    by capture for 1, 2, 3, 4, 16 and 32 vertices a patch). Each run is tessellated on its own
    (draw_tess_eval_shader_run), and gl_PrimitiveID restarts at 0 in each."""
    size = PATCH_RUN_VERTICES // patch_vertices
    return [range(start, min(start + size, count)) for start in range(0, count, size)]


def run_points(tessellations, patch_vertices: int = 1) -> list[int]:
    """The domain points of each run of the draw (patch_runs). A run of more than
    MAX_RUN_POINTS is drawn wrong by llvmpipe: see captured_draw."""
    tessellations = list(tessellations)
    return [sum(len(tessellations[p].u) for p in run) for run in patch_runs(len(tessellations), patch_vertices)]


@dataclass(frozen=True)
class DrawCapture:
    """What transform feedback captures of one draw of many patches, vertex by vertex of each
    primitive: `tess_coord` (V, 3) float32, the gl_TessCoord the vertex was shaded with;
    `patch` (V,) int64, the patch (its number in the draw) whose domain point that is;
    `primitive_id` (V,) int64, gl_PrimitiveID as llvmpipe's evaluation shader reads it there."""
    tess_coord: np.ndarray
    patch: np.ndarray
    primitive_id: np.ndarray


def captured_draw(tessellations, patch_vertices: int = 1) -> DrawCapture:
    """One draw call of these patches as llvmpipe 22.3.6's draw module makes it (draw_tess.c,
    draw_tess_eval_shader_run), run by run (patch_runs): a run's patches' points appended to
    one vertex array in patch order (vert_start accumulates; a culled patch adds none), each
    primitive vertex's element index vert_start + index stored as a uint16. While a run has
    at most MAX_RUN_POINTS points that is each patch's own tessellation, in order; past that
    the element indices wrap modulo 2^16, and the later primitives take their vertices from
    the run's first patches: the renderer must split such draws."""
    tessellations = list(tessellations)
    coords_of = {id(t): tess_coord(t) for t in tessellations}       # patches share cached ones
    coords, patches, primitive_ids = [], [], []
    for run in patch_runs(len(tessellations), patch_vertices):
        vertices = [coords_of[id(tessellations[p])] for p in run]
        owners = [np.full(len(v), p, np.int64) for p, v in zip(run, vertices)]
        starts = np.cumsum([0] + [len(v) for v in vertices])
        elements = np.concatenate([(start + tessellations[p].indices.astype(np.int64)) % MAX_RUN_POINTS
                                   for start, p in zip(starts, run)] + [np.zeros(0, np.int64)])
        if len(elements):
            owner = np.concatenate(owners)[elements]
            coords.append(np.concatenate(vertices)[elements])
            patches.append(owner)
            primitive_ids.append(owner - run.start)
    if not coords:
        return DrawCapture(np.zeros((0, 3), np.float32), np.zeros(0, np.int64), np.zeros(0, np.int64))
    return DrawCapture(np.concatenate(coords), np.concatenate(patches), np.concatenate(primitive_ids))
