"""
Quantisation, dithering and half-toning
=======================================

The output stage turns linear colour into codes: here the globe at 1 bit per channel,
rounded to the nearest code, ordered-dithered with an 8 x 8 Bayer matrix, error-diffused
(Floyd-Steinberg), and printed as a CMYK half-tone; the NumPy twin of the GPU's pass.
"""

import matplotlib.pyplot as plt

import reference.output
from renderer.core.output_settings import OutputSettings, Transfer, parse_halftone
from renderer.core.scene_file import load_scene
from renderer.methods import open_renderer

with open_renderer(load_scene("globe"), (200, 150)) as gpu:
    linear = gpu.render(linear=True).linear

srgb = Transfer("srgb")
stages = {"nearest": OutputSettings(transfer=srgb, bits=1),
          "Bayer 8x8": OutputSettings(transfer=srgb, bits=1, dither="bayer8"),
          "Floyd-Steinberg": OutputSettings(transfer=srgb, bits=1, dither="floyd-steinberg"),
          "half-tone": OutputSettings(transfer=srgb, halftone=parse_halftone("6:15"))}
figure, axes = plt.subplots(1, len(stages), figsize=(11, 2.6))
for axis, (title, settings) in zip(axes, stages.items()):
    codes = reference.output.apply(linear, settings)[..., :3]
    axis.imshow(codes / ((1 << settings.code_bits) - 1), interpolation="nearest")
    axis.set_title(title)
    axis.axis("off")
figure.tight_layout()
plt.show()
