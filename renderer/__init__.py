"""A real-time GLSL renderer whose every image is checked against a NumPy reference.

The pipeline stages live in glsl/ (GPU) and reference/ (NumPy), with the same names;
docs/conventions.md fixes every convention both follow.
"""

__version__ = "0.1.0"
