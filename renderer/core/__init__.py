"""The scene model and what both pipelines share: scenes and scene files, meshes and
primitives, the matrices, frames, frustum culling, sample patterns, image files and the GL
rules (gl_rules.py). Imports nothing of the renderer above it; the reference imports only this."""
