"""The shadow maps' depth pass (reference/shadow/depth.py): a hand-computed map (depths at
known texels, the nearer caster winning, the first of equal depths staying, nothing outside
the tile), then the reference's atlas of a built-in scene against llvmpipe's, drawn pass by
pass into a DEPTH_COMPONENT32F texture with tests/glsl/shadow_depth.vert: the same texels
covered, and depths within the per-texel tolerance the lookup's ties allow for."""

from types import SimpleNamespace

import numpy as np

from reference.shadow.depth import ShadowAtlas, draw_pass, render_atlas
from renderer.core.builtin import builtin_scenes
from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.scene import Mesh
from renderer.core.scene_file import load_scene
from renderer.core.shadows import ShadowPass, Tile, plan_shadows, shadow_layout
from renderer.gpu.shaders import shader_source
from shadow_gl import GLSL, depth32f_texture

F32 = np.float32


def quad(x0, x1, z_of_x):
    """Two triangles over x0..x1, y -1..1, at clip z = z_of_x(x) (identity model and pass)."""
    xs = [x0, x1, x1, x0]
    positions = np.array([[x, y, z_of_x(x)] for x, y in zip(xs, [-1, -1, 1, 1])], float)
    return Mesh(positions, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]))


def test_a_known_map_by_hand():
    """A 4-texel tile at (4, 0) of an 8x8 atlas, the pass's clip = world (identity), so texel
    i's centre is x_ndc = (i + 0.5) / 2 - 1 = -0.75, -0.25, 0.25, 0.75. Caster 0: the plane
    z_clip = x / 4 over the whole tile: z_w = (z_ndc + 1) / 2 = 0.40625, 0.46875, 0.53125,
    0.59375 (exact in float32). Caster 1: z_clip = -0.5 (z_w 0.25) over x in [-1, 0]: nearer,
    it wins texels 0 and 1 though drawn later. Caster 2: caster 0 again, drawn last: equal
    depths, GL_LESS keeps the first (caster 0). Atlas texels outside the tile stay 1.0 / -1."""
    plane = quad(-1.0, 1.0, lambda x: x / 4)
    front = quad(-1.0, 0.0, lambda x: -0.5)
    scene = SimpleNamespace(objects=[SimpleNamespace(mesh=m) for m in (plane, front, plane)])
    matrices = SimpleNamespace(objects=[SimpleNamespace(model=np.eye(4))] * 3)
    atlas = ShadowAtlas(np.ones((8, 8), F32), np.full((8, 8), -1, np.int32), np.zeros((8, 8), F32))
    draw_pass(scene, matrices, ShadowPass("directional", 0, 0, Tile(4, 0, 4), np.eye(4), (0, 1, 2)), atlas)
    row = [0.25, 0.25, 0.53125, 0.59375]
    assert atlas.depth[:4, 4:].tolist() == [row] * 4
    assert atlas.caster[:4, 4:].tolist() == [[1, 1, 0, 0]] * 4
    assert (atlas.depth[4:] == 1).all() and (atlas.depth[:, :4] == 1).all()
    assert (atlas.caster[4:] == -1).all() and (atlas.caster[:, :4] == -1).all()
    assert (atlas.tolerance[:4, 4:] > 0).all() and (atlas.tolerance[:4, 4:] < 1e-5).all()


def gpu_atlas(ctx, scene, matrices, plan) -> np.ndarray:
    """llvmpipe's atlas: every pass drawn as the design says (viewport on the tile, cleared to
    1.0, GL_LESS, no culling), read back (S, S) float32, GL rows."""
    from renderer.gpu.context import activate
    activate(ctx)
    S = plan.atlas_side
    program = ctx.program(vertex_shader=shader_source("shadow_depth.vert", directory=GLSL).text,
                          fragment_shader=shader_source("shadow_depth.frag", directory=GLSL).text)
    texture = depth32f_texture(ctx, S, S)
    framebuffer = ctx.framebuffer(depth_attachment=texture)
    things = [program, framebuffer, texture]
    try:
        framebuffer.use()
        framebuffer.clear(depth=1.0)
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        ctx.depth_func = STANDARD_DEPTH.depth_func          # GL_LESS
        for shadow_pass in plan.passes:
            tile = shadow_pass.tile
            framebuffer.viewport = (tile.x, tile.y, tile.size, tile.size)
            for index in shadow_pass.casters:
                mesh = scene.objects[index].mesh
                matrix = shadow_pass.clip_from_world @ matrices.objects[index].model
                program["u_clip_from_model"].write(matrix.T.astype(F32).tobytes())
                vbo = ctx.buffer(np.asarray(mesh.positions, F32).tobytes())
                ibo = ctx.buffer(np.asarray(mesh.faces, np.int32).tobytes())
                vao = ctx.vertex_array(program, [(vbo, "3f", "in_position")], index_buffer=ibo)
                vao.render()
                things += [vao, vbo, ibo]
        return np.frombuffer(texture.read(), F32).reshape(S, S).copy()
    finally:
        ctx.disable(ctx.DEPTH_TEST)
        for thing in things:
            thing.release()


def test_the_atlas_of_a_scene_matches_llvmpipes(gl_contexts):
    """`classic` at 64x48: a directional map and a point light's cube (7 tiles of 256 in a
    1024 atlas). Coverage is the same texels; each depth is within the reference's per-texel
    tolerance (STORE_TIE_ROUNDINGS roundings of the plane's float32 set-up at absolute atlas
    coordinates), which is what the lookup's tie bands add."""
    scene = load_scene(builtin_scenes()["classic"])
    matrices = scene.matrices(64, 48)
    plan = plan_shadows(scene, matrices, shadow_layout(scene, 64, 48))
    atlas = render_atlas(scene, matrices, plan)
    drawn = atlas.caster >= 0
    assert drawn.sum() > 10000
    for kind, ctx in gl_contexts.items():
        gpu = gpu_atlas(ctx, scene, matrices, plan)
        assert ((gpu != 1.0) == drawn).all(), (kind, int(((gpu != 1.0) != drawn).sum()))
        error = np.abs(gpu.astype(np.float64) - atlas.depth)[drawn]
        ratio = error / atlas.tolerance[drawn]
        assert ratio.max() <= 1.0, (kind, float(ratio.max()), float(error.max()))
