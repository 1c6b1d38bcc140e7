"""
The rasteriser and the ray tracer
=================================

One scene, two methods through the same `open_renderer`: the rasteriser with its shadow
maps, and the ray tracer (4 samples a pixel on a jittered grid) with exact shadows, the
mirror's reflection and the glass sphere's refraction.
"""

import matplotlib.pyplot as plt

from renderer.core.ray_options import RayOptions
from renderer.core.scene_file import load_scene
from renderer.methods import open_renderer

scene = load_scene("classic")
size = (240, 180)
with open_renderer(scene, size) as raster:
    rasterised = raster.render().rgba8
with open_renderer(scene, size, method="raytrace",
                   options=RayOptions(samples=4, pattern="jittered")) as tracer:
    traced = tracer.render().rgba8

figure, axes = plt.subplots(1, 2, figsize=(8, 3.2))
for axis, image, title in zip(axes, (rasterised, traced), ("rasteriser", "ray tracer, 4 spp")):
    axis.imshow(image)
    axis.set_title(title)
    axis.axis("off")
figure.tight_layout()
plt.show()
