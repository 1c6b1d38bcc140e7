"""`renderer extremes`: the stiff and extreme scenes of assets/extreme/, each rendered by the
GPU (EGL and OSMesa) and by the reference, with the figures that show it is stable.

    cases = measure_extremes(extreme_scenes(), (160, 120), {"egl": ctx, "osmesa": ctx})
    write_report(Path("out"), cases, (160, 120))   # out/extremes.json and out/extremes.md

Ground truth is the reference pipeline in float64 at the same size: the question here is
numerical stability, not aliasing. Each case passes when no pixel is NaN or Inf anywhere
(the linear colour, and the depth where something was drawn) and every GPU frame meets the
pipeline tolerance against it (renderer/checks/tolerance.py). A scene authored with
reversed-Z is measured a second time with it off, to show the depth error it removes. A
scene whose file is refused (a NaN vertex) is listed with the one-line error a user sees.

A scene file whose name starts with `rt_` is ray traced instead (RayTracer on each context
against reference/raytrace in float64, 1 sample per pixel or its RAYTRACE_SAMPLING, at each of
its RAYTRACE_DEPTHS, the default depth otherwise): where the float32 and float64 references disagree on a grazing
ray (renderer/checks/compare.py, grazing_ray_pixels) either one's colour and depth is
accepted, as at the rasteriser's depth ties. Ray-traced cases are not rasterised: the
rasteriser draws their spheres and planes as tessellations, whose extremes are the rasteriser
cases' own.

A scene file whose name starts with `rad_` is drawn by radiosity (RadiosityRenderer on each
context against the twin in float64, RADIOSITY_OPTIONS or the defaults): it passes when
nothing is NaN or Inf, the solver converged, and every frame meets the pipeline tolerance;
its figures say whether the GPU's form factors were the twin's exactly, and its residual.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from renderer.core.builtin import assets_dir, scene_description
from renderer.checks.compare import compare_frames, depth_tie_pixels, either_precision
from renderer.checks.tolerance import PIPELINE_TOLERANCE as TOLERANCE
from renderer.core.ray_depth import DEFAULT_MAX_DEPTH
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_solve import residual
from renderer.core.ray_options import RayOptions
from renderer.errors import SceneError
from renderer.methods import open_renderer
from renderer.core.imageio import outputs
from renderer.core.jsonio import json_text
from renderer.core.scene_file import load_scene
from renderer.study.shadow_sweep import markdown_section, sweep_acne

REVERSED_Z_STABILITY = ("reversed-Z: glClipControl ZERO_TO_ONE, near -> 1, far -> 0, a float32 "
                        "depth buffer cleared to 0 and GL_GREATER; the shadow map keeps the "
                        "standard mapping, its depth spanning only the light's casters and "
                        "receivers")

# What makes each case stable, keyed by the scene file's name (docs/conventions.md has the rules).
STABILITY = {
    "bad_normals": "the loader renormalises file normals and replaces zero-length ones by the "
                   "computed vertex normal, so both pipelines get unit normals",
    "camera_along_up": "look_at falls back to the world axis least aligned with the view "
                       "direction when up is parallel to it",
    "crossing_w_zero": "clipping in homogeneous coordinates before the divide by w "
                       "(GL's clipper; the reference divides only after clipping)",
    "degenerate_triangles": "zero-area triangles are never rasterised; a face normal of zero "
                            "length stays zero (normalize_or_zero), never NaN",
    "depth_ratio_1e5": REVERSED_Z_STABILITY,
    "depth_ratio_1e8": REVERSED_Z_STABILITY,
    "duplicate_vertices": "coincident vertices of a file without normals are merged (and split "
                          "again at creases); the repeated faces share their vertices, tie "
                          "exactly and the first drawn wins in both",
    "extreme_scale": "the normal matrix is the cofactor matrix (det(M) M^-T), scaled in float64 "
                     "before the float32 upload",
    "far_from_origin": "camera-relative transforms: T(-eye) M in float64, the view a rotation, "
                       "eye and lights relative to the eye; the light views are built from the "
                       "same camera-relative points",
    "grazing_light": "max(N.L, 0) and no highlight unless N.L > 0 and R.V > 0",
    "light_behind": "max(N.L, 0) and no highlight unless N.L > 0 and R.V > 0: ambient only",
    "nan_mesh": "refused when loaded: one line naming file, key and reason, exit status 2",
    "phong_exponents": "pow(R.V, n) only for R.V > 0 (GLSL's pow is undefined for a base <= 0); "
                       "n = 0 gives 1 there, n = 10000 underflows to 0",
    "point_light_on_surface": "at distance 0 the light is fully incident: L = N, "
                              "att = 1 / c",
    "singular_model": "the cofactor normal matrix is defined for det(M) = 0; a normal it "
                      "zeroes lights as ambient (normalize_or_zero)",
    "subpixel_triangles": "vertices snapped to 1/256 px and the fill rule decide coverage "
                          "identically in both pipelines",
    # shadow maps (docs/conventions.md, "Shadows")
    "shadow_contact": "the automatic bias moves a lookup at most the filter's reach (plus 1/4 "
                      "texel towards the light), so a shadow starts within a texel of where its "
                      "caster touches; the floor, planar with everything on its lit side, is "
                      "left out of the map and cannot self-shadow at the contact",
    "shadow_grazing_light": "the normal-offset bias is finite at every angle (o >= r(|N.X| + "
                            "|N.Y|) texels, where a slope-scaled bias grows as tan(theta)); the "
                            "floor cannot shadow its own lit side and is left out of the map",
    "shadow_light_inside": "a point light's near plane is half the distance to the nearest "
                           "caster triangle, so the enclosing mesh is never clipped away and "
                           "every face's depth holds it; a lookup beyond it is shadowed",
    "shadow_point_in_box": "the cube-face rule's ties (largest |d_k|, x before y before z) are "
                           "the same in both twins, and each face is widened by a guard band "
                           "holding real depth, so filter taps at a face's edge read no seam",
    "shadow_tiny_caster": "a directional map is fitted to the receivers in view cut to the "
                          "casters' box across the light: its texels are the caster's size / R, "
                          "not the floor's; the floor is not drawn into it",
    # textures (docs/conventions.md, "Texture coordinates"; reference/sampler.py)
    "tex_1x1": "a 1 x 1 texture is one level, and every wrap, filter and blend of it reads its "
               "one texel (lerp8 of equal texels is the texel): the level of detail, the wrap "
               "and the anisotropic footprint cannot show",
    "tex_grazing": "llvmpipe's anisotropic filter twinned texel for texel (the EWA over the "
                   "footprint's ellipse at the level of its minor axis, NEAREST texels, the "
                   "Gaussian table); a floor with small UVs, whose float32 interpolation "
                   "stays within a weight step",
    "tex_horizon": "the nearest texel is floor(fl32(u W)) on both sides; the plane centred under "
                   "the camera keeps u small where a square covers many pixels, so GL's float32 "
                   "interpolation picks the twin's texel there, and the moire is the same in both",
    "tex_huge_uv": "the fixed-point coordinate's int32 wrap (round(s W 256) - 128 at |s| W 256 >= "
                   "2^31 is INT_MIN - 128: the last and first texels half and half) reproduced, "
                   "not the textbook's repeat; NPOT repeat takes the fraction first; uv_offset "
                   "added in float32 on both sides",
    "tex_magnified": "texel coordinates in 1/256 of a texel (round(s W 256)) and 8-bit weights on "
                     "both sides: at 1000 pixels a texel each weight step spans about 4 pixels, "
                     "the same steps in both",
    "tex_npot": "NPOT repeat takes u's fraction before the texel, at every level by the base "
                "level's size (as llvmpipe); mirror takes the float path; the mip chain's "
                "fractional box weights are the same uploaded levels for both",
    # the tessellation stages (docs/tessellation.md)
    "tess_levels_1_and_64": "levels are clamped to [1, 64] in the control stage and the twin's "
                            "tessellator is llvmpipe's line by line; a patch makes at most 3,169 "
                            "points, so 20 patches a draw keep each run's uint16 indices from "
                            "wrapping (one draw at level 64 draws later patches on wrong points)",
    "tess_near_plane": "an edge whose midpoint's clip w is at or below 0 gets the largest level, "
                       "never one from a negative w; the generated triangles are clipped in "
                       "homogeneous coordinates like any others",
    "tess_tiny_far": "a need below one part clamps to level 1 (the patch drawn as it is); s >= 1 "
                     "(an error as large as the sphere) gives 1 too",
    "tess_edge_on": "levels depend on world lengths and depth, not on the patch's projected "
                    "area, so a grazing patch gets the levels its edges need; the displaced "
                    "heights are read at level 0 (no derivatives in the evaluation stage)",
    # ray traced (docs/conventions.md, "Rays")
    "rad_stiff_furnace": "the delta form factors are scaled to sum to exactly 1, so a closed room's "
                         "rows sum to 1 within 1e-15 and B = E / (1 - rho) holds at rho = 0.999 "
                         "(a sensitivity of 1e-15 / (1 - rho)); Gauss-Seidel sweeps until its "
                         "largest change is 1e-6 of E (about 7,000 sweeps); the direct solver is "
                         "exact in one",
    "rad_tiny_beside_huge": "reversed-Z hemicubes (float32 depth keeps 1e-7 relative precision at "
                            "every distance) with the near plane 1e-3 of the shortest element "
                            "edge and the far plane beyond every element: finite, GPU = twin. "
                            "Not accurate: the huge elements' hemicubes see the tile through no "
                            "pixel centre (it is smaller than a pixel), so its light is lost; "
                            "finer elements or hemicubes are the remedy",
    "rad_emitter_in_closed_box": "an element emits and reflects from its front only: its back "
                                 "passes nothing on in the item buffers and is drawn black",
    "rad_grazing_pair": "a neighbour below an element's plane is clipped at the near plane or "
                        "falls below a side face's horizon (discarded): the delta form factors "
                        "weigh z / (pi r^4), finite at every angle",
    "rad_coincident": "coplanar surfaces: the twin keeps the first drawn of equal depths as GL "
                      "does and flags as ties the pixels where GL's float32 depth planes may "
                      "order the two either way; the form factors then differ there (z-fighting "
                      "in the hemicubes), the images stay within the tolerance",
    "rt_coplanar": "hit ties: a surface replaces the nearest hit only when nearer by more than "
                   "2^-18 relative, so the plane, found first, shows wherever the triangle lies "
                   "in it; rays leaving it start at s > 2^-18 |O| and skip it",
    "rt_fast_motion": "motion in the displacement form about camera-relative centres (X + (R - I)(X - c) "
                      "+ t v), rays moved into a mesh's time-0 frame and its normals turned back: "
                      "rounding relative to the distance moved, whatever the speed or the turns",
    "rt_far_from_origin": "camera-relative coordinates: the shapes and lights relative to the "
                          "eye in float64 before the float32 upload",
    "rt_huge_aperture": "the lens offset lies across the view axis and every lens ray passes "
                        "its pinhole ray's point on the focus plane (O' = O + offset, D' = D - "
                        "offset / f: nothing divides by the aperture), so rays starting 50 units "
                        "off the axis stay finite and s stays the view depth",
    "rt_glossy_exponents": "a lobe below the surface is absorbed, not reflected back; "
                           "square_to_phong_lobe computes 1 - cos alpha from log and exp (series "
                           "where they would cancel), so an exponent of 1e6 keeps its angles "
                           "where sqrt(1 - cos^2) would round them away",
    "rt_grazing_sphere": "the robust discriminant (Ray Tracing Gems ch. 7); where float32 "
                         "cannot tell a tangent ray from a miss the float64 reference decides "
                         "otherwise, and those grazing pixels accept either",
    "rt_huge_area_light": "shadow rays to a light's point end a hit tie short of it (s_max = "
                          "d (1 - 2^-18)), so the floor the point lies in does not decide them "
                          "by float32's rounding; points behind a receiver's horizon add nothing "
                          "and cast no shadow ray",
    "rt_huge_sphere": "rays leaving a sphere never meet it again but at the far root q/a "
                      "(convexity), so the cancellation of f.f - r^2 at radius 1e4 casts no "
                      "false shadow; camera rays' depth keeps it within 5e-4",
    "rt_inside_glass": "from inside, the near root is behind and the far one is the hit; "
                       "leaving the glass flips the normal and eta = ior; Snell's k < 0 is "
                       "total internal reflection, weighted F = 1",
    "rt_light_on_surface": "a shadow ray of length 0 (d = 0) casts nothing and the light is "
                           "fully incident (L = N); rays along the plane graze the sphere "
                           "resting on it, accepted either way",
    "rt_mirrors": "Hall and Greenberg's weight cut-off (2^-9) and the energy rule bound the "
                  "ray tree, so the GLSL loop is finite at depth 64; perfect mirrors keep "
                  "weight 1 and reach it",
    "rt_tiny_sphere": "rays leaving a shape start on it, with no offset to swamp a radius of "
                      "1e-4 (Waechter and Binder's 2^-16 near the eye is for triangles only)",
    "rt_total_internal_reflection": "ray_refract reports k < 0 and the transmitted weight "
                                    "goes to the reflection (F = 1); triangles' rays leave "
                                    "from Waechter and Binder's offset",
}

# Ray-traced cases measured at other maximum depths than the default, and with more samples
# per pixel than 1 (regular pattern; motion blur: each sample its own time).
RAYTRACE_DEPTHS = {"rt_mirrors": (0, 64)}
# Ray-traced cases whose effect needs several samples per pixel (each sample its own lens
# point, or its own time): (samples, pattern); one regular sample otherwise, whose lens point is
# the lens's centre and whose time the middle of the shutter.
RAYTRACE_SAMPLING = {"rt_huge_aperture": (4, "jittered"), "rt_fast_motion": (4, "regular"),
                     "rt_huge_area_light": (4, "jittered"), "rt_glossy_exponents": (4, "jittered")}
RAY_TRACED_PREFIX = "rt_"
# A scene file whose name starts with this is drawn by radiosity (`--method radiosity`), each
# GPU context's frame against the twin's (reference/radiosity/, float64), with the options of
# RADIOSITY_OPTIONS or the defaults.
RADIOSITY_PREFIX = "rad_"
RADIOSITY_OPTIONS = {
    # rho = 0.999 needs about 7,000 Gauss-Seidel sweeps: 48 elements keep them to seconds
    "rad_stiff_furnace": RadiosityOptions(element_size=1.0, hemicube=16, max_iterations=20000),
}


def is_ray_traced(name: str) -> bool:
    """Whether the extreme scene file `name` (its stem) is ray traced (module docstring)."""
    return name.startswith(RAY_TRACED_PREFIX)


def method_of(name: str) -> str:
    """The method that draws the extreme scene file `name` (its stem): by its prefix."""
    if is_ray_traced(name):
        return "raytrace"
    return "radiosity" if name.startswith(RADIOSITY_PREFIX) else "raster"


def extreme_scenes(extra=()) -> dict[str, Path]:
    """Name to path of every scene in assets/extreme/, then of the `extra` scene files."""
    scenes = {path.stem: path for path in sorted((assets_dir() / "extreme").glob("*.toml"))}
    scenes.update((Path(path).stem, Path(path)) for path in extra)
    return scenes


def is_finite_frame(frame) -> bool:
    """No NaN or Inf in the linear colour, nor in the depth where something was drawn
    (+inf is the depth of the background by convention)."""
    drawn = frame.rgba8[..., 3] == 255
    return bool(np.isfinite(frame.linear).all() and np.isfinite(frame.depth[drawn]).all()
                and not np.isnan(frame.depth).any())


def measure_scene(scene, size: tuple[int, int], contexts: dict) -> dict:
    """Figures of one scene: finiteness per backend and each GPU frame against the float64
    reference (the worst context's figures are the case's). `contexts` are the pipeline
    tolerance's figures, which accept either surface where the reference finds two closer
    in depth than GL can order (depth ties: `tie_pixels`); `truth` holds the same frame
    against the reference's own image alone, where z-fighting shows."""
    gpu_frames = {}
    for kind, ctx in contexts.items():
        with open_renderer(scene, size, context=ctx) as gpu:
            gpu_frames[kind] = gpu.render(linear=True, depth=True)
            subpixel_bits = gpu.subpixel_bits
    with open_renderer(scene, size, backend="reference", precision="float64",
                       subpixel_bits=subpixel_bits) as twin:
        truth = twin.render(linear=True)
    finite = {kind: is_finite_frame(frame) for kind, frame in gpu_frames.items()}
    finite["reference"] = is_finite_frame(truth)
    per_context = {kind: compare_frames(frame.rgba8, truth.rgba8, frame.depth, truth.depth,
                                        reference_tie=truth.rgba8_tie).as_dict()
                   for kind, frame in gpu_frames.items()}
    against_truth = {kind: compare_frames(frame.rgba8, truth.rgba8).as_dict()
                     for kind, frame in gpu_frames.items()}
    return {"finite": finite, "tie_pixels": depth_tie_pixels(truth),
            "contexts": per_context, "worst": _worst(per_context),
            "truth": against_truth, "worst_truth": _worst(against_truth),
            "passes": all(finite.values()) and all(TOLERANCE.passes(c) for c in per_context.values())}


def measure_ray_traced(scene, size: tuple[int, int], contexts: dict,
                       max_depth: int = DEFAULT_MAX_DEPTH, samples: int = 1,
                       pattern: str = "regular") -> dict:
    """Figures of one ray-traced scene, as measure_scene: each GPU frame against the float64
    reference, which accepts the float32 reference's colour and depth at grazing pixels
    (`grazing_pixels`: where the two references' ray trees differ); `truth` without that.
    `samples` per pixel, regular pattern."""
    options = RayOptions(max_depth=max_depth, samples=samples, pattern=pattern)
    gpu_frames = {}
    for kind, ctx in contexts.items():
        with open_renderer(scene, size, method="raytrace", options=options, context=ctx) as tracer:
            gpu_frames[kind] = tracer.render()
    with open_renderer(scene, size, method="raytrace", backend="reference", options=options) as ref:
        twin = ref.render()
        ref.precision = "float64"                # the same BVH, for both precisions
        truth = ref.render()
    tie, tie_depth, grazing = either_precision(truth, twin)
    finite = {kind: is_finite_frame(frame) for kind, frame in gpu_frames.items()}
    finite["reference"] = is_finite_frame(truth) and is_finite_frame(twin)
    per_context = {kind: compare_frames(frame.rgba8, truth.rgba8, frame.depth, truth.depth,
                                        reference_tie=tie, reference_tie_depth=tie_depth).as_dict()
                   for kind, frame in gpu_frames.items()}
    against_truth = {kind: compare_frames(frame.rgba8, truth.rgba8).as_dict()
                     for kind, frame in gpu_frames.items()}
    return {"finite": finite, "grazing_pixels": grazing,
            "contexts": per_context, "worst": _worst(per_context),
            "truth": against_truth, "worst_truth": _worst(against_truth),
            "passes": all(finite.values()) and all(TOLERANCE.passes(c) for c in per_context.values())}


def measure_radiosity(scene, size: tuple[int, int], contexts: dict, options: RadiosityOptions) -> dict:
    """Figures of one radiosity scene, as measure_scene: each GPU context's frame against the
    twin's in float64 (depth ties accepted either way), whether the GPU's form factors are the
    twin's exactly (identical item buffers), and the solution's elements, iterations,
    convergence and residual (the whole residual, max |E + rho (H + S + F B) - B|: the solver's
    source, with the lights' and the sky's light; and over the largest source, as the solvers'
    tolerance reads it)."""
    gpu_frames, matrices = {}, {}
    for kind, ctx in contexts.items():
        with open_renderer(scene, size, method="radiosity", options=options, context=ctx) as gpu:
            gpu_frames[kind] = gpu.render(linear=True, depth=True)
            matrices[kind] = gpu.solution.form_factors
    with open_renderer(scene, size, method="radiosity", options=options, backend="reference",
                       precision="float64") as twin:
        truth = twin.render(linear=True)
        solved = twin.solution
    finite = {kind: is_finite_frame(frame) for kind, frame in gpu_frames.items()}
    finite["reference"] = is_finite_frame(truth) and bool(np.isfinite(solved.solution.radiosity).all())
    per_context = {kind: compare_frames(frame.rgba8, truth.rgba8, frame.depth, truth.depth,
                                        reference_tie=truth.rgba8_tie).as_dict()
                   for kind, frame in gpu_frames.items()}
    against_truth = {kind: compare_frames(frame.rgba8, truth.rgba8).as_dict()
                     for kind, frame in gpu_frames.items()}
    same = all(all(np.array_equal(getattr(m, name), getattr(solved.form_factors, name))
                   for name in ("indptr", "columns", "values")) for m in matrices.values())
    e = solved.elements
    whole = residual(solved.form_factors, e.reflectance, solved.source, solved.solution.radiosity)
    return {"finite": finite, "tie_pixels": depth_tie_pixels(truth),
            "contexts": per_context, "worst": _worst(per_context),
            "truth": against_truth, "worst_truth": _worst(against_truth),
            "elements": len(e), "same_form_factors": same, "iterations": solved.solution.iterations,
            "converged": solved.solution.converged, "residual": whole,
            "relative_residual": whole / max(float(np.abs(solved.source).max()), np.finfo(float).tiny),
            "passes": (all(finite.values()) and solved.solution.converged
                       and all(TOLERANCE.passes(c) for c in per_context.values()))}


def _worst(comparisons: dict) -> dict:
    return max(comparisons.values(), key=lambda c: (c["mismatched_pixels"],
                                                    c["raw_mismatched_fraction"], c["rmse"]))


def measure_extremes(scenes: dict[str, Path], size: tuple[int, int], contexts: dict,
                     methods=("raster", "raytrace", "radiosity"), on_case=None) -> list[dict]:
    """One case per scene (two for a reversed-Z scene: as authored, and with it off; one per
    depth of RAYTRACE_DEPTHS for a ray-traced one), of the scenes whose method is in
    `methods`; `on_case(case)`, if given, as each is measured (a command's progress)."""
    cases = []
    for name, path in scenes.items():
        measured = len(cases)
        method = method_of(name)
        if method not in methods:
            continue
        base = {"case": name, "file": str(path), "method": method,
                "stability": STABILITY.get(name, "")}
        try:
            scene = load_scene(path)
        except SceneError as error:
            cases.append(base | {"refused": error.line(), "passes": True})
        else:
            cases += CASES[method](name, scene, base | {"tests": scene_description(path)}, size, contexts)
        for case in cases[measured:] if on_case is not None else ():
            on_case(case)
    return cases


def case_state(case: dict) -> str:
    """A case's outcome in a word or two: "pass", "FAIL", "refused" (a scene refused as it
    should be), or for a documented before-image (reversed-Z off) "before-image", which is not
    held to the rule."""
    if case.get("before"):
        return "before-image"
    if "refused" in case:
        return "refused"
    return "pass" if case["passes"] else "FAIL"


def summary(cases: list[dict]) -> str:
    """"41 cases: 36 pass, 1 refused as it should be, 4 documented before-images (not held to
    the rule), 0 FAIL"."""
    states = [case_state(case) for case in cases]
    return (f"{len(cases)} cases: {states.count('pass')} pass, {states.count('refused')} refused as "
            f"it should be, {states.count('before-image')} documented before-images (reversed_z "
            f"off: not held to the rule), {states.count('FAIL')} FAIL")


def _ray_cases(name: str, scene, base: dict, size, contexts) -> list[dict]:
    """One case per depth of RAYTRACE_DEPTHS, at the scene's RAYTRACE_SAMPLING."""
    depths = RAYTRACE_DEPTHS.get(name, (DEFAULT_MAX_DEPTH,))
    samples, pattern = RAYTRACE_SAMPLING.get(name, (1, "regular"))
    return [base | {"case": name if len(depths) == 1 else f"{name} (max depth {depth})",
                    "max_depth": depth, "samples": samples, "pattern": pattern}
            | measure_ray_traced(scene, size, contexts, depth, samples, pattern) for depth in depths]


def _raster_cases(name: str, scene, base: dict, size, contexts) -> list[dict]:
    """The case as authored and, for a reversed-Z scene, the same with it off (its 'before')."""
    cases = [base | {"reversed_z": scene.camera.reversed_z} | measure_scene(scene, size, contexts)]
    if scene.camera.reversed_z:
        standard = replace(scene, camera=replace(scene.camera, reversed_z=False))
        cases.append(base | {"case": f"{name} (reversed_z off)", "reversed_z": False,
                             "stability": "none: the 'before' of the row above", "before": True}
                     | measure_scene(standard, size, contexts))
    return cases


def _radiosity_cases(name: str, scene, base: dict, size, contexts) -> list[dict]:
    """One case, with the scene's RADIOSITY_OPTIONS or the defaults."""
    options = RADIOSITY_OPTIONS.get(name, RadiosityOptions())
    return [base | {"options": options.as_dict()} | measure_radiosity(scene, size, contexts, options)]


# Each method's cases, by the name renderer/methods registers it under.
CASES = {"raster": _raster_cases, "raytrace": _ray_cases, "radiosity": _radiosity_cases}


# -------------------------------------------------------------------------- the report

def _json_safe(value):
    """Non-finite floats as strings ("inf", "nan"), so that extremes.json is strict JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    return value


def _yes_no(flag: bool) -> str:
    return "yes" if flag else "**NO**"


def markdown_table(cases: list[dict], size: tuple[int, int]) -> str:
    lines = [f"# Extreme cases ({size[0]}x{size[1]})", "",
             "GPU against the float64 reference (the ground truth here: the same pipeline in "
             "float64 at the same size; for `raytrace` cases the ray tracer, 1 sample per "
             f"pixel but where the case needs more: {_sampled(cases)}). Mismatched: pixels "
             "failing the threshold-2 compare with ±1 px allowed, both ways; raw: fraction off by more than 2 in place; both "
             "accept either surface at the reference's depth ties (tie px: pixels where two "
             "surfaces are closer than GL's float32 depth can order, that is z-fighting) and, "
             "ray traced, either precision's result where the float32 and float64 references "
             "disagree on a grazing ray (grazing px). "
             "Against truth: rmse / max_abs on the 0-255 scale against the reference image "
             "alone, ties not forgiven. Depth: largest relative error of the camera-space "
             "depth. Figures are the worst of the GPU contexts. Pass: the pipeline tolerance "
             f"({TOLERANCE.max_mismatched_pixels} mismatched, raw <= {TOLERANCE.raw_mismatch_limit}, "
             f"depth <= {TOLERANCE.depth_rel_limit:g}).", "",
             "| case | method | what it tests | finite (" + " / ".join(_backends(cases)) + ") "
             "| mismatched px | raw mismatch | tie / grazing px | against truth: rmse / max_abs "
             "| depth max rel | pass | what makes it stable |",
             "| --- | --- | --- | --- | ---: | ---: | ---: | --- | ---: | --- | --- |"]
    for case in cases:
        if "refused" in case:
            lines.append(f"| {case['case']} | {case['method']} | refused: `{case['refused']}` | - "
                         f"| - | - | - | - | - | yes (refused) | {case['stability']} |")
            continue
        worst, truth = case["worst"], case["worst_truth"]
        finite = " / ".join(_yes_no(v) for v in case["finite"].values())
        verdict = _yes_no(case["passes"]) if not case.get("before") else \
            ("yes" if case["passes"] else "no (expected)")
        ties = case["grazing_pixels"] if case["method"] == "raytrace" else case["tie_pixels"]
        lines.append(
            f"| {case['case']} | {case['method']} | {case['tests']} | {finite} "
            f"| {worst['mismatched_pixels']} | {worst['raw_mismatched_fraction']:.4f} | {ties} "
            f"| {truth['rmse']:.3f} / {truth['max_abs']} "
            f"| {worst['depth_max_rel']:.2e} | {verdict} | {case['stability']} |")
    return "\n".join(lines) + "\n"


def _sampled(cases: list[dict]) -> str:
    """'rt_huge_aperture 4 jittered' for each case measured with more than one sample."""
    return ", ".join(f"{case['case']} {case['samples']} {case['pattern']}" for case in cases
                     if case.get("samples", 1) > 1) or "none here"


def _backends(cases: list[dict]) -> list[str]:
    for case in cases:
        if "finite" in case:
            return list(case["finite"])
    return ["reference"]


def write_report(out: Path, cases: list[dict], size: tuple[int, int],
                 sweep: list[dict] | None = None) -> tuple[Path, Path]:
    """extremes.json (every figure of every case, and of the light-elevation sweep when
    measured: renderer/study/shadow_sweep.py) and extremes.md (the tables): both or neither
    (imageio.outputs)."""
    json_path, md_path = Path(out) / "extremes.json", Path(out) / "extremes.md"
    document = {"size": list(size), "cases": cases}
    table = markdown_table(cases, size)
    if sweep is not None:
        document["light_elevation_sweep"] = sweep
        table += "\n" + markdown_section(sweep, size)
    with outputs(json_path, md_path) as written:
        written.text(json_path, json_text(_json_safe(document)))
        written.text(md_path, table)
    return json_path, md_path


def all_pass(cases: list[dict], sweep: list[dict] = ()) -> bool:
    """Every case as authored passes (the reversed_z-off rows are the 'before' and may not),
    and the sweep shows no acne on any backend (where the truth was measured)."""
    return (all(case["passes"] for case in cases if not case.get("before"))
            and not any(sweep_acne(row) for row in sweep))
