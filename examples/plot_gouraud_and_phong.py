"""
Gouraud and Phong shading
=========================

The same coarse sphere shaded per vertex (Gouraud, left) and per fragment (Phong, right),
and point lights just above coarse grids, where Gouraud misses the pool of light that Phong
shows: two of the built-in scenes, on the GPU path.
"""

import matplotlib.pyplot as plt

from renderer.core.scene_file import load_scene
from renderer.methods import open_renderer

figure, axes = plt.subplots(1, 2, figsize=(9, 3.4))
for axis, name in zip(axes, ("gouraud_vs_phong", "point_light_plane")):
    with open_renderer(load_scene(name), (320, 240)) as gpu:
        axis.imshow(gpu.render().rgba8)
    axis.set_title(name)
    axis.axis("off")
figure.tight_layout()
plt.show()
