"""The GPU path: GL contexts (EGL, OSMesa, adopted windows), shader variants from glsl/, uniform
packing and GpuRenderer, which draws a scene through them. Imports core only.

    from renderer.gpu import GpuRenderer
"""

from renderer.gpu.pipeline import GpuRenderer, multisample_counts

__all__ = ["GpuRenderer", "multisample_counts"]
