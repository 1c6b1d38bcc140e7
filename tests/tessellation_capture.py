"""GL's tessellator captured by transform feedback, for tests/test_tessellator.py.

capture(ctx, domain, spacing, levels, ...) draws one patch a row of `levels` (N, 6): each
patch is one vertex carrying gl_TessLevelOuter[0..3] and gl_TessLevelInner[0..1]
(glsl/tessellation/capture.vert, capture.tesc), and the evaluation shader (capture.tese, its
layout from defines) hands on gl_TessCoord and gl_PrimitiveID; transform feedback captures
them vertex by vertex of each primitive (triangles, lines or points), rasterisation
discarded. moderngl's transform() refuses GL_PATCHES, so the draw is made with GL's own entry
points (renderer.gpu.context.gl_function) on moderngl's objects, and every GL object is
released, and the state put back, before it returns.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np

from renderer.gpu.context import activate, gl_function
from renderer.gpu.shaders import shader_source

GL_POINTS, GL_LINES, GL_TRIANGLES, GL_PATCHES = 0x0000, 0x0001, 0x0004, 0x000E
GL_TRANSFORM_FEEDBACK_BUFFER = 0x8C8E
GL_RASTERIZER_DISCARD = 0x8C89
GL_PRIMITIVES_GENERATED = 0x8C87
GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN = 0x8C88
GL_QUERY_RESULT = 0x8866

CAPTURED = np.dtype([("tess_coord", "<f4", 3), ("patch_id", "<i4")])   # interleaved, 16 bytes
VERTICES_PER_PRIMITIVE = {"triangles": 3, "lines": 2, "points": 1}


@dataclass
class Captured:
    """What one draw's transform feedback holds: `tess_coord` (V, 3) float32 and `patch_id`
    (V,) int32, V = primitives x vertices per primitive, in capture order; `generated`, the
    primitives GL generated (more than were written when the buffer was too small)."""
    tess_coord: np.ndarray
    patch_id: np.ndarray
    primitive: str
    generated: int
    written: int


def capture_defines(domain: str, spacing: str, order: str, point_mode: bool) -> dict:
    """capture.tese's defines for a layout in GL's names ("quads", "fractional_odd_spacing", "cw")."""
    return {f"DOMAIN_{domain.upper()}": True,
            f"SPACING_{spacing.removesuffix('_spacing').upper()}": True,
            f"ORDER_{order.upper()}": True,
            "POINT_MODE": bool(point_mode)}


def _gl(ctx):
    uint, sizei = ctypes.c_uint, ctypes.c_int
    signatures = {
        "glUseProgram": (uint,), "glBindVertexArray": (uint,),
        "glBindBufferBase": (uint, uint, uint), "glEnable": (uint,), "glDisable": (uint,),
        "glBeginTransformFeedback": (uint,), "glEndTransformFeedback": (),
        "glDrawArrays": (uint, sizei, sizei),
        "glGenQueries": (sizei, ctypes.POINTER(uint)), "glDeleteQueries": (sizei, ctypes.POINTER(uint)),
        "glBeginQuery": (uint, uint), "glEndQuery": (uint,),
        "glGetQueryObjectuiv": (uint, uint, ctypes.POINTER(uint)),
    }
    functions = {name: gl_function(ctx, name, None, *args) for name, args in signatures.items()}
    missing = [name for name, function in functions.items() if function is None]
    if missing:
        raise RuntimeError(f"GL entry points not found: {', '.join(missing)}")
    return functions


def capture(ctx, domain: str, spacing: str, levels, order: str = "ccw", point_mode: bool = False,
            capacity: int = 0, patch_vertices: int = 1) -> Captured:
    """Draws len(levels) patches in one draw call and captures their primitives' vertices.
    `levels`: (N, 6) outer[0..3], inner[0..1] per patch (float32). `capacity`: the vertices
    the capture buffer holds (at least 1). `patch_vertices`: the vertices of each input patch
    (GL_PATCH_VERTICES, 1 to 32; each a copy of the patch's levels, the first one read)."""
    levels = np.ascontiguousarray(levels, dtype=np.float32).reshape(-1, 6)
    patches = len(levels)
    primitive = "points" if point_mode else "lines" if domain == "isolines" else "triangles"
    feedback_mode = {"triangles": GL_TRIANGLES, "lines": GL_LINES, "points": GL_POINTS}[primitive]
    defines = capture_defines(domain, spacing, order, point_mode)
    activate(ctx)
    program = ctx.program(vertex_shader=shader_source("tessellation/capture.vert").text,
                          tess_control_shader=shader_source("tessellation/capture.tesc").text,
                          tess_evaluation_shader=shader_source("tessellation/capture.tese", defines).text,
                          varyings=["tess_coord", "patch_id"])
    vbo = ctx.buffer(np.repeat(levels, patch_vertices, axis=0).tobytes())
    vao = None
    try:
        vao = ctx.vertex_array(program, [(vbo, "4f 2f", "in_outer", "in_inner")])
        data, generated, written = feedback(ctx, program, vao, patches * patch_vertices, patch_vertices,
                                            primitive, capacity, CAPTURED)
    finally:
        for item in (vao, vbo, program):
            if item is not None:
                item.release()
    return Captured(np.array(data["tess_coord"]), np.array(data["patch_id"]), primitive, generated, written)


def feedback(ctx, program, vao, vertices: int, patch_vertices: int, primitive: str, capacity: int,
             dtype: np.dtype) -> tuple[np.ndarray, int, int]:
    """Draws `vertices` vertices of `vao` as patches of `patch_vertices` with `program`,
    rasterisation discarded, and captures its output primitives' vertices (interleaved as
    `dtype`, at most `capacity`): (the captured records, primitives generated, written)."""
    gl = _gl(ctx)
    feedback_mode = {"triangles": GL_TRIANGLES, "lines": GL_LINES, "points": GL_POINTS}[primitive]
    out = ctx.buffer(reserve=max(1, capacity) * dtype.itemsize)
    framebuffer = ctx.simple_framebuffer((4, 4))             # transform feedback needs one bound
    queries = (ctypes.c_uint * 2)()
    patch_vertices_before = ctx.patch_vertices
    try:
        framebuffer.use()
        ctx.patch_vertices = patch_vertices
        gl["glGenQueries"](2, queries)
        gl["glUseProgram"](program.glo)
        gl["glBindVertexArray"](vao.glo)
        gl["glBindBufferBase"](GL_TRANSFORM_FEEDBACK_BUFFER, 0, out.glo)
        gl["glEnable"](GL_RASTERIZER_DISCARD)
        gl["glBeginQuery"](GL_PRIMITIVES_GENERATED, queries[0])
        gl["glBeginQuery"](GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, queries[1])
        gl["glBeginTransformFeedback"](feedback_mode)
        gl["glDrawArrays"](GL_PATCHES, 0, vertices)
        gl["glEndTransformFeedback"]()
        gl["glEndQuery"](GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN)
        gl["glEndQuery"](GL_PRIMITIVES_GENERATED)
        counts = []
        for query in queries:
            value = ctypes.c_uint()
            gl["glGetQueryObjectuiv"](query, GL_QUERY_RESULT, ctypes.byref(value))
            counts.append(value.value)
        generated, written = counts
        captured = written * VERTICES_PER_PRIMITIVE[primitive]
        data = np.frombuffer(out.read(size=captured * dtype.itemsize), dtype).copy() if captured else \
            np.zeros(0, dtype)
    finally:
        gl["glDisable"](GL_RASTERIZER_DISCARD)
        gl["glBindBufferBase"](GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0)
        gl["glBindVertexArray"](0)
        gl["glUseProgram"](0)
        gl["glDeleteQueries"](2, queries)
        ctx.patch_vertices = patch_vertices_before
        for item in (out, framebuffer):
            item.release()
    return data, generated, written


STAGE_OUTPUTS = np.dtype([("position", "<f4", 3), ("normal", "<f4", 3), ("levels", "<f4", 4)])


def capture_stages(ctx, defines: dict, corners: np.ndarray, layout: str, attributes: tuple,
                   uniforms, extra: dict | None = None) -> np.ndarray:
    """The rasteriser's own stages (glsl/tess_vertex.glsl, tess_control.glsl,
    tess_evaluation.glsl with `defines` and CAPTURE) drawing `corners` ((P * 3, K) float32,
    three rows a triangle patch, read as `layout` into `attributes`) with the control uniforms
    (a reference.tessellation.control.ControlUniforms) and `extra` ones: each primitive
    vertex's point, normal and its patch's levels (STAGE_OUTPUTS), in order."""
    activate(ctx)
    from renderer.core import transforms
    program = ctx.program(vertex_shader=shader_source("tess_vertex.glsl", defines).text,
                          tess_control_shader=shader_source("tess_control.glsl", defines).text,
                          tess_evaluation_shader=shader_source("tess_evaluation.glsl", defines | {"CAPTURE": True}).text,
                          varyings=["t_position", "t_normal", "t_levels"])
    vbo = ctx.buffer(np.ascontiguousarray(corners, np.float32).tobytes())
    vao = None
    try:
        for name, matrix in (("u_model", uniforms.model), ("u_view", uniforms.view),
                             ("u_projection", uniforms.projection)):
            program[name].write(transforms.to_glsl(matrix))
        values = {"u_viewport_height": uniforms.viewport_height, "u_target_error": uniforms.target_error,
                  "u_surface_radius": uniforms.surface_radius, "u_max_level": uniforms.max_level,
                  "u_fixed_level": uniforms.fixed_level, **(extra or {})}
        for name, value in values.items():
            if name in program:                      # the compiler drops what a surface does not read
                program[name].value = value
        wanted = [name for name in attributes if name in program]
        if wanted != list(attributes):               # an attribute dropped: skip its bytes
            layout = " ".join(part if name in program else f"{int(part[0]) * 4}x"
                              for part, name in zip(layout.split(), attributes))
        vao = ctx.vertex_array(program, [(vbo, layout, *wanted)])
        data, generated, written = feedback(ctx, program, vao, len(corners), 3, "triangles", 1 << 20,
                                            STAGE_OUTPUTS)
        assert generated == written
        return data
    finally:
        for item in (vao, vbo, program):
            if item is not None:
                item.release()


def gpu_against_twin(scene, ctx, size=(320, 240)):
    """The GPU's frame of `scene` against the reference's (renderer.checks.compare's Comparison)."""
    from renderer.checks.compare import compare_frames
    from renderer.methods import open_renderer
    with open_renderer(scene, size, context=ctx) as gpu:
        got = gpu.render(depth=False).rgba8
    with open_renderer(scene, size, backend="reference") as reference:
        expected = reference.render(depth=False).rgba8
    return compare_frames(got, expected)


def lonely_edge_points(captured_positions, edge_points, exempt=lambda point: False) -> tuple[int, list]:
    """Crack-freeness by points: `edge_points` [(patch, (N, 3) positions on its edges)] from the
    twin, all of them among the GPU's `captured_positions`; (how many distinct edge points,
    those that only one patch makes and `exempt` (their bytes) does not excuse)."""
    gpu_points = {p.tobytes() for p in captured_positions}
    seen_by: dict[bytes, set] = {}
    for patch, points in edge_points:
        for p in points:
            seen_by.setdefault(p.tobytes(), set()).add(patch)
    assert seen_by.keys() <= gpu_points
    return len(seen_by), [key for key, patches in seen_by.items() if len(patches) < 2 and not exempt(key)]
