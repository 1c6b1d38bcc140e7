"""A real-time GLSL renderer whose every image is checked against a NumPy reference.

The pipeline stages live in glsl/ (GPU) and reference/ (NumPy), with the same names;
docs/conventions.md fixes every convention both follow. The subpackages, each importing only
those below it: core (scene model, matrices, GL rules), gpu (GpuRenderer), checks (comparison,
tolerance, goldens), study (report, extremes), viewer (the window); docs/layout.md.
"""

__version__ = "0.1.0"
