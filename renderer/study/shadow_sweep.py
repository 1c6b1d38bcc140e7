"""The light-elevation sweep (`renderer extremes`, "light-elevation sweep"): one scene made
from a template at each of ELEVATIONS, a directional light from 1 to 89 degrees above the
ground, its shadow maps held against ray-cast truth (renderer/checks/shadow_truth.py) with the
map's visibility v taken from the reference's lookup and from each GPU backend's image.

    rows = measure_sweep((160, 120), {"egl": ctx, "osmesa": ctx})

The template (`elevation_scene`): a large low box as the ground (12 x 0.2 x 8: not planar,
so it is drawn into the map, as a caster of the box's and the ball's shadows, and a wrong
bias shows as acne on its lit top where the map covers it: where the box and the ball can
shadow it; renderer/core/shadow_casting.py), a cube and a tessellated ball standing on it
(contact: peter-panning shows as a gap), one directional light from azimuth LIGHT_AZIMUTH.

The GPU's v, per pixel, from three renders of the one-light scene in linear float colour:
shadows on (I_s), the light's shadows off (I_u) and the light off (I_a, the ambient term):
v = sum_rgb(I_s - I_a) / sum_rgb(I_u - I_a), the light's terms being multiplied by v and
nothing else (docs/conventions.md, "Shadows"). Where the denominator is below MIN_TERM the
light adds almost nothing and v is not measured (NaN); v within V_ROUNDING of 0 or 1 is
snapped there (float32 rounding of the three colours, at most ~4 ulp of 1 over MIN_TERM).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from renderer.checks.shadow_truth import EDGE_KEY, EDGE_PX, shadows_vs_truth
from renderer.core.primitives import cube, uv_sphere
from renderer.core.scene import Camera, DirectionalLight, Material, Scene, SceneObject, Transform
from renderer.methods import open_renderer

ELEVATIONS = (1, 2, 5, 10, 20, 30, 45, 60, 75, 89)      # degrees above the ground
LIGHT_AZIMUTH = 20.0          # degrees from +x towards +z: the light comes from the back left
MIN_TERM = 2.0 ** -6          # linear RGB summed: the light's terms below this leave v unmeasured
V_ROUNDING = 2.0 ** -14       # v this near 0 or 1 is 0 or 1 (float32 rounding, module docstring)


def light_direction(elevation: float) -> tuple[float, float, float]:
    """The way the light travels, `elevation` degrees above the horizon (down, across +x)."""
    e, a = math.radians(elevation), math.radians(LIGHT_AZIMUTH)
    return (math.cos(e) * math.cos(a), -math.sin(e), math.cos(e) * math.sin(a))


def elevation_scene(elevation: float) -> Scene:
    """The sweep's template at one elevation (module docstring)."""
    ground = Material(ka=(0.62, 0.6, 0.55), kd=(0.62, 0.6, 0.55), ks=(0.05, 0.05, 0.05), n=4.0)
    red = Material(ka=(0.75, 0.15, 0.1), kd=(0.75, 0.15, 0.1), ks=(0.5, 0.5, 0.5), n=40.0)
    blue = Material(ka=(0.15, 0.3, 0.7), kd=(0.15, 0.3, 0.7), ks=(0.3, 0.3, 0.3), n=20.0)
    objects = [
        SceneObject("ground", cube(2.0), ground, Transform(scale=(6.0, 0.1, 4.0), translate=(0.0, -0.1, 0.0))),
        SceneObject("box", cube(0.8), blue, Transform(rotate=(0.0, 30.0, 0.0), translate=(-1.4, 0.4, 0.2))),
        SceneObject("ball", uv_sphere(0.5, 32, 16), red, Transform(translate=(0.6, 0.5, -0.4))),
    ]
    return Scene(camera=Camera(eye=(0.5, 5.0, 7.0), look=(0.5, 0.0, 0.0), fov_y=45.0, near=0.5, far=30.0),
                 objects=objects, ambient=(0.12, 0.12, 0.12), background=(0.3, 0.38, 0.5),
                 directional_lights=[DirectionalLight(direction=light_direction(elevation),
                                                      intensity=(0.9, 0.88, 0.82))],
                 name=f"light_elevation_{elevation:g}")


def gpu_visibility(scene: Scene, size: tuple[int, int], ctx) -> np.ndarray:
    """(H, W) the map's visibility of the scene's one light as a GPU image shows it (module
    docstring; row 0 at the top); NaN where the light's terms are ~0 or nothing was drawn."""
    [light] = scene.directional_lights
    dark = replace(scene, directional_lights=[replace(light, intensity=(0.0, 0.0, 0.0))])
    with open_renderer(scene, size, context=ctx) as gpu:
        shadowed = gpu.render(linear=True).linear
        gpu.shadows = False
        unshadowed = gpu.render(linear=True).linear
    with open_renderer(dark, size, context=ctx) as gpu:
        ambient = gpu.render(linear=True).linear
    drawn = shadowed[..., 3] > 0
    term = (unshadowed[..., :3] - ambient[..., :3]).sum(axis=2).astype(np.float64)
    lit = (shadowed[..., :3] - ambient[..., :3]).sum(axis=2).astype(np.float64)
    measured = drawn & (term >= MIN_TERM)
    v = np.full(term.shape, np.nan)
    v[measured] = lit[measured] / term[measured]
    v[measured & (np.abs(v) <= V_ROUNDING)] = 0.0
    v[measured & (np.abs(v - 1.0) <= V_ROUNDING)] = 1.0
    return v


def truth_figures(scene: Scene, size: tuple[int, int], visibility: np.ndarray | None = None) -> dict:
    """The truth's figures for `scene` (ShadowTruth.as_dict(): wrong_beyond_2px_pixels,
    acne_pixels, wrong_outside_band_pixels, peter_panning, ...), the one light's visibility from the
    reference's lookup, or `visibility` (H, W) (gpu_visibility's image)."""
    given = None if visibility is None else {("directional", 0): visibility}
    return shadows_vs_truth(scene, *size, visibility=given).as_dict()


def _summary(figures: dict) -> dict:
    return {"acne_pixels": figures["acne_pixels"],
            f"{EDGE_KEY}_pixels": figures[f"{EDGE_KEY}_pixels"],
            "wrong_outside_band_pixels": figures["wrong_outside_band_pixels"],
            "wrong_outside_band_fraction": figures["wrong_outside_band_fraction"],
            "peter_panning_max_texels": figures["peter_panning"]["max_texels"],
            "considered_pixels": figures["considered_pixels"]}


def measure_sweep(size: tuple[int, int], contexts: dict, elevations=ELEVATIONS,
                  on_row=None) -> list[dict]:
    """One row per elevation: the truth's figures with v from the reference ("reference")
    and from each context's images (its kind); `on_row(row)`, if given, as each is made."""
    rows = []
    for elevation in elevations:
        scene = elevation_scene(elevation)
        row = {"elevation": elevation, "reference": _summary(truth_figures(scene, size))}
        for kind, ctx in contexts.items():
            row[kind] = _summary(truth_figures(scene, size, gpu_visibility(scene, size, ctx)))
        rows.append(row)
        if on_row is not None:
            on_row(row)
    return rows


def sweep_acne(row: dict) -> int:
    """The most acne pixels of a sweep row over its backends."""
    return max(figures["acne_pixels"] for key, figures in row.items() if key != "elevation")


def _cell(row: dict, backends: list[str], key: str) -> str:
    return " / ".join(f"{row[b][key]:,}" for b in backends)


def markdown_section(rows: list[dict], size: tuple[int, int]) -> str:
    """The table "light-elevation sweep" of extremes.md."""
    backends = ["reference", *[k for k in rows[0] if k not in ("elevation", "reference")]] if rows else []
    header = " / ".join("ref" if b == "reference" else b for b in backends)
    lines = ["## Light-elevation sweep", "",
             f"A directional light at each elevation over a low box with a cube and a ball on it "
             f"({size[0]}x{size[1]}, default shadow settings), held against ray-cast truth "
             f"(renderer/checks/shadow_truth.py); the map's visibility from the reference's "
             f"lookup (ref) and from each GPU backend's images (renderer/study/shadow_sweep.py). "
             f"Acne: pixels lit in truth that the receiver's own texels darken; wrong beyond "
             f"{EDGE_PX} px: pixels the map gets wrong farther than {EDGE_PX} pixels from the true "
             f"shadow boundary; wrong outside the band: farther than a texel from the true shadow "
             f"edge along the surface; peter-panning: the largest gap between a shadow and its "
             f"caster, in texels.", "",
             f"| elevation | acne ({header}) | wrong beyond {EDGE_PX} px ({header}) "
             f"| wrong outside band ({header}) | peter-panning max, texels ({header}) |",
             "| ---: | ---: | ---: | ---: | ---: |"]
    for row in rows:
        lines.append(f"| {row['elevation']}° | {_cell(row, backends, 'acne_pixels')} "
                     f"| {_cell(row, backends, f'{EDGE_KEY}_pixels')} "
                     f"| {_cell(row, backends, 'wrong_outside_band_pixels')} "
                     f"| {_cell(row, backends, 'peter_panning_max_texels')} |")
    return "\n".join(lines) + "\n"
