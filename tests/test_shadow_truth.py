"""The shadow maps held against ray-cast truth (renderer/checks/shadow_truth.py; `renderer
compare --shadows-vs-truth`): a hand-checked case per rule on a ball of radius R over a floor
under a light straight down, whose true shadow is a disc of radius R under the ball (the
icosphere's silhouette lies between its inscribed radius and R), then the built-in shadow
scenes against the issue's targets."""

import json

import numpy as np
import pytest

from reference.pipeline import surface_pixels
from renderer.checks.shadow_truth import CLASSES, LightRays, TruthScenes, shadows_vs_truth
from renderer.cli import main
from renderer.core import primitives
from renderer.core.builtin import resolve_scene
from renderer.core.scene import Camera, DirectionalLight, Scene, SceneObject, Transform
from renderer.core.scene_file import load_scene
from renderer.core.shadow_settings import BiasRule, Shadow

R = 0.5                                   # the ball's radius; its centre 1 above the floor
BALL = primitives.icosphere(R, 3)
_faces = BALL.positions[BALL.faces]
_normals = np.cross(_faces[:, 1] - _faces[:, 0], _faces[:, 2] - _faces[:, 0])
INSCRIBED = float(np.abs(np.einsum("ij,ij->i", _faces[:, 0], _normals)
                         / np.linalg.norm(_normals, axis=1)).min())      # 0.4977


def ball_over_floor(bias=None, direction=(0.0, -1.0, 0.0), ball=BALL, lift=1.0):
    """An orthographic camera looking down at 45 degrees (it sees the shadow behind the ball);
    the light's map of 64 texels."""
    light = DirectionalLight(direction=direction, shadow=Shadow(resolution=64, bias=bias))
    camera = Camera(eye=(0.0, 4.0, 4.0), look=(0.0, 0.0, 0.0), projection="parallel", height=3.0,
                    near=1.0, far=12.0)
    return Scene(camera=camera, directional_lights=[light], name="ball_over_floor",
                 objects=[SceneObject("floor", primitives.plane(6.0)),
                          SceneObject("ball", ball, transform=Transform(translate=(0.0, lift, 0.0)))])


def truly_lit(classes):
    names = np.array([c.name for c in CLASSES] + ["-"])
    return np.isin(names[classes], ["lit", "wrongly_shadowed_band", "wrongly_shadowed"])


def test_the_truth_is_the_disc_under_the_ball():
    """Floor pixels nearer the axis than the inscribed radius are in shadow in truth, those
    beyond R lit; every pixel of the floor and the ball's upper half faces the light."""
    scene = ball_over_floor()
    surface, _ = surface_pixels(scene, 64, 48)
    result = shadows_vs_truth(scene, 64, 48)
    floor = surface.object == 0
    world = surface.P[floor] + np.asarray(scene.camera.eye)
    rho = np.hypot(world[:, 0], world[:, 2])
    lit = truly_lit(result.classes).reshape(-1)[surface.pixel[floor]]
    assert (rho < INSCRIBED).sum() > 20 and (rho > R).sum() > 1000
    assert not lit[rho < INSCRIBED].any() and lit[rho > R].all()


def test_the_band_is_where_the_truth_changes_within_a_texel():
    """Points on the floor at radius rho: the truth changes within a texel t (the map's
    world texel) where a step of t towards the silhouette (between INSCRIBED and R) must cross
    it (the nearest of the 8 directions is within 22.5 degrees of it: a step of at least
    cos 22.5 t = 0.92 t), and nowhere farther than t from the silhouette."""
    scene = ball_over_floor()
    _, maps = surface_pixels(scene, 64, 48)
    rays = LightRays("directional", 0, maps, TruthScenes.of(scene))
    t = float(maps.uniforms["u_directional_shadow"][0][1])
    rho = np.concatenate([np.linspace(0.3, INSCRIBED - 1.01 * t, 30),   # outside the band
                          np.linspace(R - 0.9 * t, INSCRIBED - 0.05 * t, 10),   # within it, shadowed
                          np.linspace(R + 0.05 * t, INSCRIBED + 0.9 * t, 10),           # within it, lit
                          np.linspace(R + 1.01 * t, 0.8, 30)])                          # outside it
    phi = np.linspace(0.0, 2.0 * np.pi, len(rho), endpoint=False)
    P = np.stack([rho * np.cos(phi), np.zeros_like(rho), rho * np.sin(phi)], 1) - scene.camera.eye
    Ng = np.tile([0.0, 1.0, 0.0], (len(rho), 1))
    floor = np.zeros(len(rho), np.int64)
    lit = rays.lit(P, Ng, floor)
    band = rays.changes_within(P, Ng, Ng, floor, lit, 1.0)
    assert lit.tolist() == [False] * 40 + [True] * 40
    assert band.tolist() == [False] * 30 + [True] * 20 + [False] * 30


def test_the_automatic_bias_leaves_no_acne_and_errs_only_within_the_band():
    """A map of 64 texels with the automatic bias: no acne, nothing wrong outside the band (the
    ball's shadow edge is a little blurred by PCF, within a texel)."""
    figures = shadows_vs_truth(ball_over_floor(), 64, 48).as_dict()
    assert figures["acne_pixels"] == 0 and figures["wrong_outside_band_pixels"] == 0
    assert figures["considered_pixels"] > 3000


def test_without_bias_the_ball_shadows_itself():
    """BiasRule() (no bias): the ball, in its own map, darkens its lit side (acne) and much of
    it reads as shadowed outside any shadow edge; the floor is not in its map (it cannot
    shadow the ball), so no acne there."""
    result = shadows_vs_truth(ball_over_floor(BiasRule()), 64, 48)
    figures = result.as_dict()
    assert figures["acne_pixels"] > 100 and figures["classes"]["wrongly_shadowed"]["pixels"] > 50
    surface, _ = surface_pixels(ball_over_floor(), 64, 48)
    on_ball = np.zeros(64 * 48, bool)
    on_ball[surface.pixel[surface.object == 1]] = True
    assert on_ball[result.acne.reshape(-1)].all()


def test_a_caster_touching_the_floor_casts_an_attached_shadow():
    """A box standing on the floor, the light at 45 degrees: its shadow starts at its foot;
    peter-panning (floor pixels lit by the map farther than a texel from a true shadow) at
    most 2 texels, and none wrong otherwise."""
    scene = ball_over_floor(direction=(1.0, -1.0, 0.0), ball=primitives.cube(0.8), lift=0.4)
    figures = shadows_vs_truth(scene, 64, 48).as_dict()
    assert figures["classes"]["shadowed"]["pixels"] > 100 and figures["acne_pixels"] == 0
    assert figures["classes"]["wrongly_shadowed"]["pixels"] == 0
    assert figures["peter_panning"]["max_texels"] <= 2


def test_cli_writes_the_classification_and_the_figures(tmp_path, capsys):
    out = tmp_path / "truth"
    assert main(["compare", "shadow_plane", "--shadows-vs-truth", "--size", "32x24", "--out", str(out)]) == 0
    json_line, line = capsys.readouterr().out.strip().splitlines()
    figures = json.loads(json_line)
    assert figures == json.loads((out / "shadow_truth.json").read_text())
    assert figures["scene"] == "shadow_plane" and figures["pixels"] == 32 * 24
    assert line.startswith("shadow_plane 32x24: ") and "acne" in line
    assert sorted(p.name for p in out.iterdir()) == ["shadow_truth.json", "shadow_truth.png"]


def test_cli_refuses_a_scene_without_shadow_maps(tmp_path, capsys):
    scene = tmp_path / "unshadowed.toml"
    scene.write_text(resolve_scene("shadow_plane").read_text().replace(
        'type = "directional"', 'type = "directional"\nshadows = false'))
    assert not any(light.shadow.enabled for light in load_scene(scene).directional_lights)
    assert main(["compare", str(scene), "--shadows-vs-truth", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no shadow maps" in err[0] and str(scene) in err[0]
    assert not (tmp_path / "o").exists()


def second_wall_distance(world):
    """(K,) the distance of points (K, 3) inside shadow_room's room (x, z in [-2, 2], y in
    [0, 3]) to the second-nearest of its six walls: small only near a concave corner."""
    to_walls = np.stack([2 - world[:, 0], 2 + world[:, 0], world[:, 1], 3 - world[:, 1],
                         2 - world[:, 2], 2 + world[:, 2]], axis=1)
    return np.sort(to_walls, axis=1)[:, 1]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["shadow_plane", "shadow_room", "shadow_curved"])
def test_builtin_shadow_scenes_reach_the_issue_targets(name):
    """The issue's target at default settings, 320x240: fewer than 0.1 % of the pixels wrong
    outside the 1-texel band, and no pixel wrong beyond 2 px of the true shadow boundary and no
    acne, but at shadow_room's concave corners (a K x K filter reads the other wall: no bias
    along one plane can cover it), every one of those within 0.02 units (about a texel) of a
    second wall. (shadow_room also had 4 acne pixels at cube-face seams while a point light's
    lookup read the face its moved point fell on; it reads P's own face now.)"""
    scene = load_scene(resolve_scene(name))
    result = shadows_vs_truth(scene, 320, 240)
    figures = result.as_dict()
    assert figures["wrong_outside_band_fraction"] < 0.001
    if name != "shadow_room":
        assert figures["acne_pixels"] == 0 and figures["wrong_beyond_2px_pixels"] == 0
        return
    surface, _ = surface_pixels(scene, 320, 240)
    world = surface.P + np.asarray(scene.camera.eye)
    flagged = (result.acne | result.wrong_beyond).reshape(-1)[surface.pixel]
    assert 0 < flagged.sum() < 200
    assert second_wall_distance(world[flagged]).max() < 0.02
