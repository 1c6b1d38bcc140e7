"""The twin of GL's tessellation stage: the fixed-function tessellator as llvmpipe runs it
(`tessellator.py`), the domain points and primitives it hands the evaluation shader.

Its capture harness, glsl/tessellation/capture.vert, capture.tesc, capture.tese, is a test's
(tests/tessellation_capture.py); the renderer draws no tessellated patch yet (issue 34)."""
