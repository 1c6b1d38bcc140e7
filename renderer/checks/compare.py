"""Comparing two frames the way dEQP does, and the figures `renderer compare` prints.

Threshold compare with position deviation (dEQP tcuImageCompare.cpp,
intThresholdPositionDeviationCompare): a pixel passes when some pixel within ±N of it in
the other image matches within the threshold on every channel, checked both ways
(GPU → reference and reference → GPU). That forgives an edge that moved by one pixel, which
sub-pixel rounding may do, and nothing else.

A second acceptable reference (`reference_tie`, and for depth `reference_tie_depth`) is
accepted wherever it differs from the first: the rasteriser reference's rgba8_tie at depth
ties, and for the ray tracer the float64 reference's colour and depth at grazing pixels, where
the float32 and float64 references' ray trees differ (`grazing_ray_pixels`,
`either_precision`; docs/conventions.md, "Grazing rays").

Where a reference is a range rather than one image (an `Envelope`: the twin rendered at the
corners of the texture verifier's coordinate bound, renderer/checks/texture_bounds.py), a
channel matches within the threshold of the range, and differences are measured from it:
the gap between two ranges, which for two images is their difference.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from renderer.checks.tolerance import PIPELINE_TOLERANCE

# The defaults of every function here: the pipeline tolerance's (renderer/checks/tolerance.py).
DEFAULT_THRESHOLD = PIPELINE_TOLERANCE.threshold          # of 255, per channel
DEFAULT_DEVIATION = PIPELINE_TOLERANCE.deviation          # pixels


@dataclass(frozen=True, eq=False)
class Envelope:
    """Several acceptable references as one: per pixel and channel, the lowest and highest
    of their values ((H, W, C) uint8 each). Where every channel of a result lies within
    [low, high], it differs from the envelope by 0."""
    low: np.ndarray
    high: np.ndarray

    @classmethod
    def of(cls, images) -> "Envelope":
        stack = np.stack(images)
        return cls(stack.min(axis=0), stack.max(axis=0))

    @property
    def shape(self) -> tuple:
        return self.low.shape


def _range(image) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) int16 of an Envelope; (image, image) of an image."""
    if isinstance(image, Envelope):
        return image.low.astype(np.int16), image.high.astype(np.int16)
    values = image.astype(np.int16)
    return values, values


def _gap(a, b) -> np.ndarray:
    """Per channel, how far the ranges a and b ((low, high) pairs) lie apart (0 where they
    overlap): |a - b| for two single values."""
    (a_low, a_high), (b_low, b_high) = a, b
    return np.maximum(np.maximum(b_low - a_high, a_low - b_high), 0)


def _offsets(deviation: int):
    return [(dy, dx) for dy in range(-deviation, deviation + 1) for dx in range(-deviation, deviation + 1)]


def _shifted(image: np.ndarray, dy: int, dx: int, fill) -> np.ndarray:
    """image[y + dy, x + dx] at (y, x), `fill` where that falls outside the image."""
    h, w = image.shape[:2]
    out = np.full_like(image, fill)
    ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
    xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
    out[yd, xd] = image[ys, xs]
    return out


def _matches_nearby(a, b, threshold: int, deviation: int) -> np.ndarray:
    """(H, W) bool: pixel of `a` has a pixel of `b` within ±deviation matching within threshold
    (either may be an Envelope)."""
    a_range, (b_low, b_high) = _range(a), _range(b)
    ok = np.zeros(a.shape[:2], dtype=bool)
    for dy, dx in _offsets(deviation):
        nearby = (_shifted(b_low, dy, dx, fill=np.int16(-1000)),   # outside never matches
                  _shifted(b_high, dy, dx, fill=np.int16(-1000)))
        ok |= _gap(a_range, nearby).max(axis=-1) <= threshold
    return ok


def position_deviation_mismatch(result: np.ndarray, reference,
                                threshold: int = DEFAULT_THRESHOLD,
                                deviation: int = DEFAULT_DEVIATION,
                                reference_tie=None) -> np.ndarray:
    """(H, W) bool mask of pixels that fail the dEQP compare in either direction.

    `reference_tie` (the reference frame's rgba8_tie) is a second acceptable reference: at
    a depth tie either surface may show, so a pixel matching either one matches. Either
    reference may be an Envelope.
    """
    result_ok = _matches_nearby(result, reference, threshold, deviation)
    reference_ok = _matches_nearby(reference, result, threshold, deviation)
    if reference_tie is not None:
        result_ok |= _matches_nearby(result, reference_tie, threshold, deviation)
        reference_ok |= _matches_nearby(reference_tie, result, threshold, deviation)
    return ~(result_ok & reference_ok)


def channel_difference(result: np.ndarray, reference, reference_tie=None) -> np.ndarray:
    """(H, W, C) int16 |result - reference| per channel (from an Envelope: how far outside it);
    where `reference_tie` (the reference frame's rgba8_tie) is nearer in its largest channel,
    against that instead."""
    diff = _gap(_range(result), _range(reference))
    if reference_tie is not None:
        tie_diff = _gap(_range(result), _range(reference_tie))
        closer = tie_diff.max(axis=-1) < diff.max(axis=-1)
        diff[closer] = tie_diff[closer]
    return diff


def raw_mismatch(result: np.ndarray, reference, threshold: int = DEFAULT_THRESHOLD,
                 reference_tie=None) -> np.ndarray:
    """(H, W) bool mask of pixels with any channel off by more than the threshold (from
    both the reference and, if given, its depth-tie alternative)."""
    return channel_difference(result, reference, reference_tie).max(axis=-1) > threshold


def _depth_rel_nearby(a: np.ndarray, b: np.ndarray, deviation: int) -> np.ndarray:
    """Per pixel of `a`: smallest relative difference to a depth of `b` within ±deviation, or
    to `b`'s surface there continued by one pixel towards `a`'s (b(p+d) - (b(p+2d) - b(p+d)),
    where both are finite): at a silhouette seen edge-on, the surface's depth changes by more
    than the limit from one pixel to the next, so the pixel one image covers and the other
    does not is held against the other's surface extrapolated to it, not its neighbour."""
    b = b.astype(np.float64)
    best = np.full(a.shape, np.inf)
    for dy, dx in _offsets(deviation):
        nearby = _shifted(b, dy, dx, fill=np.inf)
        candidates = [nearby]
        if (dy, dx) != (0, 0):
            beyond = _shifted(b, 2 * dy, 2 * dx, fill=np.inf)
            with np.errstate(invalid="ignore"):
                candidates.append(np.where(np.isfinite(beyond), 2 * nearby - beyond, np.inf))
        for depth in candidates:
            with np.errstate(invalid="ignore", divide="ignore"):
                rel = np.abs(a - depth) / np.abs(depth)
            best = np.fmin(best, np.where(np.isfinite(depth), rel, np.inf))
    return best


def depth_max_rel(result: np.ndarray, reference: np.ndarray, deviation: int = DEFAULT_DEVIATION,
                  reference_tie: np.ndarray | None = None) -> float:
    """Largest relative depth difference where both drew, with the same ±deviation as colour.

    At a silhouette one image may see the object and the other the one behind it, exactly as
    with colour, so each pixel is held against the nearest-matching depth within ±deviation,
    both ways. `reference_tie`, a second acceptable reference depth (the other precision's at
    grazing rays, `either_precision`), counts wherever it is nearer.
    """
    references = [reference] if reference_tie is None else [reference, reference_tie]
    both = np.isfinite(result) & np.logical_or.reduce([np.isfinite(r) for r in references])
    if not both.any():
        return 0.0
    forward = np.fmin.reduce([_depth_rel_nearby(result, r, deviation) for r in references])
    backward = np.fmin.reduce([_depth_rel_nearby(r, result, deviation) for r in references])
    return float(max(forward[both].max(), backward[both].max()))


def depth_tie_pixels(reference_frame) -> int:
    """Pixels where the reference accepts another colour because of a depth tie (or, from the
    ray tracer, the adaptive pattern's other decision): not a shadow-map tie."""
    tie = reference_frame.rgba8_tie
    if tie is None:
        return 0
    other = (tie != reference_frame.rgba8).any(axis=-1)
    shadow = getattr(reference_frame, "shadow_ties", None)
    return int((other if shadow is None else other & ~shadow).sum())


def shadow_tie_pixels(reference_frame) -> int:
    """Pixels where the reference accepts another colour because a shadow-map lookup was within
    float32 rounding of its decision (reference/shadow/lookup.py, "Ties")."""
    shadow = getattr(reference_frame, "shadow_ties", None)
    return 0 if shadow is None else int(shadow.sum())


def grazing_ray_pixels(reference32, reference64) -> np.ndarray:
    """(H, W) bool: where the reference ray tracer in float32 and in float64 disagree on a
    grazing ray: some sample's ray tree (Frame.ray_tree: which surface each camera, secondary
    and shadow ray hit) differs (docs/conventions.md, "Grazing rays")."""
    return reference32.ray_tree != reference64.ray_tree


def either_precision(frame, other) -> tuple[np.ndarray | None, np.ndarray | None, int]:
    """(rgba8, depth, pixels) for two reference ray-traced frames, float32 and float64 either
    way round: the second acceptable reference that compare_frames takes as reference_tie and
    reference_tie_depth, and how many pixels graze. At grazing pixels `other`'s colour and
    depth; elsewhere `frame`'s own alternative (rgba8_tie: the adaptive pattern's other
    decision) or its image. (frame.rgba8_tie, None, 0) where no pixel grazes."""
    grazing = grazing_ray_pixels(frame, other)
    if not grazing.any():
        return frame.rgba8_tie, None, 0
    base = frame.rgba8 if frame.rgba8_tie is None else frame.rgba8_tie
    return (np.where(grazing[..., None], other.rgba8, base),
            np.where(grazing, other.depth, frame.depth), int(grazing.sum()))


@dataclass
class Comparison:
    max_abs: int                  # largest channel difference, 0..255 (RGB)
    mean_abs: float               # mean channel difference (RGB)
    rmse: float                   # root mean square channel difference (RGB), 0..255 scale
    psnr: float                   # dB on the 8-bit scale; inf for identical images
    raw_mismatched_pixels: int    # pixels with any RGBA channel off by more than threshold
    raw_mismatched_fraction: float
    mismatched_pixels: int        # pixels still failing with ±deviation allowed, both ways
    mismatched_fraction: float
    depth_max_rel: float | None   # largest relative depth difference where both drew
    threshold: int
    deviation: int

    def as_dict(self) -> dict:
        return asdict(self)


def compare_frames(result_rgba8: np.ndarray, reference_rgba8,
                   result_depth: np.ndarray | None = None, reference_depth: np.ndarray | None = None,
                   threshold: int = DEFAULT_THRESHOLD, deviation: int = DEFAULT_DEVIATION,
                   reference_tie=None,
                   reference_tie_depth: np.ndarray | None = None) -> Comparison:
    """The figures of `renderer compare`. `reference_tie`: the reference frame's rgba8_tie,
    accepted wherever it differs (pixels at a depth tie), or the other precision's colour at
    grazing rays (`either_precision`, with its depth as `reference_tie_depth`); max_abs and
    the like measure against the nearer of the two there. Either colour reference may be an
    Envelope (texture_bounds.py), measured from its range."""
    if result_rgba8.shape != reference_rgba8.shape:
        raise ValueError(f"image sizes differ: {result_rgba8.shape} and {reference_rgba8.shape}")
    difference = channel_difference(result_rgba8, reference_rgba8, reference_tie)
    diff = difference[..., :3]
    total = result_rgba8.shape[0] * result_rgba8.shape[1]
    rmse = float(np.sqrt(np.mean(diff.astype(np.float64) ** 2)))
    raw = int((difference.max(axis=-1) > threshold).sum())
    deq = int(position_deviation_mismatch(result_rgba8, reference_rgba8, threshold, deviation,
                                          reference_tie).sum())
    depth = None
    if result_depth is not None and reference_depth is not None:
        depth = depth_max_rel(result_depth, reference_depth, deviation, reference_tie_depth)
    return Comparison(
        max_abs=int(diff.max()), mean_abs=float(diff.mean()), rmse=rmse,
        psnr=math.inf if rmse == 0 else 20 * math.log10(255.0 / rmse),
        raw_mismatched_pixels=raw, raw_mismatched_fraction=raw / total,
        mismatched_pixels=deq, mismatched_fraction=deq / total,
        depth_max_rel=depth, threshold=threshold, deviation=deviation,
    )


# Heat-map ramp: black (equal) → red → yellow → white (8 or more levels off).
_RAMP = np.array([[0, 0, 0], [180, 0, 0], [255, 200, 0], [255, 255, 255]], dtype=np.float64)
_RAMP_FULL_SCALE = 8.0
_MISMATCH_COLOUR = (255, 0, 255)


def heat_map(result_rgba8: np.ndarray, reference_rgba8,
             threshold: int = DEFAULT_THRESHOLD, deviation: int = DEFAULT_DEVIATION,
             reference_tie=None) -> np.ndarray:
    """(H, W, 3) uint8 amplified difference: the ramp reaches white at 8 levels of 255, and
    pixels that fail the position-deviation compare are magenta."""
    diff = channel_difference(result_rgba8, reference_rgba8, reference_tie).max(axis=-1)
    t = np.clip(diff / _RAMP_FULL_SCALE, 0.0, 1.0) * (len(_RAMP) - 1)
    lo = np.floor(t).astype(int)
    hi = np.minimum(lo + 1, len(_RAMP) - 1)
    frac = (t - lo)[..., None]
    image = _RAMP[lo] * (1 - frac) + _RAMP[hi] * frac
    image[position_deviation_mismatch(result_rgba8, reference_rgba8, threshold, deviation,
                                      reference_tie)] = _MISMATCH_COLOUR
    return image.round().astype(np.uint8)
