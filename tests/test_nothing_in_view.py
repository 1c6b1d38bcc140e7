"""A frame in which nothing was drawn is not silent: `renderer render` (either backend) and
`renderer compare` print one warning line on stderr saying why, when the objects' bounding
boxes in clip space tell (renderer/core/visibility.py: not_in_view, nothing_in_view), and the
exit status stays 0.

Each case is a camera of [0, 0, 5] looking at the origin (unless said otherwise) and objects
whose boxes are easy to place by hand: a cube of edge 2 spans 4 to 6 units in front of it.
"""

import pytest

from renderer.cli import main

CAMERA = "[camera]\neye = [0, 0, 5]\nlook = [0, 0, 0]\n"
BOX = '[[objects]]\nname = "box"\nmesh = { primitive = "cube" }\n'
BALL = '[[objects]]\nname = "ball"\nmesh = { primitive = "uv_sphere", segments = 8, rings = 4 }\n'

CASES = [
    # the camera looks away, along +z: the cube (z -1..1) and the ball (z -4..-2) are behind it
    ("looking away", "[camera]\neye = [0, 0, 5]\nlook = [0, 0, 10]\n" + BOX + BALL + "translate = [0, 0, -3]\n",
     "both box and ball are behind the camera"),
    # far = 3: the cube is 4 to 6 units away
    ("beyond far", CAMERA + "far = 3\n" + BOX, "box is beyond the far plane (3)"),
    # the same under reversed-Z, where the far plane is z_clip = 0 (not -w): not culled, but clipped
    ("beyond far, reversed-Z", CAMERA + "far = 3\nreversed_z = true\n" + BOX,
     "box is beyond the far plane (3)"),
    # near = 3.5: a cube of edge 0.5 at z = 3 is 1.75 to 2.25 units away
    ("nearer than near", CAMERA + "near = 3.5\n" + BOX.replace('"cube"', '"cube", size = 0.5')
     + "translate = [0, 0, 3]\n", "box is nearer than the near plane (3.5)"),
    # a parallel camera: w is 1 everywhere, the depth of the corners says the cube is behind
    ("parallel, behind", CAMERA + 'projection = "parallel"\n' + BOX + "translate = [0, 0, 8]\n",
     "box is behind the camera"),
    # 45 degrees of view at 5 units: the view is about 2.1 units either side
    ("right", CAMERA + BOX + "translate = [50, 0, 0]\n", "box is to the right of the view"),
    ("left", CAMERA + BOX + "translate = [-50, 0, 0]\n", "box is to the left of the view"),
    ("above", CAMERA + BOX + "translate = [0, 50, 0]\n", "box is above the view"),
    ("below", CAMERA + BOX + "translate = [0, -50, 0]\n", "box is below the view"),
    ("mixed", CAMERA + "far = 20\n" + BOX + "translate = [0, 0, 10]\n" + BALL + "translate = [0, 0, -30]\n",
     "box is behind the camera; ball is beyond the far plane (20)"),
    ("many", CAMERA + "".join(f'[[objects]]\nname = "b{i}"\nmesh = {{ primitive = "cube" }}\n'
                              f'translate = [0, 0, {10 + 3 * i}]\n' for i in range(5)),
     "all 5 objects are behind the camera"),
    # a ball of radius 1e-4 at the centre of a 32x24 image, which is a pixel corner
    ("too small", CAMERA + BALL + "scale = 1e-4\n",
     "ball is in the view volume, yet no triangle covers a pixel centre"),
    # the plane faces +y; seen from below only its back faces show, and they are culled
    ("culled", "[camera]\neye = [0, -5, 0]\nlook = [0, 0, 0]\n"
               '[[objects]]\nname = "floor"\nmesh = { primitive = "plane" }\ncull = "back"\n',
     'floor is in the view volume, yet no triangle covers a pixel centre or all that do are '
     'culled (cull = "back")'),
    # an analytic plane is drawn where it meets the view volume: looking up, the floor does not
    ("plane misses", "[camera]\neye = [0, 1, 5]\nlook = [0, 9, 4]\n"
                     '[[objects]]\nname = "floor"\nshape = { type = "plane" }\n',
     "floor is outside the view volume (an infinite plane that misses it)"),
    ("empty", CAMERA, "the scene has no objects"),
]


def render(tmp_path, text, *options):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out.png"
    status = main(["render", str(scene), "--size", "32x24", "-o", str(out), "--quiet", *options])
    return status, out


@pytest.mark.parametrize("text, reason", [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_nothing_drawn_is_one_warning_line_with_the_reason(text, reason, tmp_path, capsys):
    status, out = render(tmp_path, text, "--backend", "reference")
    out_text, err = capsys.readouterr()
    assert status == 0 and out.exists() and out_text == ""
    assert err.splitlines() == [f"renderer: warning: nothing was drawn: {reason}"]


@pytest.mark.parametrize("case", ["looking away", "beyond far, reversed-Z", "right"])
def test_the_gpu_backend_warns_alike(case, tmp_path, capsys):
    text, reason = next(c[1:] for c in CASES if c[0] == case)
    status, _ = render(tmp_path, text, "--backend", "gpu", "--context", "osmesa")
    assert status == 0
    assert capsys.readouterr().err.splitlines() == [f"renderer: warning: nothing was drawn: {reason}"]


def test_a_frame_with_anything_drawn_gives_no_warning(tmp_path, capsys):
    """One corner of the cube in view is enough."""
    status, _ = render(tmp_path, CAMERA + BOX + "translate = [2.5, 1.5, 0]\n", "--backend", "reference")
    assert status == 0 and capsys.readouterr().err == ""


def test_compare_warns_too(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text(CAMERA + "far = 3\n" + BOX)
    status = main(["compare", str(scene), "--size", "32x24", "--context", "osmesa",
                   "--out", str(tmp_path / "cmp")])
    out, err = capsys.readouterr()
    assert status == 0 and '"passes": true' in out
    assert err.splitlines() == ["renderer: warning: nothing was drawn: box is beyond the far plane (3)"]
