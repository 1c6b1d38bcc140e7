"""The shadow-map lookup (glsl/shadow/lookup.glsl, reference/shadow/lookup.py), a hand-checked
case per rule: the depth compare, the bilinear weights of percentage-closer filtering, the
cube-face choice, the automatic bias. Where a rule is the sampler's or the GLSL's, the same
inputs go through tests/glsl/shadow_lookup.frag on llvmpipe (EGL and OSMesa) and the two
agree exactly. A known map is layer LAYER of a three-layer array texture whose other layers
hold 0.0 (every ref > 0 in shadow there), so reading the wrong layer shows."""

import math

import numpy as np
import pytest

from reference.lighting import Lights
from reference.shadow.depth import ShadowLayers, render_layers
from reference.shadow.lookup import (ShadowMaps, light_visibility_directional, shadow_bias_point,
                                     shadow_filter)
from renderer.core import primitives
from renderer.core.scene import Camera, DirectionalLight, Scene, SceneObject, Transform
from renderer.core.shadow_settings import FILTERS, BiasRule, Shadow, auto_bias
from renderer.core.shadows import CUBE_FACE_AXES, CUBE_FACE_ROTATIONS, cube_face, plan_shadows, shadow_layout
from shadow_gl import run_lookup_shader

F32 = np.float32


LAYER = 1


def layers_of(depth) -> ShadowLayers:
    """A bare (S, S) float32 map as layer LAYER of three, the others 0.0."""
    layers = ShadowLayers.cleared(3, depth.shape[0])
    layers.depth[:] = 0.0
    layers.depth[LAYER] = depth
    return layers


def reference_filter(depth, uvz, kernel):
    """reference shadow_filter on a bare (S, S) float32 map, no tie bands (-> ShadowLookup)."""
    uvz = np.asarray(uvz, F32)
    return shadow_filter(layers_of(depth), uvz, LAYER, kernel, np.zeros(len(uvz)), np.zeros((len(uvz), 2)))


def gpu_filter(ctx, depth, uvz, kernel):
    inputs = np.concatenate([np.asarray(uvz, F32), np.full((len(uvz), 1), kernel, F32)], axis=1)
    return run_lookup_shader(ctx, inputs, mode=0, maps=layers_of(depth).depth, layer=LAYER)[:, 0]


# -- (a) the compare: LEQUAL ---------------------------------------------------------------------

STORED = F32(0.3)                        # float32(0.3) = 0.300000011920928955078125
ABOVE = np.nextafter(STORED, F32(1))     # one float32 ulp (2^-25 = 2.98e-8) above it


@pytest.mark.parametrize("kernel", [1, 2])
def test_a_reference_depth_equal_to_the_stored_one_is_lit_one_ulp_above_is_not(kernel, gl_contexts):
    """A 4x4 map holding float32(0.3) everywhere, looked up at texel (1, 2)'s centre
    (u, v) = (1.5 / 4, 2.5 / 4) = (0.375, 0.625): ref = 0.3 (the same float32) is lit,
    LEQUAL (ref <= stored), visibility 1; ref = 0.3 + 2^-25 (the next float32) is in shadow, 0.
    Hard (kernel 1) and pcf2x2 alike (every texel the bilinear tap reads holds 0.3). At the
    stored depth itself the reference calls the tap tied (|ref - stored| = 0 <= its band): GL's
    rounding could put the reference on either side."""
    depth = np.full((4, 4), STORED, F32)
    uvz = [(0.375, 0.625, STORED), (0.375, 0.625, ABOVE)]
    look = reference_filter(depth, uvz, kernel)
    assert look.visibility.tolist() == [1.0, 0.0]
    assert look.tied.tolist() == [True, False] and look.alternative.tolist() == [0.0, 0.0]
    for ctx in gl_contexts.values():
        assert gpu_filter(ctx, depth, uvz, kernel).tolist() == [1.0, 0.0]


# -- (b) the bilinear comparison weights ----------------------------------------------------------

def one_near_texel(i=1, j=2):
    """4x4 map of 1.0 with texel (i, j) (column i, GL row j) at 0.25: ref 0.5 is shadowed there."""
    depth = np.ones((4, 4), F32)
    depth[j, i] = 0.25
    return depth


# (u, v) -> x = 4u - 1/2 = 1.25, y = 4v - 1/2 = 1.75: texels i 1..2 (weight of i = 2: s = 0.25),
# j 1..2 (weight of j = 2: t = 0.75). Texel (1, 2) weighs (1 - s) t = 0.75 * 0.75 = 0.5625.
U, V = 1.75 / 4, 2.25 / 4


@pytest.mark.parametrize("uvz, kernel, visibility", [
    # pcf2x2: one bilinear tap, 1 - 0.5625
    ((U, V, 0.5), 2, 0.4375),
    # pcf3x3: four taps at (x, y) = (1.25 +- 0.5, 1.75 +- 0.5); texel (1, 2)'s weight in each:
    # (0.75, 1.25): 0.75 * 0.25; (1.75, 1.25): 0.25 * 0.25; (0.75, 2.25): 0.75 * 0.75;
    # (1.75, 2.25): 0.25 * 0.75; they sum to 1, the mean is 1/4: visibility 0.75
    ((U, V, 0.5), 3, 0.75),
    # hard: the nearest texel, floor(4u) = 1, floor(4v) = 2: texel (1, 2) itself
    ((U, V, 0.5), 1, 0.0),
    # ref 0.25 = stored: lit (LEQUAL) through any filter
    ((U, V, 0.25), 2, 1.0),
    # CLAMP_TO_EDGE: u = v = -0.2 gives x = max(-0.8 - 0.5, 0) = 0: texel (0, 0) alone
    ((-0.2, -0.2, 0.5), 2, 0.0),
    # ... and u = v = 1.2 gives x = min(4.8, 4) - 0.5 = 3.5: texels 3 and min(4, 3) = 3
    ((1.2, 1.2, 0.5), 2, 1.0),
])
def test_b_bilinear_weights_on_a_known_map(uvz, kernel, visibility, gl_contexts):
    depth = one_near_texel() if uvz[0] > 0 else one_near_texel(0, 0)
    if uvz[0] > 1:
        depth = one_near_texel(2, 2)     # not read from the clamped corner: visibility 1
    assert reference_filter(depth, [uvz], kernel).visibility.tolist() == [visibility]
    for ctx in gl_contexts.values():
        assert gpu_filter(ctx, depth, [uvz], kernel).tolist() == [visibility]


def test_b_a_tied_tap_gives_the_other_decision_with_its_weight():
    """ref = stored at texel (1, 2) (a tie): visibility 1 (LEQUAL), the alternative 0.4375 (the
    texel decided the other way: as if shadowed, its weight 0.5625 lost)."""
    depth = one_near_texel()
    look = reference_filter(depth, [(U, V, 0.25)], 2)
    assert look.visibility.tolist() == [1.0] and look.alternative.tolist() == [0.4375]
    assert look.tied.tolist() == [True]


def test_b_a_texel_whose_coverage_is_in_doubt_ties_every_depth_it_may_hold():
    """Texel (1, 2) stores 1.0 but GL may have covered it at 0.25 (below = 0.75, depth.py):
    a hard lookup there with ref 0.5 is lit, tied, the alternative shadowed; ref 0.2 (nearer
    than either) is lit and certain."""
    layers = layers_of(np.full((4, 4), 1.0, F32))
    layers.below[LAYER, 2, 1] = 0.75
    uvz = np.array([[U, V, 0.5], [U, V, 0.2]])
    look = shadow_filter(layers, uvz, LAYER, 1, np.zeros(2), np.zeros((2, 2)))
    assert look.visibility.tolist() == [1.0, 1.0]
    assert look.alternative.tolist() == [0.0, 1.0] and look.tied.tolist() == [True, False]


def test_b_hard_lookup_near_a_texel_edge_offers_the_neighbour():
    """Hard lookup at u S = 2 - 1e-9 (within a band of 1e-6 texels of the edge between texels
    1 and 2): texel 1 (shadowed, 0), alternative texel 2 (lit, 1). At u S = 1.5: no tie."""
    uvz = np.array([[(2 - 1e-9) / 4, 2.5 / 4, 0.5], [1.5 / 4, 2.5 / 4, 0.5]])
    look = shadow_filter(layers_of(one_near_texel(1, 2)), uvz, LAYER, 1, np.zeros(2), np.full((2, 2), 1e-6))
    assert look.visibility.tolist() == [0.0, 0.0]
    assert look.alternative.tolist() == [1.0, 0.0] and look.tied.tolist() == [True, False]


# -- (c) the cube face ----------------------------------------------------------------------------

# The rule: the largest |d_k|, ties to the earlier axis (x, then y, then z); a negative
# component (not -0.0: -0.0 < 0 is false) picks the odd face.
CUBE_CASES = [
    ((1, 0, 0), 0), ((-1, 0, 0), 1), ((0, 1, 0), 2), ((0, -1, 0), 3), ((0, 0, 1), 4), ((0, 0, -1), 5),
    ((1, 1, 0), 0), ((-1, 1, 0), 1), ((1, -1, 0), 0),          # |x| = |y|: x
    ((0, 1, 1), 2), ((0, -2, 2), 3), ((0, 2, -2), 2),          # |y| = |z|: y
    ((1, 0, 1), 0), ((-3, 0, -3), 1),                          # |x| = |z|: x
    ((1, 1, 1), 0), ((-1, -1, -1), 1), ((1, -1, -1), 0),       # |x| = |y| = |z|: x
    ((0, 0, 0), 0), ((-0.0, 0, 0), 0), ((-0.0, -0.0, -0.0), 0),  # zero vectors: +x
    ((0, -0.0, 1e-30), 4), ((-0.0, -1e-30, 0), 3),             # negative zeros lose to any |d|
    ((1e-30, -1e-30, 0), 0), ((-1e-30, 1e-30, -1e-30), 1),
]


def test_c_cube_face_in_the_reference_follows_the_rule():
    directions = np.array([d for d, _ in CUBE_CASES], np.float64)
    assert cube_face(directions).tolist() == [f for _, f in CUBE_CASES]
    assert cube_face(directions.astype(F32)).tolist() == [f for _, f in CUBE_CASES]


def test_c_cube_face_and_its_table_in_glsl_equal_the_rule_and_core(gl_contexts):
    """GLSL's cube_face on the same directions, and its CUBE_FACE_RIGHT / UP / AXIS rows for the
    face, digit-encoded by the shader as 16 (x + 1) + 4 (y + 1) + (z + 1), equal
    CUBE_FACE_ROTATIONS rows 0, 1 and CUBE_FACE_AXES (= -row 2)."""
    directions = np.array([d for d, _ in CUBE_CASES], F32)
    inputs = np.concatenate([directions, np.zeros((len(directions), 1), F32)], axis=1)
    digits = lambda v: 16 * (v[..., 0] + 1) + 4 * (v[..., 1] + 1) + (v[..., 2] + 1)   # noqa: E731
    faces = np.array([f for _, f in CUBE_CASES])
    assert (-CUBE_FACE_ROTATIONS[:, 2] == CUBE_FACE_AXES).all()
    for ctx in gl_contexts.values():
        out = run_lookup_shader(ctx, inputs, mode=1)
        assert out[:, 0].tolist() == faces.tolist()
        assert out[:, 1].tolist() == digits(CUBE_FACE_ROTATIONS[faces, 0]).tolist()
        assert out[:, 2].tolist() == digits(CUBE_FACE_ROTATIONS[faces, 1]).tolist()
        assert out[:, 3].tolist() == digits(CUBE_FACE_AXES[faces]).tolist()


# -- (d) the automatic bias -----------------------------------------------------------------------

def test_d_auto_bias_moves_the_point_by_the_rule():
    """A plane at theta = 60 degrees to the light: N = (sin 60, 0, cos 60) = (0.8660254, 0, 0.5),
    L = (0, 0, 1), map axes X = (1, 0, 0), Y = (0, 1, 0), a texel t = 0.01. pcf2x2's auto rule
    (normal 1 = its footprint radius, constant 0.5, slope 0) moves P by
    t * 1 * (|N.X| + |N.Y|) = 0.01 * 0.8660254 along N = (0.0075, 0, 0.0043301) and by
    t * 0.5 = 0.005 along L: Q - P = (0.0075, 0, 0.0093301)."""
    theta = math.radians(60)
    N = np.array([[math.sin(theta), 0.0, math.cos(theta)]])
    P = np.array([[1.0, 2.0, 3.0]])
    L, X, Y = np.array([0.0, 0, 1]), np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    bias = auto_bias("pcf2x2").as_vec4()
    assert bias.tolist() == [1.0, 0.5, 0.0, 0.0]
    moved = shadow_bias_point(P, N, L, X, Y, 0.01, bias) - P
    assert moved[0] == pytest.approx([0.0075, 0.0, 0.0093301270189222], abs=1e-15)   # 0.005 + 0.01 sqrt(3) / 4
    # the slope term: tan 60 = sqrt 3, capped at MAX_SLOPE = 16 (grazing: c = 0)
    slope = BiasRule(slope=1.0).as_vec4()
    assert (shadow_bias_point(P, N, L, X, Y, 1.0, slope) - P)[0, 2] == pytest.approx(math.sqrt(3))
    grazing = np.array([[1.0, 0.0, 0.0]])
    assert (shadow_bias_point(P, grazing, L, X, Y, 1.0, slope) - P)[0, 2] == 16.0


def tilted_plane_scene(theta_degrees: float, filter_name: str, bias: BiasRule | None):
    """A 2x2 plane (mesh normal +y) turned theta about z, so its normal (-sin, cos, 0) makes
    theta with the light straight above (travelling -y); 64-texel map."""
    plane = SceneObject("plane", primitives.plane(2.0), transform=Transform(rotate=(0.0, 0.0, theta_degrees)))
    light = DirectionalLight(direction=(0.0, -1.0, 0.0),
                             shadow=Shadow(resolution=64, filter=filter_name, bias=bias))
    return Scene(camera=Camera(eye=(-4.0, 4.0, 4.0)), objects=[plane], directional_lights=[light])


def self_lookup(scene, dtype):
    """The plane looked up in its own map at 400 points of its inner 90%: ShadowLookup."""
    matrices = scene.matrices(64, 48)
    plan = plan_shadows(scene, matrices, shadow_layout(scene, 64, 48, prune=False), prune=False)  # draw the plane
    maps = ShadowMaps.from_plan(render_layers(scene, matrices, plan, dtype), plan,
                                Lights.from_scene(scene, dtype, origin=matrices.origin), dtype)
    model = np.asarray(matrices.objects[0].model)
    s = np.linspace(-0.9, 0.9, 20)
    local = np.stack(np.meshgrid(s, [0.0], s, indexing="ij"), -1).reshape(-1, 3)
    P = (local @ model[:3, :3].T + model[:3, 3]).astype(dtype)
    N = np.tile(model[:3, :3] @ [0.0, 1.0, 0.0], (len(P), 1)).astype(dtype)
    corners = primitives.plane(2.0).positions @ model[:3, :3].T + model[:3, 3]
    return light_visibility_directional(maps, 0, P, N, np.full(len(P), np.abs(corners).max()))


# pcf3x3 is the full run's (--all): the same rule at a kernel size between two the default run
# keeps, the smallest (hard: one tap) and the widest (pcf5x5), with the default (pcf2x2).
@pytest.mark.parametrize("filter_name", [
    pytest.param(name, marks=[pytest.mark.slow] if name == "pcf3x3" else []) for name in FILTERS])
def test_d_a_plane_is_lit_in_its_own_map_at_every_angle(filter_name):
    """With the automatic bias, no point of the plane shadows itself (no acne) and no tap is
    even tied, at 1..89 degrees (every 4th in the default run; test_d_every_angle: all), in
    float64 and float32; without a bias (BiasRule()) the same plane at 45 degrees is acne, and
    at 0 degrees (facing the light: its depth is the same at every texel) every lookup is a
    tie (ref = stored up to rounding): lit in float64 (ref <= stored), 0 decided the other way
    where every tap reads the plane."""
    for theta in range(1, 90, 4):
        for dtype in (np.float64, np.float32):
            look = self_lookup(tilted_plane_scene(theta, filter_name, None), dtype)
            assert look.visibility.min() == 1.0 and not look.tied.any(), (theta, dtype)
    acne = self_lookup(tilted_plane_scene(45, filter_name, BiasRule()), np.float64)
    assert acne.visibility.min() < 1.0
    facing = self_lookup(tilted_plane_scene(0, filter_name, BiasRule()), np.float64)
    assert facing.tied.all() and (facing.visibility == 1.0).all() and facing.alternative.min() == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("filter_name", list(FILTERS))
def test_d_every_angle(filter_name):
    for theta in range(1, 90):
        for dtype in (np.float64, np.float32):
            look = self_lookup(tilted_plane_scene(theta, filter_name, None), dtype)
            assert look.visibility.min() == 1.0 and not look.tied.any(), (theta, dtype)
