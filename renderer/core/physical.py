"""The physical model (issue 33; docs/conventions.md, "The physical model"): a scene's
`model = "physical"` read in radiometric units, and the scene each method draws for it.

In the physical model a pixel shows radiance (W sr^-1 m^-2, linear):
- k_d is the Lambertian reflectance rho (at most 1: the BRDF rho / pi); k_s the albedo of the
  energy-normalised Phong lobe (n + 2) / (2 pi) k_s cos^n; `ambient` the radiance of a uniform
  surround, which a Lambertian surface reflects as rho L_a (k_a is not read);
- a point light's `intensity` is in W/sr and falls off as the inverse square (attenuation
  (0, 0, 1); a scene file may set no other); an area light's is along its normal (conventions.md,
  "Area lights"); a directional light's is the irradiance it gives a surface facing it (W/m^2);
- `emission` is an exitance (W/m^2): the surface's radiance is E / pi;
- a material's Fresnel reflectance is exact unless it says otherwise (scene files), and a
  refracted ray's radiance is scaled by eta^2 (n_i / n_t)^2 (radiance_scaling: the ray and path
  tracers' RADIANCE_SCALING), so that radiance inside glass is n^2 times that outside.

Each method draws the physical scene as a Phong one in its own units, so that nothing of its
shading changes (`for_method`, through each method's options' scene_for):
- the rasteriser and the ray tracer (the lighting equation, radiance out): k_d / pi,
  k_s (n + 2) / (2 pi), k_a = k_d, inverse-square point lights;
- the path tracer and radiosity, which compute exitance (pi times radiance) from reflectances
  and exitances: every light's intensity and every emission over pi (their pixels then show
  radiance), k_s (n + 2) / 2 (the lobe's exitance), inverse-square point lights.
"""

from __future__ import annotations

import dataclasses
import math

from renderer.core.scene import Scene

MODELS = ("phong", "physical")
INVERSE_SQUARE = (0.0, 0.0, 1.0)


def is_physical(scene: Scene) -> bool:
    return scene.model == "physical"


def _scaled(values, factor: float) -> tuple:
    return tuple(float(v) * factor for v in values)


def for_method(scene: Scene, method: str) -> Scene:
    """The scene `method` draws for `scene` (module docstring): itself in the Phong model."""
    if not is_physical(scene):
        return scene
    exitance = method in ("pathtrace", "radiosity")
    objects = []
    for obj in scene.objects:
        m = obj.material
        lobe = (m.n + 2.0) / 2.0                      # the normalised Phong lobe's, times pi
        if exitance:
            material = dataclasses.replace(m, ks=_scaled(m.ks, lobe), emission=_scaled(m.emission, 1 / math.pi))
        else:
            material = dataclasses.replace(m, kd=_scaled(m.kd, 1 / math.pi), ks=_scaled(m.ks, lobe / math.pi),
                                           ka=tuple(m.kd))
        objects.append(dataclasses.replace(obj, material=material))
    light_scale = 1 / math.pi if exitance else 1.0
    points = [dataclasses.replace(light, attenuation=INVERSE_SQUARE, intensity=_scaled(light.intensity, light_scale))
              for light in scene.point_lights]
    directionals = [dataclasses.replace(light, intensity=_scaled(light.intensity, light_scale))
                    for light in scene.directional_lights]
    return dataclasses.replace(scene, objects=objects, point_lights=points, directional_lights=directionals)
