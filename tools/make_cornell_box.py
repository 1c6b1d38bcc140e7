"""Write the Cornell box (scene cornell_box_radiosity) from the Cornell Program of Computer
Graphics' published data (https://www.graphics.cornell.edu/online/box/data.html: the geometry
in millimetres, the camera, the surfaces' measured reflectance spectra at 4 nm from 400 to
700 nm, and the light's emission spectrum at 400, 500, 600 and 700 nm):

    python tools/make_cornell_box.py

assets/meshes/cornell_box/{white,red,green,light}.obj   the quads of each material, in metres,
                                                        counter-clockwise seen from the front
assets/scenes/cornell_box_radiosity.toml                the scene, its colours computed here

Colours (linear sRGB, renderer/core/colour.py's XYZ_TO_RGB): a reflectance spectrum's colour
under CIE D65 with the CIE 1931 2-degree observer (colour-science's tables), normalised so that
a perfect white reflector is Y = 1, which the sRGB matrix makes (1, 1, 1); the light's emission
spectrum (linearly interpolated between its four samples, as a spectral radiance) integrated
against the same observer and divided by the integral of y-bar, so that a flat spectrum of 1
has Y = 1 (the data's own unit), and its exitance for radiosity E = pi L (a Lambertian emitter).

Two changes to the data, both said in the scene file: the ceiling is cut around the light
(four quads), so that the light, in the ceiling's plane, is no coincident surface; and nothing
else. The blocks stand on the floor without bottoms, as the data gives them.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
MESHES = ROOT / "assets" / "meshes" / "cornell_box"
SCENE = ROOT / "assets" / "scenes" / "cornell_box_radiosity.toml"

# -- the data (millimetres), as the page gives it --------------------------------------------
FLOOR = [(552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2)]
LIGHT = [(343.0, 548.8, 227.0), (343.0, 548.8, 332.0), (213.0, 548.8, 332.0), (213.0, 548.8, 227.0)]
CEILING = [(556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0)]
BACK = [(549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2)]
RIGHT_GREEN = [(0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2)]
LEFT_RED = [(552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0)]
SHORT_BLOCK = [
    [(130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)],
    [(290.0, 0.0, 114.0), (290.0, 165.0, 114.0), (240.0, 165.0, 272.0), (240.0, 0.0, 272.0)],
    [(130.0, 0.0, 65.0), (130.0, 165.0, 65.0), (290.0, 165.0, 114.0), (290.0, 0.0, 114.0)],
    [(82.0, 0.0, 225.0), (82.0, 165.0, 225.0), (130.0, 165.0, 65.0), (130.0, 0.0, 65.0)],
    [(240.0, 0.0, 272.0), (240.0, 165.0, 272.0), (82.0, 165.0, 225.0), (82.0, 0.0, 225.0)]]
TALL_BLOCK = [
    [(423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)],
    [(423.0, 0.0, 247.0), (423.0, 330.0, 247.0), (472.0, 330.0, 406.0), (472.0, 0.0, 406.0)],
    [(472.0, 0.0, 406.0), (472.0, 330.0, 406.0), (314.0, 330.0, 456.0), (314.0, 0.0, 456.0)],
    [(314.0, 0.0, 456.0), (314.0, 330.0, 456.0), (265.0, 330.0, 296.0), (265.0, 0.0, 296.0)],
    [(265.0, 0.0, 296.0), (265.0, 330.0, 296.0), (423.0, 330.0, 247.0), (423.0, 0.0, 247.0)]]
CAMERA = {"position": (278.0, 273.0, -800.0), "direction": (0.0, 0.0, 1.0), "up": (0.0, 1.0, 0.0),
          "focal_length": 0.035, "film": 0.025}
WAVELENGTHS = np.arange(400, 701, 4)
WHITE = [0.343, 0.445, 0.551, 0.624, 0.665, 0.687, 0.708, 0.723, 0.715, 0.710, 0.745, 0.758, 0.739,
         0.767, 0.777, 0.765, 0.751, 0.745, 0.748, 0.729, 0.745, 0.757, 0.753, 0.750, 0.746, 0.747,
         0.735, 0.732, 0.739, 0.734, 0.725, 0.721, 0.733, 0.725, 0.732, 0.743, 0.744, 0.748, 0.728,
         0.716, 0.733, 0.726, 0.713, 0.740, 0.754, 0.764, 0.752, 0.736, 0.734, 0.741, 0.740, 0.732,
         0.745, 0.755, 0.751, 0.744, 0.731, 0.733, 0.744, 0.731, 0.712, 0.708, 0.729, 0.730, 0.727,
         0.707, 0.703, 0.729, 0.750, 0.760, 0.751, 0.739, 0.724, 0.730, 0.740, 0.737]
GREEN = [0.092, 0.096, 0.098, 0.097, 0.098, 0.095, 0.095, 0.097, 0.095, 0.094, 0.097, 0.098, 0.096,
         0.101, 0.103, 0.104, 0.107, 0.109, 0.112, 0.115, 0.125, 0.140, 0.160, 0.187, 0.229, 0.285,
         0.343, 0.390, 0.435, 0.464, 0.472, 0.476, 0.481, 0.462, 0.447, 0.441, 0.426, 0.406, 0.373,
         0.347, 0.337, 0.314, 0.285, 0.277, 0.266, 0.250, 0.230, 0.207, 0.186, 0.171, 0.160, 0.148,
         0.141, 0.136, 0.130, 0.126, 0.123, 0.121, 0.122, 0.119, 0.114, 0.115, 0.117, 0.117, 0.118,
         0.120, 0.122, 0.128, 0.132, 0.139, 0.144, 0.146, 0.150, 0.152, 0.157, 0.159]
RED = [0.040, 0.046, 0.048, 0.053, 0.049, 0.050, 0.053, 0.055, 0.057, 0.056, 0.059, 0.057, 0.061,
       0.061, 0.060, 0.062, 0.062, 0.062, 0.061, 0.062, 0.060, 0.059, 0.057, 0.058, 0.058, 0.058,
       0.056, 0.055, 0.056, 0.059, 0.057, 0.055, 0.059, 0.059, 0.058, 0.059, 0.061, 0.061, 0.063,
       0.063, 0.067, 0.068, 0.072, 0.080, 0.090, 0.099, 0.124, 0.154, 0.192, 0.255, 0.287, 0.349,
       0.402, 0.443, 0.487, 0.513, 0.558, 0.584, 0.620, 0.606, 0.609, 0.651, 0.612, 0.610, 0.650,
       0.638, 0.627, 0.620, 0.630, 0.628, 0.642, 0.639, 0.657, 0.639, 0.635, 0.642]
LIGHT_WAVELENGTHS = (400, 500, 600, 700)
LIGHT_EMISSION = (0.0, 8.0, 15.6, 18.4)


def observer():
    """(wavelengths at 1 nm from 400 to 700, the CIE 1931 2-degree colour matching functions
    there (W, 3), D65 there (W,)): colour-science's tables."""
    import colour
    shape = colour.SpectralShape(400, 700, 1)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    return shape.wavelengths, cmfs.values, d65.values


def linear_srgb(spectrum, weights) -> np.ndarray:
    """Linear sRGB of `spectrum` (W,) seen through the observer with `weights` (W,) on each
    wavelength, normalised so that a spectrum of 1 has Y = 1."""
    from renderer.core.colour import XYZ_TO_RGB
    _, cmfs, _ = observer()
    weighted = weights[:, None] * cmfs
    return XYZ_TO_RGB @ ((spectrum[:, None] * weighted).sum(axis=0) / weighted[:, 1].sum())


def reflectance_rgb(values) -> np.ndarray:
    """Linear sRGB of a reflectance spectrum under D65, the 1931 observer, white = Y 1."""
    wavelengths, _, d65 = observer()
    return linear_srgb(np.interp(wavelengths, WAVELENGTHS, values), d65)


def emission_rgb() -> np.ndarray:
    """Linear sRGB of the light's spectral radiance, a flat spectrum of 1 having Y = 1."""
    wavelengths, _, _ = observer()
    radiance = np.interp(wavelengths, LIGHT_WAVELENGTHS, LIGHT_EMISSION)
    return linear_srgb(radiance, np.ones_like(radiance))


def ceiling_around_light():
    """The ceiling as four quads around the light's rectangle (x 213..343, z 227..332)."""
    y = 548.8
    x0, x1, z0, z1 = 213.0, 343.0, 227.0, 332.0
    rects = [(0.0, 556.0, 0.0, z0), (0.0, 556.0, z1, 559.2), (0.0, x0, z0, z1), (x1, 556.0, z0, z1)]
    return [[(a, y, c), (b, y, c), (b, y, d), (a, y, d)] for a, b, c, d in rects]


def oriented(quad, toward) -> list:
    """The quad's corners in the order whose front (counter-clockwise) faces the point `toward`
    (inside the room for a wall, outside a block for its faces)."""
    q = np.array(quad, float)
    normal = np.cross(q[1] - q[0], q[2] - q[0])
    return quad if normal @ (np.asarray(toward, float) - q.mean(axis=0)) > 0 else quad[::-1]


def away_from(quad, centre) -> list:
    q = np.array(quad, float)
    return oriented(quad, 2 * q.mean(axis=0) - np.asarray(centre, float))


def obj_text(quads) -> str:
    lines = ["# tools/make_cornell_box.py: the Cornell box's quads in metres "
             "(https://www.graphics.cornell.edu/online/box/data.html)"]
    for quad in quads:
        for x, y, z in quad:
            lines.append(f"v {x / 1000:.4f} {y / 1000:.4f} {z / 1000:.4f}")
    for k in range(len(quads)):
        a = 4 * k + 1
        lines += [f"f {a} {a + 1} {a + 2}", f"f {a} {a + 2} {a + 3}"]
    return "\n".join(lines) + "\n"


def main() -> None:
    room_centre = (278.0, 274.4, 279.6)
    short_centre = np.mean(np.array(SHORT_BLOCK[0]), axis=0) * [1, 0.5, 1]
    tall_centre = np.mean(np.array(TALL_BLOCK[0]), axis=0) * [1, 0.5, 1]
    white = ([oriented(FLOOR, room_centre), oriented(BACK, room_centre)]
             + [oriented(q, room_centre) for q in ceiling_around_light()]
             + [away_from(q, short_centre) for q in SHORT_BLOCK]
             + [away_from(q, tall_centre) for q in TALL_BLOCK])
    meshes = {"white": white, "red": [oriented(LEFT_RED, room_centre)],
              "green": [oriented(RIGHT_GREEN, room_centre)], "light": [oriented(LIGHT, room_centre)]}
    MESHES.mkdir(parents=True, exist_ok=True)
    for name, quads in meshes.items():
        (MESHES / f"{name}.obj").write_text(obj_text(quads), encoding="utf-8")
    colours = {name: reflectance_rgb(values) for name, values in (("white", WHITE), ("red", RED),
                                                                 ("green", GREEN))}
    radiance = emission_rgb()
    fov = 2 * math.degrees(math.atan(CAMERA["film"] / 2 / CAMERA["focal_length"]))
    eye = np.array(CAMERA["position"]) / 1000
    look = eye + np.array(CAMERA["direction"])
    fmt = lambda v: "[" + ", ".join(f"{x:.6g}" for x in v) + "]"     # noqa: E731
    text = f'''# The Cornell box as the Cornell Program of Computer Graphics publishes it
# (https://www.graphics.cornell.edu/online/box/data.html), for radiosity (--method radiosity):
# made by tools/make_cornell_box.py, which says how each number follows from the data (the
# geometry in metres; the colours from the measured spectra, linear sRGB under D65; the
# light's emission spectrum as radiance L, its exitance E = pi L). One change: the ceiling is
# cut around the light, which lies in its plane. The light is the only emitter: the scene has
# no [[lights]], so the rasteriser and the ray tracer show it by its ambient term alone.
description = "Radiosity (--method radiosity): the Cornell box from its published data"

background = [0.0, 0.0, 0.0]
ambient = [0.1, 0.1, 0.1]

[camera]
eye = {fmt(eye)}
look = {fmt(look)}
up = {fmt(CAMERA["up"])}
fov_y = {fov:.6g}          # 2 atan(film 25 mm / 2 / focal length 35 mm)
near = 0.01
far = 5.0

[materials.white]
kd = {fmt(colours["white"])}
ka = {fmt(colours["white"])}

[materials.red]
kd = {fmt(colours["red"])}
ka = {fmt(colours["red"])}

[materials.green]
kd = {fmt(colours["green"])}
ka = {fmt(colours["green"])}

[materials.light]
kd = [0.78, 0.78, 0.78]     # the data gives the light no reflectance; a white diffuser's
ka = [0.78, 0.78, 0.78]
emission = {fmt(math.pi * radiance)}     # pi L, L = {fmt(radiance)}
'''
    for name in ("white", "red", "green", "light"):
        text += f'''
[[objects]]
name = "{name}"
mesh = {{ file = "meshes/cornell_box/{name}.obj" }}
material = "{name}"
'''
    SCENE.write_text(text, encoding="utf-8")
    print("white", colours["white"], "red", colours["red"], "green", colours["green"], "L", radiance)


if __name__ == "__main__":
    main()
