"""The GPU ray tracer (glsl/raytrace/raytrace.frag and trace.glsl; twin: reference/raytrace/
pipeline.py): one full-screen pass that traces every sample of every pixel (the samples looped
in the shader, placed by glsl/raytrace/sampling.glsl), into a float colour target (average
linear colour, coverage), a float depth target (the view depth of the nearest first hit) and,
for the adaptive pattern, a float target of the samples traced per pixel, read back row 0 at
the top; rgba8 is gl_rules.to_unorm8 of the clamped linear colour, alpha 255 where a camera ray
hit. `render(first_sample=F)` traces sample indices F .. F + N - 1 (a uniform, no recompile).

GL resources are made once in the constructor: the program, specialised by #defines for what
the scene uses (light counts, SPECULAR, SHADOWS when there are lights, NUM_SPHERES, NUM_PLANES,
MESHES when there are triangles, SECONDARY when some k_r or k_t > 0, GLOSSY when such a material
has a finite gloss, MAX_DEPTH, LENS when the camera's aperture is above 0, AREA_LIGHTS when some
point light has an area of size > 0, MOTION and NUM_MOVING_MESHES where something moves during
the shutter (docs/conventions.md, "Motion blur"), TEXTURES and NUM_TEXTURES where some material
is textured (renderer/core/ray_textures.py), and the sample pattern's constants from
renderer/core/ray_sampling.py, LIGHT_SAMPLES among them); the uniforms (camera rays and the thin
lens from renderer/core/camera_rays.py, lights from renderer/core/uniforms.py and their areas
from renderer/core/light_areas.py, shapes, the objects' motions from renderer/core/motion.py,
the pattern's); the
materials, the BVH (nodes and triangles, `texels` of renderer/core/bvh.py's layout, as
renderer/gpu/bvh.py) and the triangles' vertices and normals as float textures; the image
textures through renderer/gpu/textures.py's TextureCache (each uploaded once, one unit per
slot, after the float textures' units). A viewer moving
the camera calls update() (and resize()), which keeps all of them and writes new contents: the
same image as a RayTracer made afresh, without the BVH build or (unless the light counts
changed) the compile. reseed(seed) likewise changes the sampling seed (a batch's items).

`specialise=False` (benchmarks/bench_raytrace.py measures what specialising saves) compiles
every feature in whatever the scene uses: SPECULAR, SHADOWS (where there are lights and
`shadows`), SECONDARY and GLOSSY (where max_depth > 0), LENS (a lens of radius 0 without an
aperture), MOTION (each moving mesh in its own tree wherever an object declares a motion),
MESHES (the BVH walk; a scene without static triangles gets a one-triangle tree of a degenerate
triangle at root 0, which no ray hits) and AREA_LIGHTS (where there are point lights;
renderer/core/light_areas.py). The light, sphere and plane counts stay compile-time
constants, and TEXTURES stays where some material is textured (an array of samplers with
no texture to read is no feature). The image is the same.
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from renderer.core.bvh import build_bvh, forest, roots, texels, walk_layout
from renderer.core.camera_rays import camera_ray_uniforms, lens_uniforms
from renderer.core.frame import Frame, image_size
from renderer.core.motion import declares_motion, moves, scene_motion
from renderer.core.gl_rules import check_light_count, to_unorm8
from renderer.core.light_areas import area_light_uniforms
from renderer.core.ray_options import RayOptions
from renderer.core.ray_sampling import check_first_sample
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene import Scene
from renderer.core.transforms import to_glsl
from renderer.core.uniforms import light_uniforms
from renderer.gpu.bvh import texel_texture
from renderer.gpu.base import ContextRenderer
from renderer.gpu.readback import flip_into
from renderer.gpu.context import activate
from renderer.gpu.declarations import program_uniforms, uniforms_to_write
from renderer.gpu.defines import area_light_defines, sampling_defines
from renderer.gpu.shaders import shader_source
from renderer.gpu.textures import TextureCache

# Samples a band of rows holds (render()): a few tenths of a second of llvmpipe's tracing,
# short enough for Ctrl-C and a progress bar, long enough that the bands cost nothing.
BAND_SAMPLES = 1 << 21


class RayTracer(ContextRenderer):
    """Ray traces one scene at one size; see the module docstring. `options` (RayOptions,
    renderer/core/ray_options.py), or its fields as keywords; the lens overrides are the
    caller's to apply (RayOptions.scene_for: renderer/methods does)."""

    def __init__(self, scene: Scene, width: int, height: int, options: RayOptions | None = None, *,
                 context: moderngl.Context | None = None, context_kind: str = "auto", **fields):
        if options is not None and fields:
            raise TypeError(f"give RayOptions or its fields, not both ({', '.join(fields)})")
        options = RayOptions(**fields) if options is None else options
        width, height = image_size(width, height)
        check_light_count(scene)
        self.scene = scene
        self.width, self.height = width, height
        self.options = options
        self.sampling = options.sampling
        self.max_depth = options.max_depth
        self.shadows = options.shadows
        self.specialise = options.specialise
        self._open_context(context, context_kind)
        self._resources: list = []
        self._image_textures = TextureCache(self.ctx)     # the materials' images, uploaded once
        try:
            activate(self.ctx)
            self._build()
        except BaseException:
            self.release()
            raise

    def _build(self) -> None:
        ctx = self.ctx
        self._motion_layout = self._motion_now()
        rs = self.ray_scene = ray_scene(self.scene, motion=self._motion_layout)
        self._surfaces = self._surfaces_now()
        self.defines = self._defines(rs)
        self._compile()
        self._textures, self._units = [], {}          # (unit, texture); sampler -> unit
        for unit, (name, array) in enumerate(self._texture_arrays(rs).items()):
            texture = texel_texture(ctx, array)
            self._resources.append(texture)
            self._textures.append((unit, texture))
            self._units[name] = unit
        self._write_uniforms(rs)
        self._build_targets()
        self._gl_info = self._context_info()

    def _defines(self, rs) -> dict:
        scene, every = self.scene, not self.specialise
        return {
            "NUM_DIRECTIONAL_LIGHTS": len(scene.directional_lights),
            "NUM_POINT_LIGHTS": len(scene.point_lights),
            "SPECULAR": rs.specular or every,
            "SHADOWS": self.shadows and bool(scene.directional_lights or scene.point_lights),
            "MATERIAL_VARIABLES": True,
            "NUM_SPHERES": len(rs.sphere_radius),
            "NUM_PLANES": len(rs.plane_offset),
            "MESHES": rs.bvh is not None or every,
            "SECONDARY": (rs.secondary or every) and self.max_depth > 0,
            "GLOSSY": (rs.glossy or every) and self.max_depth > 0,
            "MAX_DEPTH": self.max_depth,
            "LENS": scene.camera.has_lens or every,
            "RADIANCE_SCALING": rs.radiance_scaling,
            **sampling_defines(self.sampling),
            **area_light_defines(scene, every),
            **self._motion_defines(rs),
            **({"TEXTURES": True, "NUM_TEXTURES": len(rs.textures.textures)} if rs.textures else {}),
        }

    def _compile(self) -> None:
        """The program for self.defines and its vertex array (those of before released)."""
        for name in ("_vao", "program"):
            old = getattr(self, name, None)
            if old is not None:
                self._resources.remove(old)
                old.release()
        fragment = shader_source("raytrace/raytrace.frag", self.defines)
        self.program = self.ctx.program(
            vertex_shader=shader_source("raytrace/fullscreen.vert").text,   # no uniforms
            fragment_shader=fragment.text)
        self._fragment_text = fragment.text
        self._resources.append(self.program)
        self._vao = self.ctx.vertex_array(self.program, [])
        self._resources.append(self._vao)

    def _write_uniforms(self, rs) -> None:
        """Camera rays, lights, shapes and the sample pattern; the textures' units. Written are
        the ones the program's #defines declare (uniforms_to_write: one the scene's
        specialisation leaves out is not, and a name the GLSL declares nowhere, or a uniform it
        declares that gets no value, is an error); self._uniforms_written names them."""
        scene = self.scene
        matrices = scene.matrices(self.width, self.height)
        rays = camera_ray_uniforms(matrices.view, matrices.projection, self.width, self.height)
        values = {name: to_glsl(value) for name, value in rays.items()}
        values.update(self._lens_values(matrices))
        for name, value in (light_uniforms(scene, matrices.origin) | area_light_uniforms(scene)).items():
            if value.size:
                values[name] = np.asarray(value, np.float32).tobytes()
        values["u_background"] = np.asarray(scene.background, np.float32).tobytes()
        values["u_near"] = np.float32(scene.camera.near).tobytes()
        values["u_far"] = np.float32(scene.camera.far).tobytes()
        values.update({name: value.tobytes() for name, value in self.sampling.uniforms().items()})
        if len(rs.sphere_radius):
            values["u_spheres"] = np.concatenate([rs.sphere_centre, rs.sphere_radius[:, None]], 1).astype(np.float32).tobytes()
            values["u_sphere_object"] = rs.sphere_object.astype(np.int32).tobytes()
        if len(rs.plane_offset):
            values["u_planes"] = np.concatenate([rs.plane_normal, rs.plane_offset[:, None]], 1).astype(np.float32).tobytes()
            values["u_plane_object"] = rs.plane_object.astype(np.int32).tobytes()
        values.update(self._motion_uniforms(rs))
        values.update(self._texture_uniforms(rs))
        values.update({name: np.int32(unit).tobytes() for name, unit in self._units.items()})
        if rs.textures is not None:
            units = [unit for unit, _ in self._image_units()]
            values["u_textures"] = np.asarray(units, np.int32).tobytes()
        values["u_first_sample"] = np.uint32(0).tobytes()      # render() writes each frame's
        values.update(self._more_uniforms(rs))
        self._uniforms_written = uniforms_to_write(self._fragment_text,
                                                   program_uniforms(self.program), values)
        for name in self._uniforms_written:
            self.program[name].write(values[name])

    def _more_uniforms(self, rs) -> dict:
        """A subclass's own uniforms as bytes (the path tracer's emitters); none here."""
        return {}

    def _lens_values(self, matrices) -> dict:
        """The thin lens's uniforms (renderer/core/camera_rays.py, lens_uniforms) as float32
        bytes; a camera without an aperture has a lens of radius 0 (the specialise=False
        build runs it: the pinhole exactly)."""
        cam = self.scene.camera
        lens = lens_uniforms(matrices.view, cam.aperture or 0.0, cam.focus)
        return {name: np.asarray(value, np.float32).tobytes() for name, value in lens.items()}

    def _texture_arrays(self, rs) -> dict:
        """The float textures' contents by sampler name (`texels` lays them out)."""
        exact = rs.fresnel_exact[:, None].astype(np.float64)
        materials = np.stack([np.concatenate(part, 1) for part in (
            (rs.ka, rs.n[:, None]), (rs.kd, rs.two_sided[:, None].astype(np.float64)),
            (rs.ks, rs.ior[:, None]), (rs.kr, rs.gloss[:, None]), (rs.kt, exact))], 1)  # (M, 5, 4)
        arrays = {"u_materials": materials}
        if self.defines["MESHES"]:
            triangles, normals, owner = rs.triangles, rs.triangle_normals, rs.triangle_object
            bvh = self._bvh(rs)
            if rs.bvh is None:                        # all features, no triangles: a placeholder
                triangles, normals, owner = np.zeros((1, 3, 3)), np.zeros((1, 3, 3)), np.zeros(1)
            walk = walk_layout(bvh)
            arrays["u_nodes"], arrays["u_triangles"] = walk.entries, walk.triangles
            data = np.zeros((len(triangles), 6, 4), np.float32)     # the texture's type: no copy
            data[:, :3, :3] = triangles
            data[:, 3:, :3] = normals
            data[:, 3, 3] = owner
            arrays["u_triangle_data"] = data
        if rs.textures is not None:
            arrays.update(self._texture_texels(rs))
        return arrays

    # -- textures (docs/conventions.md, "Textures in the ray tracer") -------------------------
    def _texture_texels(self, rs) -> dict:
        """Per object its slot, modulate flags and UV transform; per triangle its vertex UVs
        (a placeholder triangle's where MESHES walks a placeholder tree)."""
        tx = rs.textures
        flags = np.concatenate([tx.slot[:, None], tx.modulate], 1).astype(np.float64)
        arrays = {"u_texture_materials": np.stack([flags, tx.uv_transform], 1)}     # (M, 2, 4)
        if self.defines["MESHES"]:
            uvs = tx.triangle_uvs if len(tx.triangle_uvs) else np.zeros((1, 3, 2))
            data = np.zeros((len(uvs), 2, 4))
            data[:, 0] = uvs[:, :2].reshape(-1, 4)
            data[:, 1, :2] = uvs[:, 2]
            arrays["u_triangle_uvs"] = data
        return arrays

    def _image_units(self) -> list[tuple[int, object]]:
        """(unit, MaterialTexture) of each slot: the units after the float textures'."""
        if self.ray_scene.textures is None:
            return []
        return [(len(self._units) + k, material_texture)
                for k, material_texture in enumerate(self.ray_scene.textures.textures)]

    def _texture_uniforms(self, rs) -> dict:
        """Each sphere's world-to-object rotation (rows) and each plane's UV map (rows)."""
        if rs.textures is None:
            return {}
        rows = {"u_sphere_rotation": rs.textures.sphere_rotation, "u_plane_uv": rs.textures.plane_map}
        return {name: np.asarray(value, np.float32).tobytes() for name, value in rows.items()
                if np.size(value)}

    # -- motion blur (docs/conventions.md, "Motion blur") ------------------------------------
    def _motion_now(self) -> bool:
        """Whether the ray scene takes motion blur's data and trees (ray_scene's `motion`): where
        something moves in the image, or, compiling every feature, wherever an object declares
        a motion (as the twin)."""
        return moves(self.scene) or (not self.specialise and declares_motion(self.scene))

    def _motion_defines(self, rs) -> dict:
        """MOTION where something moves (every feature: always) and NUM_MOVING_MESHES, the
        moving mesh objects with their own trees."""
        if not (moves(self.scene) or not self.specialise):
            return {}
        return {"MOTION": True, "NUM_MOVING_MESHES": int((rs.mesh_object >= 0).sum())}

    def _bvh(self, rs):
        """The BVH the GPU walks: the scene's, with a placeholder tree at root 0 where MESHES
        walks one and the scene has no static triangles (no triangles at all, or only moving
        meshes): one degenerate triangle, which no ray hits."""
        if rs.bvh is not None and rs.static_tree:
            return rs.bvh
        placeholder = build_bvh(np.zeros((1, 3, 3)))
        return placeholder if rs.bvh is None else forest([placeholder, rs.bvh])

    def _motion_uniforms(self, rs) -> dict:
        """The shutter and every sphere's, plane's and moving mesh's motion rows (renderer/
        core/motion.py), the moving meshes' trees in u_nodes (walk_layout's) and their objects."""
        if "MOTION" not in self.defines:
            return {}
        motion = rs.motion if rs.motion is not None else scene_motion(self.scene)
        moving = rs.mesh_object[rs.mesh_object >= 0]
        rows = {"u_shutter": motion.shutter, "u_sphere_motion": motion.rows(rs.sphere_object),
                "u_plane_motion": motion.rows(rs.plane_object), "u_mesh_motion": motion.rows(moving)}
        values = {name: np.asarray(value, np.float32).tobytes() for name, value in rows.items()
                  if np.size(value)}
        if len(moving):                   # the moving meshes' trees are the last ones
            trees = len(roots(self._bvh(rs)))
            values["u_mesh_root"] = np.arange(trees - len(moving), trees, dtype=np.int32).tobytes()
            values["u_mesh_object"] = moving.astype(np.int32).tobytes()
        return values

    def _build_targets(self) -> None:
        """The framebuffer at the image size and its float targets (self._targets)."""
        ctx = self.ctx
        self._colour = ctx.texture((self.width, self.height), 4, dtype="f4")
        self._depth = ctx.texture((self.width, self.height), 1, dtype="f4")
        self._targets = [self._colour, self._depth]
        if self.sampling.adaptive:                    # the samples traced per pixel
            self._targets.append(ctx.texture((self.width, self.height), 1, dtype="f4"))
        self._fbo = ctx.framebuffer(self._targets)
        self._resources += [*self._targets, self._fbo]

    # -- a viewer's changes ------------------------------------------------------------------
    def update(self, scene: Scene | None = None) -> None:
        """Take the scene again after its camera, lights or materials changed in place (a
        viewer's orbit and keys), or `scene`, a Scene of the same objects (its objects, meshes
        and shapes must be the ones this tracer was made with): the image is then, bit for
        bit, that of a RayTracer made afresh for the scene. Cheaper: the BVH's tree is kept and only refitted to the triangles relative
        to the new eye (renderer/core/raytrace_scene.py), the textures are written again in
        place, and the program is compiled again only when its #defines changed (a light
        switched on or off)."""
        self._check_alive()
        previous = self.scene
        self.scene = self.scene if scene is None else scene
        try:
            self._take_scene()
        except BaseException:
            self.scene = previous
            raise

    def _take_scene(self) -> None:
        now = self._surfaces_now()
        if len(now) != len(self._surfaces) or any(
                a is not b for old, new in zip(self._surfaces, now) for a, b in zip(old, new)):
            raise ValueError("the scene's objects changed since this RayTracer was made; "
                             "make a new one")
        if self._motion_now() != self._motion_layout:
            raise ValueError("the scene's motion blur switched on or off since this RayTracer "
                             "was made; make a new one")
        check_light_count(self.scene)
        activate(self.ctx)
        rs = ray_scene(self.scene, tree=self.ray_scene.bvh, motion=self._motion_layout)
        if (rs.textures is None) != (self.ray_scene.textures is None):
            raise ValueError("the scene's textures switched on or off since this RayTracer was "
                             "made; make a new one")
        self.ray_scene = rs
        defines = self._defines(rs)
        if defines != self.defines:
            self.defines = defines
            self._compile()
        for (_, texture), array in zip(self._textures, self._texture_arrays(rs).values()):
            texture.write(texels(array).tobytes())
        self._write_uniforms(rs)

    def reseed(self, seed: int) -> None:
        """Trace with another sampling seed from now on: the frames are then, bit for bit,
        those of a RayTracer made with `seed` (a batch's items). The seed and the table
        patterns' offsets drawn from it are uniforms, so nothing is compiled or rebuilt.
        ValueError (one line) for a seed that is not a uint32."""
        self._check_alive()
        self.options = self.options.replace(seed=seed)
        self.sampling = self.options.sampling
        activate(self.ctx)
        for name, value in self.sampling.uniforms().items():
            if name in self._uniforms_written:
                self.program[name].write(value.tobytes())

    def _surfaces_now(self) -> list[tuple]:
        """What update() must find unchanged: each object, its mesh and its shape (identity)."""
        return [(obj, obj.mesh, obj.shape) for obj in self.scene.objects]

    def resize(self, width: int, height: int) -> None:
        """Trace at another size from now on (a viewer's window was resized): the targets are
        made again and update() recomputes the camera rays."""
        width, height = image_size(width, height)
        if (width, height) == (self.width, self.height):
            return
        activate(self.ctx)
        for thing in (self._fbo, *self._targets):
            self._resources.remove(thing)
            thing.release()
        self.width, self.height = width, height
        self._build_targets()
        self.update()

    def render(self, out: Frame | None = None, *, linear: bool = True, depth: bool = True,
               first_sample: int = 0, progress=None) -> Frame:
        """Trace the frame of sample indices first_sample .. first_sample + N - 1: rgba8,
        linear (average linear colour, alpha the coverage), depth and samples (traced per
        pixel), row 0 at the top. `linear` and `depth` are always traced (the Renderer
        protocol's flags change nothing); `out`, an earlier frame, has its arrays written.

        A frame of more than BAND_SAMPLES samples is traced in bands of rows (the scissor
        box; every pixel is traced on its own, so the image is the same), each finished
        before the next starts: Ctrl-C stops it after the band in flight, and
        `progress(rows done, rows)` is called after each band."""
        self._check_alive()
        start = time.perf_counter()
        images = self._begin_frame(first_sample)
        self._trace_bands(progress)
        self._end_frame(images)
        h, w = self.height, self.width
        reuse = (None, None) if out is None else (out.linear, out.depth)
        colour = _flip_read(self._fbo, 0, (h, w, 4), reuse[0])
        view_depth = _flip_read(self._fbo, 1, (h, w), reuse[1])
        if self.sampling.adaptive:
            traced = np.frombuffer(self._fbo.read(components=1, attachment=2, dtype="f4"), np.float32)
            samples = np.ascontiguousarray(traced.reshape(h, w)[::-1]).astype(np.int32)
        else:
            samples = np.full((h, w), self.sampling.samples, np.int32)
        rgba8 = to_unorm8(colour)
        rgba8[..., 3] = np.where(colour[..., 3] > 0, np.uint8(255), np.uint8(0))
        return Frame(rgba8, colour, view_depth, (time.perf_counter() - start) * 1000.0,
                     gl_info=self.gl_info, samples=samples)

    def _begin_frame(self, first_sample: int) -> list:
        """The frame's first sample index written, the textures bound, the framebuffer used:
        ready to draw. Returns the image units bound (_end_frame's)."""
        first_sample = check_first_sample(first_sample, self.sampling.samples)
        activate(self.ctx)
        if "u_first_sample" in self._uniforms_written:
            self.program["u_first_sample"].value = first_sample
        for unit, texture in self._textures:
            texture.use(unit)
        images = self._image_units()
        for unit, material_texture in images:
            self._image_textures.bind(material_texture, unit)
        self._fbo.use()
        self.ctx.viewport = (0, 0, self.width, self.height)
        return images

    def _end_frame(self, images) -> None:
        """No sampler state of ours left on the context."""
        for unit, material_texture in images:
            self._image_textures.get(material_texture)[1].clear(unit)

    def bands(self) -> list[tuple[int, int]]:
        """(first row from the bottom, rows) of each band render() traces: whole rows, about
        BAND_SAMPLES samples (camera samples times light samples) each."""
        per_row = self.width * self.sampling.samples * self.sampling.light_samples
        rows = max(1, BAND_SAMPLES // per_row)
        return [(y, min(rows, self.height - y)) for y in range(0, self.height, rows)]

    def _trace_bands(self, progress, share=(0.0, 1.0)) -> None:
        """Draw the pass band by band; `progress` told the rows done, scaled into the `share`
        of the frame this pass is (the path tracer's passes, one a sample)."""
        def told(rows):
            if progress is not None:
                progress(round(self.height * (share[0] + (share[1] - share[0]) * rows / self.height)),
                         self.height)
        bands = self.bands()
        if len(bands) == 1:                      # the frame at once, as small frames always were
            self._vao.render(vertices=3)
            told(self.height)
            return
        try:
            for y, rows in bands:
                self.ctx.scissor = (0, y, self.width, rows)
                self._vao.render(vertices=3)
                self.ctx.finish()                # done before Python runs on (and Ctrl-C is seen)
                told(y + rows)
        finally:
            self.ctx.scissor = None

    def _free(self) -> None:
        try:
            self._image_textures.release()
            for thing in reversed(self._resources):
                thing.release()
        finally:
            self._resources = []


def _flip_read(fbo, attachment: int, shape: tuple, out: np.ndarray | None) -> np.ndarray:
    """A float attachment read back, row 0 at the top, into `out` when it fits (a reused frame)."""
    rows = np.frombuffer(fbo.read(components=shape[2] if len(shape) == 3 else 1,
                                  attachment=attachment, dtype="f4"), np.float32).reshape(shape)
    return flip_into(rows, out)
