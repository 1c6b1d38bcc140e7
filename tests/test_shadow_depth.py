"""The shadow maps' depth pass (reference/shadow/depth.py): a hand-computed map (depths at
known texels, the nearer caster winning, the first of equal depths staying, nothing outside
its R x R at texel (0, 0) of its layer), then the reference's layers of a built-in scene
against llvmpipe's, each pass drawn into its own R x R DEPTH_COMPONENT32F texture with
tests/glsl/shadow_depth.vert (rasterising from texel (0, 0), as into a layer): the same texels
covered, and depths within the per-texel tolerance the lookup's ties allow for."""

from types import SimpleNamespace

import numpy as np

from reference.shadow.depth import ShadowLayers, draw_pass, render_layers
from renderer.core.builtin import builtin_scenes
from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.scene import Mesh
from renderer.core.scene_file import load_scene
from renderer.core.shadows import SHADOW_KINDS, ShadowPass, Tile, plan_shadows, shadow_layout
from renderer.gpu.shaders import shader_source
from shadow_gl import GLSL, depth32f_texture

F32 = np.float32


def quad(x0, x1, z_of_x):
    """Two triangles over x0..x1, y -1..1, at clip z = z_of_x(x) (identity model and pass)."""
    xs = [x0, x1, x1, x0]
    positions = np.array([[x, y, z_of_x(x)] for x, y in zip(xs, [-1, -1, 1, 1])], float)
    return Mesh(positions, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]))


def test_a_known_map_by_hand():
    """A 4-texel map in layer 1 of two 8x8 layers, the pass's clip = world (identity), so
    texel i's centre is x_ndc = (i + 0.5) / 2 - 1 = -0.75, -0.25, 0.25, 0.75. Caster 0: the
    plane z_clip = x / 4 over the whole map: z_w = (z_ndc + 1) / 2 = 0.40625, 0.46875, 0.53125,
    0.59375 (exact in float32). Caster 1: z_clip = -0.5 (z_w 0.25) over x in [-1, 0]: nearer,
    it wins texels 0 and 1 though drawn later. Caster 2: caster 0 again, drawn last: equal
    depths, GL_LESS keeps the first (caster 0). Texels outside [0, 4)^2 of layer 1, and
    layer 0, stay 1.0 / -1."""
    plane = quad(-1.0, 1.0, lambda x: x / 4)
    front = quad(-1.0, 0.0, lambda x: -0.5)
    scene = SimpleNamespace(objects=[SimpleNamespace(mesh=m) for m in (plane, front, plane)])
    matrices = SimpleNamespace(objects=[SimpleNamespace(model=np.eye(4))] * 3)
    layers = ShadowLayers.cleared(2, 8)
    draw_pass(scene, matrices, ShadowPass("directional", 0, 0, Tile(1, 4), np.eye(4), (0, 1, 2)), layers)
    row = [0.25, 0.25, 0.53125, 0.59375]
    assert layers.depth[1, :4, :4].tolist() == [row] * 4
    assert layers.caster[1, :4, :4].tolist() == [[1, 1, 0, 0]] * 4
    outside = np.ones((2, 8, 8), bool)
    outside[1, :4, :4] = False
    assert (layers.depth[outside] == 1).all() and (layers.caster[outside] == -1).all()
    assert (layers.tolerance[1, :4, :4] > 0).all() and (layers.tolerance[1, :4, :4] < 1e-6).all()


def test_a_texel_whose_coverage_snapping_may_change_spans_both_depths():
    """One triangle in a 4x4 map (identity pass: x_w = 2 (x + 1) texels): (0.1, 0.1), (X, 0.1),
    (X, 3.9) texels at z_w 0.5, its right edge at X = (384.5 - 1e-4) / 256 texels, 1e-4
    sub-pixel units below the rounding boundary 384.5: the reference snaps it to 384, on
    texel column 1's centres (1.5 texels = 384), which a right edge leaves out (depth 1.0);
    GL's float32 position may round to 385 and cover them (seen on llvmpipe: shadow_room
    640x480). So those texels may hold 0.5 or 1.0: below = 0.5 (and the triangle's store
    tolerance, under 1e-6). Texel (0, 0), 64 sub-pixel
    units inside every edge, is surely covered, and (0, 1), 30 units outside the hypotenuse,
    surely not: no range."""
    X = (384.5 - 1e-4) / 256
    ndc = lambda x: x / 2 - 1                                     # noqa: E731  texels -> x_ndc
    positions = np.array([[ndc(0.1), ndc(0.1), 0.0], [ndc(X), ndc(0.1), 0.0], [ndc(X), ndc(3.9), 0.0]])
    mesh = Mesh(positions, np.tile([0.0, 0.0, 1.0], (3, 1)), np.array([[0, 1, 2]]))
    scene = SimpleNamespace(objects=[SimpleNamespace(mesh=mesh)])
    matrices = SimpleNamespace(objects=[SimpleNamespace(model=np.eye(4))])
    layers = ShadowLayers.cleared(1, 4)
    draw_pass(scene, matrices, ShadowPass("directional", 0, 0, Tile(0, 4), np.eye(4), (0,)), layers)
    assert layers.depth[0, :, 1].tolist() == [1.0] * 4                    # the edge's column
    assert ((layers.below[0, :, 1] > 0.5) & (layers.below[0, :, 1] < 0.5 + 1e-6)).all()
    assert (layers.above[0, :, 1] == 0).all()
    assert layers.depth[0, 0, 0] == 0.5 and layers.below[0, 0, 0] == layers.above[0, 0, 0] == 0
    assert layers.depth[0, 1, 0] == 1.0 and layers.below[0, 1, 0] == layers.above[0, 1, 0] == 0
    assert (layers.below[0, :, 2:] == 0).all() and (layers.above[0] == 0).all()


def gpu_layers(ctx, scene, matrices, plan) -> dict[str, np.ndarray]:
    """llvmpipe's maps per kind of light (layers, S, S) float32, GL rows: every pass drawn as
    the design says (viewport (0, 0, R, R), cleared to 1.0, GL_LESS, no culling) into an R x R
    texture of its own, which rasterises as a layer does (from texel (0, 0)), read back into
    its layer of its kind's stack."""
    from renderer.gpu.context import activate
    activate(ctx)
    out = {kind: np.ones((plan.layout.stack(kind).layers, plan.layout.stack(kind).side,
                          plan.layout.stack(kind).side), F32) for kind in SHADOW_KINDS}
    program = ctx.program(vertex_shader=shader_source("shadow_depth.vert", directory=GLSL).text,
                          fragment_shader=shader_source("shadow_depth.frag", directory=GLSL).text)
    things = [program]
    try:
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        ctx.depth_func = STANDARD_DEPTH.depth_func          # GL_LESS
        for shadow_pass in plan.passes:
            R = shadow_pass.tile.size
            texture = depth32f_texture(ctx, R, R)
            framebuffer = ctx.framebuffer(depth_attachment=texture)
            things += [texture, framebuffer]
            framebuffer.use()
            framebuffer.clear(depth=1.0)
            framebuffer.viewport = (0, 0, R, R)
            for index in shadow_pass.casters:
                mesh = scene.objects[index].mesh
                matrix = shadow_pass.clip_from_world @ matrices.objects[index].model
                program["u_clip_from_model"].write(matrix.T.astype(F32).tobytes())
                vbo = ctx.buffer(np.asarray(mesh.positions, F32).tobytes())
                ibo = ctx.buffer(np.asarray(mesh.faces, np.int32).tobytes())
                vao = ctx.vertex_array(program, [(vbo, "3f", "in_position")], index_buffer=ibo)
                vao.render()
                things += [vao, vbo, ibo]
            out[shadow_pass.kind][shadow_pass.tile.layer, :R, :R] = np.frombuffer(texture.read(), F32).reshape(R, R)
        return out
    finally:
        ctx.disable(ctx.DEPTH_TEST)
        for thing in things:
            thing.release()


def store_error(gpu: np.ndarray, layers: ShadowLayers):
    """(texels whose coverage differs, float32 ulps of GL's depth from the reference's (N,),
    the error as a fraction of the per-texel tolerance (N,)) where both drew."""
    drawn = layers.caster >= 0
    differ = int(((gpu != 1.0) != drawn).sum())
    ulp = np.spacing(layers.depth[drawn]).astype(np.float64)
    error = np.abs(gpu[drawn].astype(np.float64) - layers.depth[drawn])
    return differ, error / ulp, error / layers.tolerance[drawn]


def test_the_maps_of_a_scene_match_llvmpipes(gl_contexts):
    """`classic` at 64x48: a directional map and a point light's cube (7 layers of 64). Coverage
    is the same texels; each depth is within the reference's per-texel tolerance
    (STORE_TIE_ROUNDINGS roundings of the plane's float32 set-up from texel (0, 0)), which is
    what the lookup's tie bands add."""
    scene = load_scene(builtin_scenes()["classic"])
    matrices = scene.matrices(64, 48)
    plan = plan_shadows(scene, matrices, shadow_layout(scene, 64, 48))
    stacks = render_layers(scene, matrices, plan)
    assert sum((layers.caster >= 0).sum() for layers in stacks.values()) > 4000
    for kind, ctx in gl_contexts.items():
        gpu = gpu_layers(ctx, scene, matrices, plan)
        for light_kind, layers in stacks.items():
            differ, ulps, use = store_error(gpu[light_kind], layers)
            assert differ == 0, (kind, light_kind, differ)
            assert use.size == 0 or use.max() <= 1.0, (kind, light_kind, float(use.max()), float(ulps.max()))
