"""What a render hands back, from either pipeline."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# How an image file shows where nothing was drawn (docs/conventions.md, "Colour"):
# "opaque": RGB, the scene's background colour, as an image viewer shows the picture;
# "transparent": RGBA with the coverage alpha of rgba8 (0 where nothing was drawn).
BACKGROUNDS = ("opaque", "transparent")


def image_size(width, height) -> tuple[int, int]:
    """(width, height) as ints, each at least 1 pixel, or a ValueError: the size a renderer
    is made or resized at."""
    if int(width) < 1 or int(height) < 1:
        raise ValueError(f"image size must be at least 1x1 pixels, got {width}x{height}")
    return int(width), int(height)


@dataclass
class Frame:
    """One rendered image. Row 0 is the top row in every array (docs/conventions.md).

    rgba8:  (H, W, 4) uint8, GL's unorm8 conversion of the clamped colour; alpha is 1 (255)
            where something was drawn and 0 for the background.
    linear: (H, W, 4) float32 linear colour before clamping, or None if not asked for.
    depth:  (H, W) float32 camera-space distance along the viewing axis in scene units,
            +inf where nothing was drawn, or None if not asked for.
    milliseconds: wall time of the render call that produced it.
    rgba8_tie: from the reference only, where some pixels' two nearest surfaces are closer in
            window depth than GL's float32 arithmetic can order (reference/depth_buffer.py,
            DEPTH_TIE_TOLERANCE): rgba8 with those pixels showing the other surface. GL may
            draw either, so comparisons accept either; also where a shadow-map lookup was
            within float32 rounding of its decision (reference/shadow/lookup.py, "Ties"):
            rgba8 with those pixels lit the other way. None when there is no such pixel.
    shadow_ties: from the reference only, (H, W) bool: the pixels of rgba8_tie that differ
            because of a shadow-map tie (not a depth tie); None with rgba8_tie.
    gl_info: for a GPU frame, the GL implementation that drew it (GpuRenderer.gl_info:
            GL_VENDOR, GL_RENDERER, GL_VERSION, context, depth_format); None from the
            reference. Golden tests record it beside each golden.
    samples: from the ray tracer (either twin), (H, W) int32 camera rays traced per pixel:
            N everywhere but with the adaptive pattern; None from the rasteriser.
    ray_tree: from the reference ray tracer only, (H, W) uint64: per pixel a hash of which
            surface each ray of its samples' ray trees hit and which shadow rays were
            blocked (reference/raytrace/trace.py). Where the float32 and float64 frames'
            differ, the two precisions disagree on a grazing ray (docs/conventions.md).
    """
    rgba8: np.ndarray
    linear: np.ndarray | None = None
    depth: np.ndarray | None = None
    milliseconds: float = 0.0
    rgba8_tie: np.ndarray | None = None
    gl_info: dict | None = None
    samples: np.ndarray | None = None
    ray_tree: np.ndarray | None = None
    shadow_ties: np.ndarray | None = None

    def image(self, background: str = "opaque") -> np.ndarray:
        """The pixels an image file of this frame holds: (H, W, 3) for an opaque background,
        rgba8 itself, with alpha as coverage, for a transparent one (BACKGROUNDS)."""
        if background not in BACKGROUNDS:
            raise ValueError(f"background must be one of {BACKGROUNDS}, got {background!r}")
        return self.rgba8[..., :3] if background == "opaque" else self.rgba8

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self.rgba8.shape[1], self.rgba8.shape[0]
