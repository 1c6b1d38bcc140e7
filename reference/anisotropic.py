"""# Twin: GL anisotropic texture filtering (EXT_texture_filter_anisotropic) as llvmpipe does it

llvmpipe's anisotropic filter (Mesa 22.3's lp_build_sample_aniso; reference/sampler.py routes
the "anisotropic" filter here) is not GL's footprint of N probes: it is an elliptical weighted
average (Heckbert's EWA) over the texels of ONE mip level, in float32:

- The level: 0.5 fast_log2(pmin^2), truncated, clamped to the levels, where pmin^2 is the
  smaller of |d(s, t)/dx|^2 and |d(s, t)/dy|^2 in base-level texels; an explicit lod
  (textureLod) is truncated instead, and must be one value for all fragments: llvmpipe then
  reads each 8-fragment vector's level sizes from its first two fragments (a lane mix-up in
  lp_build_sample_aniso with per-fragment lods), which the twin does not follow. The anisotropy N never changes it: llvmpipe means to raise pmin^2 to
  pmax^2 / N^2 but compares pmin^2 > pmin^2 N^2, never true, so N > 1 only turns the path on
  and every N gives the same image (probed: docs/llvmpipe/texture-sampler.md).
- The ellipse at that level: with the quad's derivatives in the level's texels (ux, uy) =
  (ds/dx, ds/dy), (vx, vy) = (dt/dx, dt/dy): A = vx^2 + vy^2 + 1, B = -2 (ux vx + uy vy),
  C = ux^2 + uy^2 + 1, F = A C - B^2 / 4, scaled by 1023 / F; its bounding box around the
  texel-space centre (s W - 1/2, t H - 1/2) is scanned row by row, q = A U^2 + B U V + C V^2
  updated incrementally along a row, and each texel with trunc(q) <= 1023 adds its NEAREST
  texel (float) times the weight table's entry trunc(q) (gl_rules.anisotropic_weight_table).
  The sum is divided by the sum of weights; where that is 0 the level's bilinear result is
  taken instead.
Every float32 operation in llvmpipe's order, none fused. The derivatives are the quad's
(`QuadDerivatives`), also for textureLod.
"""

from __future__ import annotations

import numpy as np

from reference.texels import base_level_pots, cvt_trunc, float_level, float_nearest_axis, texel_levels
from renderer.core.gl_rules import anisotropic_weight_table, fast_log2, unorm8_to_float

f32 = np.float32
_TABLE = anisotropic_weight_table()
_LAST_ENTRY = len(_TABLE) - 1
SCAN_BUDGET = 1 << 20     # box texels (fragments x largest rows x largest columns) scanned at
                          # once: fragments go in order of box size, a group closes at this
LARGEST_BOX = 1 << 26     # texels one fragment's box may have (llvmpipe scans any box; the
                          # twin refuses rather than fill memory: 8192 x 8192 texels)


def anisotropic_level(texture, derivatives, lod=None):
    """The one mip level the EWA reads (int64): trunc(0.5 fast_log2(pmin^2)) or trunc(lod),
    clamped to [0, last]."""
    last = len(texture.levels) - 1
    if lod is not None:
        return np.clip(cvt_trunc(np.asarray(lod, dtype=f32)), 0, last)
    width, height = f32(texture.width), f32(texture.height)
    dsdx, dsdy = derivatives.dudx * width, derivatives.dudy * width
    dtdx, dtdy = derivatives.dvdx * height, derivatives.dvdy * height
    along_x = dsdx * dsdx + dtdx * dtdx
    along_y = dsdy * dsdy + dtdy * dtdy
    pmin2 = np.where(along_x < along_y, along_x, along_y)      # minps: NaN gives along_y
    return np.clip(cvt_trunc(f32(0.5) * fast_log2(pmin2)), 0, last)


def sample_anisotropic(texture, sampler, u, v, *, derivatives=None,
                       lod=None):
    """The anisotropic sampler's colour (N, 4) float32 at float32 (u, v) (N,); `derivatives`
    are needed (the ellipse is the quad's), `lod` (textureLod, one value) only chooses the
    level."""
    if derivatives is None:
        raise ValueError("the anisotropic filter needs the quad's derivatives, also with a lod")
    if lod is not None:
        lod = np.broadcast_to(np.asarray(lod, dtype=f32), u.shape)
        if lod.size and not (lod == lod.flat[0]).all():
            raise ValueError("the anisotropic filter's twin takes one lod for all fragments")
    level = anisotropic_level(texture, derivatives, lod)
    store, pots = texel_levels(texture), base_level_pots(texture)
    ellipse = _Ellipse(texture, derivatives, level, u, v)
    colour = np.zeros((len(u), 4), dtype=f32)
    weight_sum = np.zeros(len(u), dtype=f32)
    for chosen in _groups(ellipse):
        colour[chosen], weight_sum[chosen] = _scan(ellipse.part(chosen), store, level[chosen], pots,
                                                   sampler.wrap)
    with np.errstate(invalid="ignore", divide="ignore"):      # 0 / 0: the fallback below
        colour = (colour / weight_sum[:, None]).astype(f32)
    empty = weight_sum == 0
    if empty.any():
        colour[empty] = float_level(store, level[empty], u[empty], v[empty], "linear", pots, sampler.wrap)
    return colour


def _groups(ellipse):
    """Fragment indices in groups whose scan (count x largest rows x largest columns) stays
    within SCAN_BUDGET (a larger box goes alone), in order of box size."""
    rows, columns = ellipse.v1 - ellipse.v0 + 1, ellipse.u1 - ellipse.u0 + 1
    if (rows * columns).max(initial=0) > LARGEST_BOX:
        raise ValueError(f"an anisotropic lookup's ellipse spans {int((rows * columns).max())} texels; "
                         f"the twin scans at most {LARGEST_BOX}")
    order = np.argsort(rows * columns, kind="stable")
    start = 0
    while start < len(order):
        most_rows = np.maximum.accumulate(rows[order[start:]])
        most_columns = np.maximum.accumulate(columns[order[start:]])
        cost = np.arange(1, len(most_rows) + 1) * most_rows * most_columns
        size = max(1, int(np.searchsorted(cost, SCAN_BUDGET, side="right")))
        yield order[start:start + size]
        start += size


class _Ellipse:
    """The ellipse's coefficients (scaled to the weight table), centre and bounding box per
    fragment, in llvmpipe's float32 order."""

    def __init__(self, texture, derivatives, level, u, v, *, _parts=None):
        if _parts is not None:
            self.__dict__.update(_parts)
            return
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # inf, NaN as llvmpipe's
            self._compute(texture, derivatives, level, u, v)

    def _compute(self, texture, derivatives, level, u, v):
        scaling = (f32(1) / (np.int64(1) << level).astype(f32)).astype(f32)
        width, height = f32(texture.width), f32(texture.height)
        ux = (derivatives.dudx * width).astype(f32) * scaling
        uy = (derivatives.dudy * width).astype(f32) * scaling
        vx = (derivatives.dvdx * height).astype(f32) * scaling
        vy = (derivatives.dvdy * height).astype(f32) * scaling
        a = (vx * vx + vy * vy) + f32(1)
        b = (ux * vx + uy * vy) * f32(-2)
        c = (ux * ux + uy * uy) + f32(1)
        f = a * c - (b * b) / f32(4)
        d = -(b * b) + (a * c) * f32(4)
        box_u = (f32(2) / d) * np.sqrt((d * c) * f)
        box_v = (f32(2) / d) * np.sqrt((a * d) * f)
        scale = f32(_LAST_ENTRY) / f
        self.a, self.b, self.c = a * scale, b * scale, c * scale
        self.tex_u = u * (width * scaling) + f32(-0.5)
        self.tex_v = v * (height * scaling) + f32(-0.5)
        self.u0 = cvt_trunc(np.floor(self.tex_u - box_u))
        self.u1 = cvt_trunc(np.ceil(self.tex_u + box_u))
        self.v0 = cvt_trunc(np.floor(self.tex_v - box_v))
        self.v1 = cvt_trunc(np.ceil(self.tex_v + box_v))

    def part(self, chosen) -> "_Ellipse":
        return _Ellipse(None, None, None, None, None,
                        _parts={name: value[chosen] for name, value in self.__dict__.items()})


def _running_sum(start, steps):
    """start, start + steps[..., 0], ... added one at a time in float32 along the last axis,
    as the scan's loop adds (np.add.accumulate is sequential)."""
    return np.add.accumulate(np.concatenate([start[..., None], steps], axis=-1), axis=-1, dtype=f32)


def _scan(e: _Ellipse, store, level, pots, wrap):
    """Sum of weight x nearest texel, and of weights, over the bounding boxes of `e`, in the
    loop's order (rows from v0, each row from u0), every row of the group at once: q and its
    increment along each row as running sums, then the texels of nonzero weight gathered
    (in loop order, left-aligned per fragment) and summed one at a time (adding a zero
    weight's 0 changes no sum)."""
    n = len(e.a)
    rows, columns = int((e.v1 - e.v0).max()) + 1, int((e.u1 - e.u0).max()) + 1
    width, height = store.width[level][:, None], store.height[level][:, None]
    big_u = e.u0.astype(f32) - e.tex_u
    v_at = e.v0[:, None] + np.arange(rows)                                   # (n, rows)
    big_v = v_at.astype(f32) - e.tex_v[:, None]
    dq_base = ((big_u * f32(2) + f32(1)) * e.a)[:, None]
    q_base = ((big_u * big_u) * e.a)[:, None]
    ddq = np.broadcast_to((e.a * f32(2))[:, None, None], (n, rows, columns - 1))
    dq = _running_sum(big_v * e.b[:, None] + dq_base, ddq)                   # (n, rows, columns)
    q = _running_sum(((e.c[:, None] * big_v) + (e.b * big_u)[:, None]) * big_v + q_base, dq[..., :-1])
    entry = cvt_trunc(q)
    u_at = e.u0[:, None] + np.arange(columns)                                # (n, columns)
    inside = ((u_at <= e.u1[:, None])[:, None, :] & (v_at <= e.v1[:, None])[:, :, None]
              & (entry <= _LAST_ENTRY))
    weight = np.where(inside, _TABLE[np.maximum(entry, 0) & _LAST_ENTRY], f32(0)).reshape(n, -1)
    fragment, position = np.nonzero(weight)                     # row-major: loop order
    count = np.bincount(fragment, minlength=n)
    rank = np.arange(len(fragment)) - np.repeat(np.cumsum(count) - count, count)
    packed = np.zeros((n, max(int(count.max()), 1)), dtype=f32)
    packed[fragment, rank] = weight[fragment, position]
    row, column = np.divmod(position, columns)
    s = (u_at[fragment, column].astype(f32) / width[fragment, 0].astype(f32)).astype(f32)
    t = (v_at[fragment, row].astype(f32) / height[fragment, 0].astype(f32)).astype(f32)
    texels = np.zeros((*packed.shape, 4), dtype=f32)
    texels[fragment, rank] = unorm8_to_float(store.fetch(
        level[fragment], float_nearest_axis(s, width[fragment, 0], pots[0], wrap),
        float_nearest_axis(t, height[fragment, 0], pots[1], wrap)))
    colour = _running_sum(np.zeros((n, 4), dtype=f32).T, (texels * packed[..., None]).transpose(2, 0, 1))
    return colour[..., -1].T, _running_sum(np.zeros(n, dtype=f32), packed)[:, -1]
