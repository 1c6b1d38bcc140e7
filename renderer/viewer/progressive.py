"""Progressive ray tracing for the viewer: the running mean of a view's ray-traced frames.

Each frame the viewer traces one sample per pixel (a RayTracer made with SAMPLES_PER_FRAME
and PATTERN) and adds it here; the image shown is the mean linear colour of every sample so
far, converted by gl_rules.to_unorm8 (alpha 255 where some camera ray hit, as the tracer's):
the picture of a render with that many samples per pixel, up to the order of the float sums.
The viewer restarts it whenever the picture would change (camera, size, shading, lights,
materials) and stops tracing once `cap` samples are in.

Each frame brings new samples: `RayTracer.render(first_sample=k)` traces sample indices k,
k + 1, ... of each pixel's sequence (docs/conventions.md, "Progressive frames"), k the samples
summed so far.
"""

from __future__ import annotations

import numpy as np

from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8

MAX_SPP = 256                   # samples per pixel at which the viewer stops refining
PATTERN = "random"              # a new random position in the pixel for every sample
SAMPLES_PER_FRAME = 1           # so that the picture follows a moving camera at once


class Accumulator:
    """Sums a view's frames; see the module docstring.

        acc.restart()               # the view changed: nothing summed
        acc.trace(tracer)           # one more frame (unless done) of a tracer made with
                                    # SAMPLES_PER_FRAME
        acc.samples, acc.done       # samples per pixel so far; whether the cap is reached
        acc.linear, acc.rgba8       # the mean so far, row 0 at the top
    """

    def __init__(self, cap: int = MAX_SPP):
        if cap < 1:
            raise ValueError(f"the cap must be at least 1 sample, got {cap}")
        self.cap = int(cap)
        self.restart()

    def restart(self) -> None:
        self.samples = 0
        self._sum: np.ndarray | None = None          # (H, W, 3) float64: colour x samples
        self._covered: np.ndarray | None = None      # (H, W) bool: some camera ray hit

    @property
    def done(self) -> bool:
        return self.samples >= self.cap

    def add(self, frame: Frame, samples: int) -> None:
        """A frame whose linear colour is the mean of `samples` new samples per pixel."""
        colour = frame.linear[..., :3].astype(np.float64) * samples
        covered = frame.linear[..., 3] > 0
        if self._sum is None:
            self._sum, self._covered = colour, covered
        elif self._sum.shape != colour.shape:
            raise ValueError(f"a {colour.shape[1]}x{colour.shape[0]} frame added to "
                             f"{self._sum.shape[1]}x{self._sum.shape[0]} ones: restart first")
        else:
            self._sum += colour
            self._covered |= covered
        self.samples += samples

    def trace(self, tracer) -> None:
        """Add the tracer's next frame: its sample indices from the count so far on."""
        if not self.done:
            self.add(tracer.render(first_sample=self.samples), SAMPLES_PER_FRAME)

    @property
    def linear(self) -> np.ndarray:
        """(H, W, 4) float32: the mean colour, alpha 1 where some camera ray hit."""
        if self._sum is None:
            raise ValueError("no frame added since the last restart")
        mean = (self._sum / self.samples).astype(np.float32)
        return np.concatenate([mean, self._covered[..., None].astype(np.float32)], -1)

    @property
    def rgba8(self) -> np.ndarray:
        return to_unorm8(self.linear)
