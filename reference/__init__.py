"""The NumPy reference pipeline: the same stages as the GLSL in glsl/, written independently.

It shares the scene model and the matrices with the GPU path (renderer/core/scene.py,
renderer/core/transforms.py) and nothing of the shading.
"""

from reference.pipeline import render

__all__ = ["render"]
