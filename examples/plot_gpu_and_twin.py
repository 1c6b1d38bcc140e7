"""
The GPU and its twin
====================

The default scene drawn twice: by the GLSL pipeline on the GPU path (llvmpipe here) and by
the NumPy reference, written apart from the GLSL. The third picture is where they differ, a
hundred times brighter: the rasteriser's rules (the fill rule, sub-pixel bits, unorm
rounding) are the same in both, so almost nothing shows.
"""

import matplotlib.pyplot as plt
import numpy as np

from renderer.core.scene_file import load_scene
from renderer.methods import open_renderer

scene = load_scene("sphere")
size = (240, 180)
with open_renderer(scene, size) as gpu:
    drawn = gpu.render().rgba8
twin = open_renderer(scene, size, backend="reference").render().rgba8
difference = np.abs(drawn[..., :3].astype(int) - twin[..., :3].astype(int))

figure, axes = plt.subplots(1, 3, figsize=(9, 2.6))
for axis, image, title in zip(axes, (drawn, twin, np.clip(difference * 100, 0, 255).astype(np.uint8)),
                              ("GPU (GLSL)", "NumPy reference", "difference x 100")):
    axis.imshow(image)
    axis.set_title(title)
    axis.axis("off")
figure.tight_layout()
plt.show()
