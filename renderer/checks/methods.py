"""Where the rasteriser and the ray tracer differ on one scene, and why (`renderer compare
SCENE --methods`).

Both methods render on the GPU at one size, through a chain of frames from the rasteriser's
picture to the full ray tracer's, each changing one thing (CHAIN):

    raster     the rasteriser (renderer.gpu.GpuRenderer), the materials' own shading
    phong      the rasteriser with every material Phong-shaded (Scene.with_shading)
    unshadowed the same without shadow maps (every light's shadows off)
    centre     the ray tracer with one ray through each pixel centre, max depth 0, no shadow
               rays: primary visibility and local shading, what the rasteriser computes
    samples    the same with the user's samples per pixel and pattern
    shadows    the same with shadow rays
    raytrace   the full ray tracer: also reflection and refraction to the user's max depth

A pixel counts where `raster` and `raytrace` differ in place by more than the threshold (the
pipeline tolerance's raw mismatch, renderer/checks/tolerance.py). Its cause (CAUSES) is the
first step of the chain that changes it in place by more than the threshold, or, where no
single step does (small changes adding up), the step that changes it most. Both steps that
touch shadows (the maps taken away, the shadow rays added) count as `shadows`: where the
shadow map and the shadow rays agree the pixel does not differ at all. The step from
`unshadowed` to `centre` is split by the tolerance's ±deviation allowance (compare.py): `edges`
where it changes the pixel by more than the threshold and each image has a match within
±1 px in the other (a silhouette a pixel apart), `tessellation` otherwise. A step that
cannot change anything (no flat or Gouraud material, one sample at the pixel centre, no
light, no reflecting or transmitting material or max depth 0) reuses the frame before it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from renderer.checks.compare import (DEFAULT_DEVIATION, DEFAULT_THRESHOLD, Comparison,
                                     channel_difference, compare_frames,
                                     position_deviation_mismatch)
from renderer.core.frame import Frame
from renderer.core.ray_options import RayOptions
from renderer.core.scene import Scene
from renderer.methods import open_renderer
from renderer.core.shadow_settings import Shadow
from renderer.core.shadows import has_shadow_maps

CHAIN = ("raster", "phong", "unshadowed", "centre", "samples", "shadows", "raytrace")


@dataclass(frozen=True)
class Cause:
    name: str
    colour: tuple[int, int, int]      # in the cause map
    colour_name: str
    meaning: str                      # what it is, and which method is right about it


CAUSES = (
    Cause("shading", (60, 120, 255), "blue",
          "flat and Gouraud materials: the rasteriser lights them per face or per vertex, as the "
          "material asks; the ray tracer lights every hit per pixel (Phong), which is the "
          "lighting equation at each point"),
    Cause("edges", (255, 220, 0), "yellow",
          "silhouettes a pixel apart: each method samples the edge at the pixel centre (the "
          "rasteriser by its fill rule, the ray tracer by its ray) and rounding puts it on "
          "either side; neither is wrong, and the pipeline tolerance's ±1 px allowance forgives it"),
    Cause("tessellation", (255, 120, 0), "orange",
          "the surface seen, or its shading, differs beyond ±1 px: the rasteriser draws an "
          "analytic sphere as an icosphere, or through the tessellation stages within their "
          "target (compare --methods --tessellate), (and skips the faces an object's cull names; "
          "a plane it draws as itself to the view's edge); the ray tracer's exact shapes are right"),
    Cause("sampling", (0, 220, 220), "cyan",
          "several samples per pixel: the ray tracer averages its samples (anti-aliased edges), "
          "the rasteriser takes one at the pixel centre; the average is nearer the pixel's "
          "true colour"),
    Cause("shadows", (230, 0, 230), "magenta",
          "the rasteriser's shadow maps against the ray tracer's shadow rays: a map's texels, "
          "filter and bias put a shadow's edge a texel or so off (renderer compare "
          "--shadows-vs-truth measures it), and lights or objects without shadow maps cast none; "
          "the shadow rays are right"),
    Cause("reflection", (0, 200, 0), "green",
          "mirror reflection (k_r) and refraction (k_t): the rasteriser shades only the local "
          "colour; the ray tracer's secondary rays are right, to its maximum depth"),
)
EDGES, TESSELLATION = 1, 2
SHADOWS = 4
# each step's cause; unshadowed -> centre: EDGES or TESSELLATION
STEP_CAUSE = np.array([0, SHADOWS, EDGES, 3, SHADOWS, 5])
VISIBILITY_STEP = 2                           # unshadowed -> centre
NO_DIFFERENCE = -1

# Remarks that hold for some scenes only (notes()).
PARALLEL_VIEWER = ("parallel projection: the rasteriser lights with the viewer at the eye "
                   "(V = E - P), the ray tracer with the viewer at each ray's origin (V = -D), so "
                   "highlights differ; those pixels count under tessellation")
SHADOW_TERMINATOR = ("shadows on meshes: along a smooth-shaded mesh's terminator its flat facets "
                     "can shadow points its interpolated normals light (the shadow-terminator "
                     "problem); the ray tracer's jagged edge there is an artefact of the facets")


def without_shadow_maps(scene: Scene) -> Scene:
    """A copy of `scene` whose lights have their shadow maps off (meshes shared)."""
    off = lambda light: replace(light, shadow=Shadow(enabled=False))     # noqa: E731
    return replace(scene, directional_lights=[off(x) for x in scene.directional_lights],
                   point_lights=[off(x) for x in scene.point_lights])


def explain(chain, threshold: int = DEFAULT_THRESHOLD, deviation: int = DEFAULT_DEVIATION) -> np.ndarray:
    """(H, W) int8 map of causes (indices into CAUSES), NO_DIFFERENCE where the first and last
    of `chain` (the (H, W, 4) uint8 images of CHAIN, in order) agree in place within
    `threshold`; see the module docstring for the rule."""
    if len(chain) != len(CHAIN):
        raise ValueError(f"expected the {len(CHAIN)} images of {', '.join(CHAIN)}, got {len(chain)}")
    changes = np.stack([channel_difference(a, b).max(axis=-1) for a, b in zip(chain, chain[1:])])
    beyond = changes > threshold
    step = np.where(beyond.any(axis=0), beyond.argmax(axis=0), changes.argmax(axis=0))
    cause = STEP_CAUSE[step]
    k = VISIBILITY_STEP
    forgiven = ~position_deviation_mismatch(chain[k], chain[k + 1], threshold, deviation)
    cause[(step == k) & ~(beyond[k] & forgiven)] = TESSELLATION
    differs = channel_difference(chain[0], chain[-1]).max(axis=-1) > threshold
    return np.where(differs, cause, NO_DIFFERENCE).astype(np.int8)


def cause_image(causes: np.ndarray, backdrop: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8: each cause's colour where it is the cause, elsewhere the backdrop
    ((H, W, 3|4) uint8, the ray-traced picture) as a dim grey, for orientation."""
    grey = backdrop[..., :3].mean(axis=-1) / 3
    image = np.repeat(grey.round().astype(np.uint8)[..., None], 3, axis=-1)
    for index, cause in enumerate(CAUSES):
        image[causes == index] = cause.colour
    return image


def notes(scene: Scene, counts: dict[str, int]) -> list[str]:
    """The remarks (PARALLEL_VIEWER, SHADOW_TERMINATOR) that may apply to this scene's counts."""
    remarks = []
    if scene.camera.projection == "parallel" and any(o.material.has_specular for o in scene.objects):
        remarks.append(PARALLEL_VIEWER)
    if counts["shadows"] and any(o.shape is None and o.material.shading != "flat" for o in scene.objects):
        remarks.append(SHADOW_TERMINATOR)
    return remarks


@dataclass
class MethodComparison:
    """The rasteriser against the ray tracer on one scene (compare_methods)."""
    scene: str
    raster: Frame
    raytrace: Frame
    causes: np.ndarray               # (H, W) int8: explain()
    comparison: Comparison           # compare_frames(raster, raytrace)
    settings: dict                   # the ray tracer's: samples, pattern, max_depth, seed
    renders: int                     # frames rendered (steps that change nothing reuse one)
    notes: list[str]                 # notes(): remarks for this scene

    def counts(self) -> dict[str, int]:
        return {cause.name: int((self.causes == k).sum()) for k, cause in enumerate(CAUSES)}

    def as_dict(self) -> dict:
        total = self.causes.size
        differing = int((self.causes != NO_DIFFERENCE).sum())
        counts = self.counts()
        info = self.raytrace.gl_info or {}
        return {"scene": self.scene, "size": list(self.raster.size), **self.settings,
                "threshold": self.comparison.threshold, "deviation": self.comparison.deviation,
                "pixels": total, "differing_pixels": differing, "differing_fraction": differing / total,
                "causes": {c.name: {"pixels": counts[c.name], "fraction": counts[c.name] / total,
                                    "colour": list(c.colour), "meaning": c.meaning} for c in CAUSES},
                "mismatched_pixels": self.comparison.mismatched_pixels, "notes": self.notes,
                "renders": self.renders, "gl_renderer": info.get("GL_RENDERER"),
                "context": info.get("context")}

    def table(self) -> str:
        """The figures as text: a line of settings, the total, a row per cause."""
        figures = self.as_dict()
        total, differing = figures["pixels"], figures["differing_pixels"]
        s = self.settings
        lines = [f"{self.scene} {figures['size'][0]}x{figures['size'][1]} ({figures['context']}, "
                 f"{figures['gl_renderer']}): the rasteriser against the ray tracer "
                 f"({s['samples']} spp {s['pattern']}, max depth {s['max_depth']})",
                 f"{differing:,} of {total:,} pixels ({differing / total:.2%}) differ in place by more "
                 f"than {figures['threshold']}/255; {figures['mismatched_pixels']:,} still do within "
                 f"±{figures['deviation']} px",
                 f"{'cause':<13} {'pixels':>8} {'share':>7}  {'map':<8} meaning"]
        for cause in CAUSES:
            row = figures["causes"][cause.name]
            lines.append(f"{cause.name:<13} {row['pixels']:>8,} {row['fraction']:>7.2%}  "
                         f"{cause.colour_name:<8} {cause.meaning}")
        lines += [f"note: {remark}" for remark in self.notes]
        return "\n".join(lines)


def compare_methods(scene: Scene, width: int, height: int, *, context=None, context_kind: str = "auto",
                    options: RayOptions | None = None, threshold: int = DEFAULT_THRESHOLD,
                    deviation: int = DEFAULT_DEVIATION) -> MethodComparison:
    """Render CHAIN on the GPU in one GL context (`context`, else a new one of
    `context_kind`) and explain where the rasteriser and the ray tracer (its `options`,
    default RayOptions()) differ."""
    from renderer.gpu.context import make_context, release_context
    options = RayOptions() if options is None else options
    ctx = make_context(context_kind) if context is None else context

    def frame_of(drawn: Scene, method: str = "raster", step: RayOptions | None = None) -> Frame:
        with open_renderer(drawn, (width, height), method=method, options=step, context=ctx) as renderer:
            return renderer.render()

    try:
        frames = {"raster": frame_of(scene)}
        phong = scene.with_shading("phong")
        frames["phong"] = frames["raster"] if set(scene.shading_modes()) == {"phong"} else frame_of(phong)
        frames["unshadowed"] = (frames["phong"] if not has_shadow_maps(scene) else
                                frame_of(without_shadow_maps(phong)))
        # What each ray-traced step sets; a step whose effective settings equal the last one's
        # reuses its frame (the sample offsets; no light: no shadow ray; nothing reflects: no bounce).
        lit = bool(scene.directional_lights or scene.point_lights)
        bounces = any(np.any(np.asarray(o.material.kr) > 0) or np.any(np.asarray(o.material.kt) > 0)
                      for o in scene.objects)
        n, kind = options.samples, options.pattern
        steps = {"centre": (1, "regular", 0, False), "samples": (n, kind, 0, False),
                 "shadows": (n, kind, 0, True), "raytrace": (n, kind, options.max_depth, True)}
        renders = 1 + (frames["phong"] is not frames["raster"]) + (frames["unshadowed"] is not frames["phong"])
        last = None
        for name, (n, kind, depth, shadows) in steps.items():
            centre = n == 1 and kind == "regular"          # one ray through the pixel centre
            sampling = "centre" if centre else (n, kind, options.seed, options.adaptive_threshold)
            key = (sampling, depth if bounces else 0, shadows and lit)
            if key != last:
                step = options.replace(samples=n, pattern=kind, max_depth=depth, shadows=shadows,
                                       adaptive_threshold=None if centre else options.adaptive_threshold)
                frame = frame_of(scene, "raytrace", step)
                renders += 1
            frames[name], last = frame, key
    finally:
        if context is None:
            release_context(ctx)
    causes = explain([frames[name].rgba8 for name in CHAIN], threshold, deviation)
    raster, raytrace = frames["raster"], frames["raytrace"]
    comparison = compare_frames(raster.rgba8, raytrace.rgba8, raster.depth, raytrace.depth,
                                threshold=threshold, deviation=deviation)
    settings = {"samples": options.samples, "pattern": options.pattern, "max_depth": options.max_depth,
                "seed": options.seed, "adaptive_threshold": options.adaptive_threshold}
    result = MethodComparison(scene.name, raster, raytrace, causes, comparison, settings, renders, [])
    result.notes = notes(scene, result.counts())
    return result
