"""The colour pass: CIE XYZ and chromaticity of every pixel of a linear frame, on the GPU
(glsl/output/colour.comp, its twin reference/output/colour.py `colour_planes`).

    with ColourPass(ctx) as colour:              # a context made elsewhere, or context_kind=
        xyz, xyz_chromaticity = colour.apply(frame.linear)

Input (H, W, 4) float32 linear colour, row 0 at the top; outputs (H, W, 4) float32 XYZ with the
alpha kept, and (H, W, 3) float32 x, y, z. The array is uploaded as it is and read back as it
is (array row r is texel row r), so nothing is flipped. A compute shader (GL 4.3) in 8 x 8
work groups; its images are made per size and reused.
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from renderer.core.colour import D65_CHROMATICITY, RGB_TO_XYZ
from renderer.gpu.context import activate, make_context, release_context
from renderer.gpu.shaders import compute_program

GROUP = 8                                 # colour.comp's local_size_x and local_size_y (#define GROUP_SIZE)


class ColourPass:
    """One compiled colour.comp in one context; see the module docstring."""

    def __init__(self, ctx: moderngl.Context | None = None, context_kind: str = "auto"):
        self._owns_context = ctx is None
        self.ctx = make_context(context_kind) if ctx is None else ctx
        self._images: dict[tuple[int, int], tuple] = {}
        self.last_milliseconds = 0.0
        try:
            activate(self.ctx)
            self.program = compute_program(self.ctx, "output/colour.comp", {"GROUP_SIZE": GROUP})
            # GL reads a mat3 column by column: the columns of M are the rows of M's transpose.
            self.program["rgb_to_xyz_matrix"].write(RGB_TO_XYZ.T.astype(np.float32).tobytes())
            self.program["white_chromaticity"].value = tuple(D65_CHROMATICITY.astype(np.float32))
        except BaseException:
            self.release()
            raise

    def _images_for(self, width: int, height: int) -> tuple:
        images = self._images.get((width, height))
        if images is None:
            images = self._images[width, height] = tuple(
                self.ctx.texture((width, height), 4, dtype="f4") for _ in range(3))
        return images

    def apply(self, linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(XYZ and alpha (H, W, 4), chromaticity x, y, z (H, W, 3)), float32."""
        linear = np.ascontiguousarray(linear, dtype=np.float32)
        height, width = linear.shape[:2]
        activate(self.ctx)
        start = time.perf_counter()
        source, xyz, chromaticity = self._images_for(width, height)
        source.write(linear)
        for unit, image in enumerate((source, xyz, chromaticity)):
            image.bind_to_image(unit, read=unit == 0, write=unit > 0)
        self.program.run(-(-width // GROUP), -(-height // GROUP))
        self.ctx.memory_barrier()
        planes = [np.frombuffer(image.read(), np.float32).reshape(height, width, 4)
                  for image in (xyz, chromaticity)]
        self.last_milliseconds = (time.perf_counter() - start) * 1000.0
        return planes[0], np.ascontiguousarray(planes[1][..., :3])

    def release(self) -> None:
        """Free the program and images; the context too if this pass made it. Idempotent."""
        try:
            if self._images or getattr(self, "program", None) is not None:
                activate(self.ctx)
            for images in self._images.values():
                for image in images:
                    image.release()
            if getattr(self, "program", None) is not None:
                self.program.release()
                self.program = None
        finally:
            self._images = {}
            if self._owns_context and self.ctx is not None:
                release_context(self.ctx)
                self.ctx = None

    def __enter__(self) -> "ColourPass":
        return self

    def __exit__(self, *exc) -> None:
        self.release()
