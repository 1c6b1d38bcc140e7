"""The texture verifier's coordinate bound (renderer/checks/texture_bounds.py) and the twin's
renders over it, which hold GL's anisotropic lookups.

Hand-checked first: e(u) is dEQP's computeFloatingPointError(u, 20), 7 units in the last place
of float32 u; a displacement moves anisotropic lookups only. Then the twin: a displacement
reaches the fragment's lookup and its quad's reference pixels alike, and a scene's accepted
colours are its own image unless it samples anisotropically. The GPU against the envelope on
the built-in scenes, and a faulty twin failing it: tests/test_texture_raster.py (slow).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import reference
from renderer.checks.compare import Envelope
from renderer.checks.texture_bounds import (COORDINATE_BITS, DISPLACEMENTS, accepted_colours,
                                            coordinate_error, displaced_lookup, has_anisotropic)
from renderer.core.builtin import builtin_scenes
from renderer.core.scene import Camera, Material, Mesh, Scene, SceneObject, Transform
from renderer.core.scene_file import load_scene
from renderer.core.textures import MaterialTexture, Sampler, checkerboard

ROOT = Path(__file__).resolve().parents[1]
f32 = np.float32


@pytest.mark.parametrize("u, error", [
    (1.0, 7 * 2.0 ** -23), (1.9999999, 7 * 2.0 ** -23), (2.0, 7 * 2.0 ** -22),
    (25.0, 7 * 2.0 ** -19), (-0.75, 7 * 2.0 ** -24), (1e6, 7 * 2.0 ** -4),
    (0.0, 7 * 2.0 ** -149), (1e-45, 7 * 2.0 ** -149),          # zero and a denormal: dEQP's 7 x 2^-149
])
def test_the_coordinate_error_is_deqps_at_20_bits(u, error):
    """computeFloatingPointError(u, 20) = float32(2^E (1 + 7 2^-23)) - 2^E for u's exponent
    E: 7 units in the last place of a normal float32 u (2^(23 - 20) - 1 = 7)."""
    assert COORDINATE_BITS == 20
    e = coordinate_error(np.array([u], dtype=f32))
    assert e.dtype == f32 and e[0] == f32(error)
    if u != 0 and abs(u) >= np.finfo(f32).tiny:
        assert e[0] == 7 * np.spacing(f32(abs(u)))


def test_a_displacement_moves_anisotropic_lookups_only():
    """(a, b) moves an anisotropic sampler's (s, t) by (a e(s), b e(t)) in float32: the corner
    (1, -1) by 7 units in the last place up in s and down in t; any other filter's lookup
    stays where it is (a scene that mixes filters holds those to the exact twin)."""
    st = np.array([[0.3, 10.5], [-2.5, 1e-3]], dtype=f32)
    moved = displaced_lookup((1, -1))(Sampler(filter="anisotropic", anisotropy=4), st)
    assert moved.dtype == f32
    assert (moved[:, 0] == st[:, 0] + 7 * np.spacing(np.abs(st[:, 0]))).all()
    assert (moved[:, 1] == st[:, 1] - 7 * np.spacing(np.abs(st[:, 1]))).all()
    for filter in ("nearest", "bilinear", "mip-nearest", "trilinear"):
        assert displaced_lookup((1, -1))(Sampler(filter=filter), st) is st
    assert {(abs(a), abs(b)) for a, b in DISPLACEMENTS} == {(1, 1), (0.5, 0.5)} and len(DISPLACEMENTS) == 8


def slanted_checks(filter: str, uv_offset=(0.0, 0.0)) -> Scene:
    """A quad tilted 75 degrees away under a perspective camera: footprints up to some 4
    times longer than wide, checked 16 x 16 squares, lit by the ambient term alone."""
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    mesh = Mesh(positions, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]), "quad",
                uvs=np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    anisotropy = 16 if filter == "anisotropic" else 1
    texture = MaterialTexture(checkerboard(16, ((0.9, 0.8, 0.1), (0.1, 0.2, 0.7)), 64),
                              Sampler(filter=filter, anisotropy=anisotropy),
                              uv_scale=(3.0, 3.0), uv_offset=uv_offset, modulate=("ka",))
    material = Material(ka=(1.0, 1.0, 1.0), kd=(0.0, 0.0, 0.0), ks=(0.0, 0.0, 0.0), texture=texture)
    return Scene(camera=Camera(eye=(0.0, 0.0, 2.4), fov_y=50.0), ambient=(1.0, 1.0, 1.0),
                 objects=[SceneObject("checks", mesh, material, Transform(rotate=(-75.0, 0.0, 0.0)))])


def test_the_twin_displaces_the_lookup_and_its_quad_alike():
    """A displacement by a constant c (in float32 after st = uv * scale + 0) draws what the
    material offset by c draws (st = uv * scale + c: the same one rounding), bit for bit: so
    it reached the fragment's lookup and its quad's reference pixels alike (displacing the
    fragment alone would change every quad's derivatives by c). Without one, the image is
    the twin's own."""
    c = np.array([0.3, 0.1], dtype=f32)
    size = (48, 32)
    shifted = reference.render(slanted_checks("anisotropic"), *size,
                               displace_lookup=lambda sampler, st: st + c)
    offset = reference.render(slanted_checks("anisotropic", uv_offset=tuple(c)), *size)
    plain = reference.render(slanted_checks("anisotropic"), *size)
    assert np.array_equal(shifted.rgba8, offset.rgba8)
    assert not np.array_equal(shifted.rgba8, plain.rgba8)
    assert np.array_equal(reference.render(slanted_checks("anisotropic"), *size,
                                           displace_lookup=lambda sampler, st: st).rgba8, plain.rgba8)


def test_only_an_anisotropic_scene_gets_the_envelope():
    """A scene without anisotropic lookups is held to the twin's own image (no further
    render); one with them to the envelope of the twin over DISPLACEMENTS, which holds the
    twin's own image and, here, moves some pixels."""
    size = (48, 32)
    trilinear = slanted_checks("trilinear")
    frame = reference.render(trilinear, *size)
    accepted = accepted_colours(trilinear, frame, *size)
    assert not has_anisotropic(trilinear)
    assert accepted.rgba8 is frame.rgba8 and accepted.displaced_renders == 0
    anisotropic = slanted_checks("anisotropic")
    frame = reference.render(anisotropic, *size)
    accepted = accepted_colours(anisotropic, frame, *size)
    assert has_anisotropic(anisotropic) and accepted.displaced_renders == len(DISPLACEMENTS)
    assert isinstance(accepted.rgba8, Envelope)
    assert ((accepted.rgba8.low <= frame.rgba8) & (frame.rgba8 <= accepted.rgba8.high)).all()
    assert (accepted.rgba8.high > accepted.rgba8.low).any()
    mixed = replace(anisotropic, objects=anisotropic.objects + [replace(trilinear.objects[0], name="other")])
    assert has_anisotropic(mixed) and not has_anisotropic(replace(anisotropic, objects=trilinear.objects))


def test_renderer_compare_holds_anisotropic_lookups_to_the_envelope(tmp_path, cli_here, gpu_stand_in):
    """`renderer compare` of a scene with anisotropic lookups (tex_grazing) says it rendered
    the twin at the DISPLACEMENTS too and measures from their range: a GPU frame showing each
    pixel's highest value over them passes with max_abs 0, though it is off the twin's own
    image by 1/255; an untextured scene takes the exact compare."""
    scene_file, size = ROOT / "assets" / "extreme" / "tex_grazing.toml", (48, 32)
    scene = load_scene(scene_file)
    frame = reference.render(scene, *size)
    highest = accepted_colours(scene, frame, *size).rgba8.high
    assert np.abs(highest.astype(int) - frame.rgba8).max() == 1
    gpu_stand_in(replace(frame, rgba8=highest))
    result = cli_here("compare", scene_file, "--size", "48x32", "--out", tmp_path / "grazing")
    figures = json.loads(result.stdout)
    assert result.returncode == 0 and figures["passes"] and figures["max_abs"] == 0
    assert figures["anisotropic_envelope_renders"] == len(DISPLACEMENTS)
    gpu_stand_in(reference.render(load_scene(builtin_scenes()["sphere"]), 32, 24))
    result = cli_here("compare", "sphere", "--size", "32x24", "--out", tmp_path / "sphere")
    assert json.loads(result.stdout)["anisotropic_envelope_renders"] == 0
