"""The GPU path: the scene drawn with the GLSL programs of glsl/ into an off-screen framebuffer.

    with GpuRenderer(scene, 640, 480) as gpu:        # EGL, else OSMesa
        frame = gpu.render()                         # Frame: rgba8, depth (and linear if asked)
        fbo = gpu.draw()                             # the same drawing, nothing read back
        gpu.resize(800, 600)                         # another size, same programs and meshes

`render()` is `draw()` plus the read-back; the window viewer (renderer/viewer/viewer.py) calls
`draw()` on a window's context (`context=`) and copies the framebuffer to the screen, so that
it shows exactly what the headless path renders. `wireframe = True` draws triangle edges only
(the viewer's W key); `shadows = False` draws no light views and uses the programs without
shadow code, the image of the scene with every light's shadows off, until `shadows = True`
(the viewer's O key; each program is compiled once, so toggling compiles nothing after the
first time either way).

Everything GL is made once per renderer: one program per shader variant the scene's materials
use, one vertex buffer (positions and normals, float32, interleaved), index buffer and vertex
array per object (and for an object with a textured material, a buffer of its vertices' UVs,
float32, the program's in_uv: no other object has one), for an analytic plane a second such
set for the polygon its camera pass draws (renderer/core/drawn.py: made once at their largest,
MAX_POLYGON_VERTICES and MAX_POLYGON_TRIANGLES, written by each update(); the shadow passes
draw the object's mesh), each texture the materials use, with
its sampler object (renderer/gpu/textures.py, TextureCache: one upload per texture however
many materials share it), and a single-sample framebuffer with an RGBA8 colour buffer and a 32-bit
float depth buffer (DEPTH_COMPONENT32F, so the stored depth is the rasteriser's float z_w with
no 24-bit rounding; moderngl only makes 24-bit depth, so the storage is re-specified through
glRenderbufferStorage). An RGBA32F buffer for the unclamped linear colour, and the program
variants that write it, are made the first time `render(linear=True)` asks for them; so are
the multisample targets of `render(samples=N)` (RGBA8 colour and DEPTH_COMPONENT32F depth
through glRenderbufferStorageMultisample, one pair per sample count, resolved into the
single-sample framebuffer by a blit).

Each frame is planned from its scene: a program per material is specialised to what that
material and the scene use (renderer/gpu/shaders.py: light counts as constants, the specular term
only where k_s > 0, back-face code only when two-sided), and an object wholly outside the
view volume is left out of the plan (renderer/core/visibility.py). `specialise=False` draws with
the all-features build instead, for benchmarks/bench_specialisation.py; the images are the same.

Shadows (docs/conventions.md, "Shadows"): when the scene's shadow layout has maps
(renderer/core/shadows.py: something casts, something receives, a light has shadows on), a
ShadowMaps (renderer/gpu/shadow_maps.py) holds the maps (layers of one depth array texture)
and draws each frame's light views into them before the camera pass; the programs of objects
that receive shadows (in every shading mode) are compiled with SHADOW_MAPS and read the maps on
texture unit 0. The layout is recomputed by update() (the texture is made again only when it
changes size: an automatic map resolution follows the image size), the plan (light views,
casters, lookup uniforms) every update().

The depth mapping (clip control, clear value, compare function) is the camera's, from
renderer/core/gl_rules.py: reversed-Z draws with glClipControl ZERO_TO_ONE, depth cleared to
0 and GL_GREATER; every frame sets the clip control either way and a reversed-Z
frame puts GL's default back, so renderers sharing a context never see each other's.

Textures: a textured material's program (ShaderVariant.texture) samples its texture on
MATERIAL_TEXTURE_UNIT (renderer/gpu/uniforms.py); each draw binds its texture and sampler
object there, and the frame unbinds the sampler object after its last draw, so that a context
shared with other drawing (a viewer) is left with no sampler state of ours.

Uniform values are computed once per update(), as bytes (renderer/gpu/uniforms.py, from the
layout the reference reads too: renderer/core/uniforms.py), and each plane's polygon with
them, from `Scene.matrices()`
(camera-relative) and the scene's lights and materials, and `render()` only hands them to GL;
a pass at a sample offset (`render(sample_offset=(dx, dy))`, docs/conventions.md) uploads
u_projection alone again. After changing the scene (camera, lights, materials, transforms, or
an object's mesh for another Mesh), call `update()`; a different list of objects needs a new
renderer.
Conventions (matrices, window, depth, colour, lighting): docs/conventions.md.
"""

from __future__ import annotations

import ctypes
import time
from dataclasses import dataclass

import moderngl
import numpy as np

from renderer.gpu.base import ContextRenderer
from renderer.gpu.readback import flip_into, usable
from renderer.gpu.context import activate, gl_function
from renderer.errors import ContextError, SystemFault
from renderer.core.drawn import drawn_meshes, is_plane
from renderer.core.facets import face_texture
from renderer.core.frame import Frame, image_size
from renderer.core.gl_rules import GL_LOWER_LEFT, STANDARD_DEPTH, DepthMapping, depth_mapping, check_light_count
from renderer.core.scene import Mesh, Scene, SceneObject
from renderer.core.shadows import ShadowLayout, plan_shadows, shadow_layout
from renderer.core.tessellation import (DISPLACEMENT_SAMPLER, check_tessellated, displaced_patches, patch_mesh,
                                        patches_per_draw, pn_patches)
from renderer.gpu.shaders import ALL_FEATURES_LIGHTS, ProgramCache, ShaderVariant
from renderer.gpu.polygon_buffers import PolygonBuffers, vertex_bytes
from renderer.gpu.shadow_maps import ShadowMaps
from renderer.gpu.textures import TextureCache
from renderer.core.transforms import jitter, to_glsl
from renderer.gpu.uniforms import (DISPLACEMENT_TEXTURE_UNIT, FACE_NORMALS_UNIT, MATERIAL_TEXTURE_UNIT, frame_uniform_values,
                                   object_uniform_values)
from renderer.core.visibility import visible_objects

GL_DITHER = 0x0BD0
GL_RENDERBUFFER = 0x8D41
GL_RENDERBUFFER_INTERNAL_FORMAT = 0x8D44
GL_DEPTH_COMPONENT24 = 0x81A6
GL_DEPTH_COMPONENT32F = 0x8CAC
GL_RGBA8 = 0x8058
GL_SAMPLES = 0x80A9
GL_NUM_SAMPLE_COUNTS = 0x9380
DEPTH_FORMAT_NAMES = {GL_DEPTH_COMPONENT24: "DEPTH_COMPONENT24",
                      GL_DEPTH_COMPONENT32F: "DEPTH_COMPONENT32F"}

CULL_FLAGS = {"none": None, "back": "back", "front": "front"}   # SceneObject.cull -> GL face


# A tessellated sphere's patches a draw call holds (llvmpipe's uint16 element indices in a run).
PATCHES_PER_DRAW = patches_per_draw()


def make_float_depth(ctx: moderngl.Context, renderbuffer, width: int, height: int,
                     samples: int = 0) -> str:
    """Re-specify moderngl's 24-bit depth renderbuffer as DEPTH_COMPONENT32F where GL lets
    us (multisampled when `samples` > 0); returns the format in use."""
    c_uint, c_int = ctypes.c_uint, ctypes.c_int
    bind = gl_function(ctx, "glBindRenderbuffer", None, c_uint, c_uint)
    if samples:
        multisample = gl_function(ctx, "glRenderbufferStorageMultisample", None,
                                  c_uint, c_int, c_uint, c_int, c_int)
        storage = None if multisample is None else (
            lambda target, fmt, w, h: multisample(target, samples, fmt, w, h))
    else:
        storage = gl_function(ctx, "glRenderbufferStorage", None, c_uint, c_uint, c_int, c_int)
    query = gl_function(ctx, "glGetRenderbufferParameteriv", None, c_uint, c_uint,
                        ctypes.POINTER(c_int))
    if bind is None or storage is None or query is None:
        return "DEPTH_COMPONENT24"
    value = c_int(0)
    bind(GL_RENDERBUFFER, renderbuffer.glo)
    storage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height)
    ctx.error                                               # clear any error it raised
    query(GL_RENDERBUFFER, GL_RENDERBUFFER_INTERNAL_FORMAT, ctypes.byref(value))
    bind(GL_RENDERBUFFER, 0)
    return DEPTH_FORMAT_NAMES.get(value.value, hex(value.value))


def multisample_counts(ctx: moderngl.Context) -> list[int]:
    """The MSAA sample counts GL offers for an RGBA8 colour buffer, ascending, 1 included
    (glGetInternalformativ GL_SAMPLES; llvmpipe offers only 4: a request for 2 gets 4)."""
    c_uint, c_int = ctypes.c_uint, ctypes.c_int
    query = gl_function(ctx, "glGetInternalformativ", None, c_uint, c_uint, c_uint, c_int,
                        ctypes.POINTER(c_int))
    if query is None:
        return [1]
    count = c_int(0)
    activate(ctx)
    query(GL_RENDERBUFFER, GL_RGBA8, GL_NUM_SAMPLE_COUNTS, 1, ctypes.byref(count))
    values = (c_int * max(count.value, 1))()
    query(GL_RENDERBUFFER, GL_RGBA8, GL_SAMPLES, len(values), values)
    limit = int(ctx.info["GL_MAX_SAMPLES"])
    return sorted({1, *(v for v in values[:count.value] if 1 < v <= limit)})


@dataclass
class _ObjectBuffers:
    """GL objects of one scene object: its mesh on the GPU and its vertex arrays per variant.
    The camera pass draws the mesh, or an analytic plane's polygon (`polygon`); the shadow
    passes draw the mesh (renderer/gpu/shadow_maps.py)."""
    obj: SceneObject
    mesh: Mesh                             # the mesh uploaded (update() re-uploads a new one)
    vbo: moderngl.Buffer | None            # in_position, in_normal: float32, interleaved
    ibo: moderngl.Buffer | None            # faces, uint32
    uv_vbo: moderngl.Buffer | None         # in_uv, float32 (a textured material's object only)
    vertex_arrays: dict                    # ShaderVariant -> moderngl.VertexArray
    uniform_bytes: dict                    # uniform name -> bytes (object's model and material)
    texture: tuple | None = None           # (moderngl.Texture, moderngl.Sampler) of its material
    face_normals: moderngl.Texture | None = None   # its faces (facets.face_texture), once a shadowed program draws it
    polygon: PolygonBuffers | None = None  # an analytic plane's, which the camera pass draws
    patches: tuple | None = None           # a tessellated object's (vbo, ibo, patches), which the camera pass draws

    @property
    def drawn_buffers(self) -> tuple:
        """(vbo, ibo, uv_vbo) the camera pass draws from."""
        if self.polygon is not None:
            return self.polygon.vbo, self.polygon.ibo, self.polygon.uv_vbo
        if self.patches is not None:
            return self.patches[0], self.patches[1], None
        return self.vbo, self.ibo, self.uv_vbo

    @property
    def count(self) -> int:
        """Indices the camera pass draws: -1 for all of the mesh's, a polygon's own count."""
        return -1 if self.polygon is None else self.polygon.count


@dataclass
class _Draw:
    """One draw call of a frame, with everything resolved ahead of time."""
    vertex_array: moderngl.VertexArray
    enable: int                            # moderngl flags for enable_only
    cull_face: str | None
    uploads: list                          # [(moderngl Uniform, bytes)]
    texture: tuple | None = None           # (texture, sampler) bound on MATERIAL_TEXTURE_UNIT
    face_normals: moderngl.Texture | None = None   # bound on FACE_NORMALS_UNIT (a shadowed program's)
    count: int = -1                        # indices drawn (-1: all)
    patches: int = 0                       # a tessellated object's triangle patches (0: triangles)
    heights: tuple | None = None           # (texture, sampler) of a displaced object's height image


class GpuRenderer(ContextRenderer):
    """Renders one scene at one size through GLSL; see the module docstring."""

    def __init__(self, scene: Scene, width: int, height: int,
                 context: moderngl.Context | None = None, context_kind: str = "auto",
                 specialise: bool = True, prune_shadows: bool = True):
        width, height = image_size(width, height)
        check_light_count(scene)         # before a program fails to link (renderer/core/gl_rules.py)
        self.scene = scene
        self.width, self.height = width, height
        self.specialise = bool(specialise)
        # False draws every caster into every shadow map and cube face, also those that can
        # change nothing (renderer/core/shadows.py, plan_shadows(prune=False)): what the frame
        # would cost without leaving them out (benchmarks/bench_shadow_pruning.py); a
        # directional map is then fitted to every caster, so the image may differ.
        self.prune_shadows = bool(prune_shadows)
        self.wireframe = False           # draw() draws edges only (a viewer's toggle)
        self._shadows = True             # the `shadows` switch
        self._open_context(context, context_kind)
        self._programs = ProgramCache(self.ctx)
        self._textures = TextureCache(self.ctx)
        self._objects: list[_ObjectBuffers] = []
        self._renderbuffers: list = []
        self._framebuffers: dict[bool, moderngl.Framebuffer] = {}
        self._plans: dict[bool, list[_Draw]] = {}
        self._staging: dict[int, np.ndarray] = {}       # attachment -> read-back array
        self._multisample: dict[int, moderngl.Framebuffer] = {}   # samples -> MSAA target
        self._jittered: dict[bool, tuple] = {}           # plan -> sample offset its programs hold
        self._shadow_layout = ShadowLayout()         # update() sets it (renderer/core/shadows.py)
        self._shadow_maps: ShadowMaps | None = None       # made when the layout has maps
        self._shadowed: dict[bool, bool] = {}             # plan -> whether a program looks maps up
        self._drawn_shadow_plan = None                    # what the last draw() drew into the maps
        self._shadow_plan = None                          # the frame's plan (update()); None: no maps
        try:
            activate(self.ctx)
            self._check_size()
            self._glDisable = gl_function(self.ctx, "glDisable", None, ctypes.c_uint)
            self._glClipControl = gl_function(self.ctx, "glClipControl", None, ctypes.c_uint,
                                              ctypes.c_uint)
            self._build_targets()
            self._gl_info = self._query_gl_info()
            self._build_objects()
            self.update()
        except BaseException:
            self.release()
            raise

    # -- building ----------------------------------------------------------------------------
    def _check_size(self) -> None:
        limit = int(self.ctx.info["GL_MAX_RENDERBUFFER_SIZE"])
        if max(self.width, self.height) > limit:
            raise ValueError(f"image size {self.width}x{self.height} exceeds this GL's "
                             f"renderbuffer limit of {limit} pixels")

    def _build_targets(self) -> None:
        size = (self.width, self.height)
        try:
            self._color = self.ctx.renderbuffer(size, 4)                       # RGBA8
            self._depth = self.ctx.depth_renderbuffer(size)
            self.depth_format = make_float_depth(self.ctx, self._depth, self.width, self.height)
            self._renderbuffers += [self._color, self._depth]
            self._framebuffers[False] = self.ctx.framebuffer([self._color], self._depth)
        except moderngl.Error as error:
            # Within GL_MAX_RENDERBUFFER_SIZE, yet the implementation could not give the storage
            # (llvmpipe at 16384x8192: "framebuffer is not complete"): the system's limit.
            raise SystemFault(f"this GL could not make a {self.width}x{self.height} framebuffer "
                              f"({error}); it may be out of memory: try a smaller --size") from None

    def _linear_framebuffer(self) -> moderngl.Framebuffer:
        fbo = self._framebuffers.get(True)
        if fbo is None:
            linear = self.ctx.renderbuffer((self.width, self.height), 4, dtype="f4")  # RGBA32F
            self._renderbuffers.append(linear)
            fbo = self._framebuffers[True] = self.ctx.framebuffer([self._color, linear], self._depth)
        return fbo

    def _multisample_framebuffer(self, samples: int) -> moderngl.Framebuffer:
        """An RGBA8 colour and float depth target with `samples` samples per pixel, made the
        first time it is asked for; render() resolves it into the single-sample one."""
        fbo = self._multisample.get(samples)
        if fbo is None:
            offered = self.sample_counts
            if samples not in offered:
                raise ValueError(f"this GL offers MSAA with {', '.join(map(str, offered))} "
                                 f"samples per pixel, not {samples}")
            size = (self.width, self.height)
            color = self.ctx.renderbuffer(size, 4, samples=samples)
            depth = self.ctx.depth_renderbuffer(size, samples=samples)
            make_float_depth(self.ctx, depth, self.width, self.height, samples=samples)
            self._renderbuffers += [color, depth]
            fbo = self._multisample[samples] = self.ctx.framebuffer([color], depth)
        return fbo

    def _build_objects(self) -> None:
        for obj in self.scene.objects:
            if obj.cull not in CULL_FLAGS:
                raise ValueError(f"object {obj.name!r}: cull must be one of "
                                 f"{', '.join(CULL_FLAGS)}, got {obj.cull!r}")
            check_tessellated(obj)
            item = _ObjectBuffers(obj, obj.mesh, None, None, None, {}, {})
            if is_plane(obj):        # its polygon's buffers, at their largest, written per update()
                item.polygon = PolygonBuffers.make(self.ctx, uvs=True)
            self._objects.append(item)
            self._upload(item)

    def _upload(self, item: _ObjectBuffers) -> None:
        mesh = item.mesh = item.obj.mesh
        if mesh.triangle_count:
            item.vbo = self.ctx.buffer(vertex_bytes(mesh))
            item.ibo = self.ctx.buffer(np.ascontiguousarray(mesh.faces, dtype=np.uint32).tobytes())
        if item.obj.tessellation is None:
            pass
        elif item.obj.tessellation.surface == "displaced":   # a patch per face, its corners apart
            corners = np.concatenate(displaced_patches(mesh), axis=2)
            item.patches = (self.ctx.buffer(np.ascontiguousarray(corners, dtype=np.float32).tobytes()),
                            self.ctx.buffer(np.arange(3 * len(corners), dtype=np.uint32).tobytes()),
                            len(corners))
        elif item.obj.tessellation.surface == "pn_triangles":
            net = pn_patches(mesh)
            corners = np.concatenate([net.positions, net.normals, net.straight[..., None]], axis=2)
            item.patches = (self.ctx.buffer(np.ascontiguousarray(corners, dtype=np.float32).tobytes()),
                            self.ctx.buffer(np.arange(3 * net.count, dtype=np.uint32).tobytes()),
                            net.count)
        else:                                       # the camera pass draws its patches instead
            patches = patch_mesh(item.obj.shape)
            item.patches = (self.ctx.buffer(vertex_bytes(patches)),
                            self.ctx.buffer(np.ascontiguousarray(patches.faces, dtype=np.uint32).tobytes()),
                            patches.triangle_count)
        self._upload_uvs(item)

    def _upload_uvs(self, item: _ObjectBuffers) -> None:
        """The mesh's UVs (in_uv, float32) once the object's material is textured: when it is
        made, or at the update() after a material gains a texture. (A plane's polygon has
        its own, written with it.)"""
        if item.polygon is not None:
            return
        uvs = item.obj.texture_coordinates()
        if uvs is not None and item.uv_vbo is None and item.vbo is not None:
            item.uv_vbo = self.ctx.buffer(np.ascontiguousarray(uvs, dtype=np.float32).tobytes())

    @staticmethod
    def _release_buffers(item: _ObjectBuffers) -> None:
        """The mesh's buffers and the vertex arrays (a polygon's buffers stay: release())."""
        for vao in item.vertex_arrays.values():
            vao.release()
        for buffer in (item.vbo, item.ibo, item.uv_vbo, item.face_normals, *(item.patches or ())[:2]):
            if buffer is not None:
                buffer.release()
        item.vertex_arrays, item.vbo, item.ibo, item.uv_vbo, item.face_normals = {}, None, None, None, None
        item.patches = None

    def _face_normals(self, item: _ObjectBuffers) -> moderngl.Texture:
        """The object's faces (normals and creases) as an RGBA32F texture (renderer/core/facets.py
        face_texture), made the first time a shadowed program draws it; texelFetch reads it
        (NEAREST, one level, so that it is complete)."""
        if item.face_normals is None:
            data = face_texture(item.mesh)
            texture = self.ctx.texture((data.shape[1], data.shape[0]), 4, data.tobytes(), dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            item.face_normals = texture
        return item.face_normals

    def _variant(self, obj: SceneObject, linear: bool) -> ShaderVariant:
        return ShaderVariant.for_object(self.scene, obj, maps=self._shadows and self._shadow_layout.any,
                                        linear_output=linear, all_features=not self.specialise)

    def _vertex_array(self, item: _ObjectBuffers, variant: ShaderVariant) -> moderngl.VertexArray:
        vao = item.vertex_arrays.get(variant)
        if vao is None:
            program = self._programs.get(variant)
            vbo, ibo, uv_vbo = item.drawn_buffers
            surface = item.obj.tessellation.surface if variant.tessellation else None
            if surface == "pn_triangles":                  # a PN patch's corners
                content = [(vbo, "3f 3f 1f", "in_position", "in_normal", "in_straight")]
            elif surface == "displaced":                   # a displaced patch's corners
                content = [(vbo, "3f 3f 2f", "in_position", "in_normal", "in_uv")]
            elif program.get("in_normal", None) is not None:
                content = [(vbo, "3f 3f", "in_position", "in_normal")]
            else:                                    # flat: the normal is the face's, not read
                content = [(vbo, "3f 3x4", "in_position")]
            if program.get("in_uv", None) is not None and surface is None:   # textured, the texel used
                content.append((uv_vbo, "2f", "in_uv"))
            vao = self.ctx.vertex_array(program, content, index_buffer=ibo,
                                        index_element_size=4)
            item.vertex_arrays[variant] = vao
        return vao

    # -- uniforms ----------------------------------------------------------------------------
    def update(self, scene: Scene | None = None) -> None:
        """Recompute every uniform from the scene (camera, lights, materials, transforms), and
        what the camera pass draws of each analytic plane (its polygon in the view volume,
        written into the buffers made for it). `scene`: draw that Scene from now on, one of
        the same objects (a copy with another camera or lights)."""
        scene = self.scene if scene is None else scene
        if len(scene.objects) != len(self._objects) or any(
                a is not b.obj for a, b in zip(scene.objects, self._objects)):
            raise ValueError("the scene's objects changed since this GpuRenderer was made; "
                             "make a new one")
        self.scene = scene
        activate(self.ctx)          # new meshes and maps are made in this renderer's context
        for item in self._objects:
            if item.mesh is not item.obj.mesh:          # a new mesh object: upload it again
                self._release_buffers(item)
                self._upload(item)
            self._upload_uvs(item)
        matrices = scene.matrices(self.width, self.height)
        drawn = drawn_meshes(scene, matrices)
        for item, what in zip(self._objects, drawn):
            if item.polygon is not None:
                item.polygon.write(what.mesh)
        visible = visible_objects(scene, matrices, drawn)
        shadows = self._update_shadows(matrices, visible)
        self._frame_uniforms = frame_uniform_values(
            scene, matrices, light_slots=None if self.specialise else ALL_FEATURES_LIGHTS,
            shadows=shadows)
        # Objects wholly outside the view volume are left out of the frame's plan.
        self._visible = visible if self.specialise else [True] * len(self._objects)
        for index, (item, what) in enumerate(zip(self._objects, drawn)):
            item.uniform_bytes = object_uniform_values(
                item.obj, what.matrices,
                None if self._shadow_plan is None else self._shadow_plan.self_masks(index), self.height)
            # Uploaded the first time a texture is asked for; a material's new texture then.
            texture = item.obj.material.texture
            item.texture = None if texture is None else self._textures.get(texture)
        self._depth_from_window = _depth_conversion(matrices.projection, (self.height, self.width),
                                                    scene.camera.reversed_z)
        self._projection = matrices.projection
        self._plans.clear()
        self._jittered.clear()

    def _update_shadows(self, matrices, visible: list[bool]) -> dict | None:
        """The shadow layout (the maps' texture changes only with it: an automatic resolution follows
        the image size), the frame's shadow plan for the depth pass; its lookup uniforms, or
        None when the scene has no maps. The plan is fitted to the objects the camera sees in
        either build, so that the all-features build draws the same shadows."""
        layout = shadow_layout(self.scene, self.width, self.height, prune=self.prune_shadows)
        if layout != self._shadow_layout and layout.any:
            if self._shadow_maps is None:
                self._shadow_maps = ShadowMaps(self.ctx, layout)
            else:
                self._shadow_maps.set_layout(layout)
        self._shadow_layout = layout
        self._shadow_plan = None
        if not layout.any:
            return None
        plan = self._shadow_plan = plan_shadows(self.scene, matrices, layout, visible,
                                                prune=self.prune_shadows)
        self._shadow_maps.set_plan(plan, [(item.vbo, item.ibo) for item in self._objects],
                                   [m.model for m in matrices.objects])
        return plan.uniforms

    def resize(self, width: int, height: int) -> None:
        """Render at another size from now on (a viewer's window was resized): the framebuffers
        are made again at that size and update() recomputes the projection for the new aspect.
        Programs, meshes and vertex arrays are kept."""
        width, height = image_size(width, height)
        if (width, height) == (self.width, self.height):
            return
        activate(self.ctx)
        self._release_targets()
        self._staging.clear()
        self.width, self.height = width, height
        self._check_size()
        self._build_targets()
        self.update()

    def _release_targets(self) -> None:
        """Free the framebuffers and their renderbuffers (single-sample, linear, MSAA)."""
        for fbo in [*self._multisample.values(), *self._framebuffers.values()]:
            fbo.release()
        for renderbuffer in self._renderbuffers:
            renderbuffer.release()
        self._multisample, self._framebuffers, self._renderbuffers = {}, {}, []

    def _plan(self, linear: bool) -> list[_Draw]:
        """The frame's draw calls; made once per update() for each kind of output."""
        plan = self._plans.get(linear)
        if plan is not None:
            return plan
        plan, programs = [], {}
        for item, visible in zip(self._objects, self._visible):
            if item.vbo is None or not visible or item.count == 0:
                continue
            variant = self._variant(item.obj, linear)
            vao = self._vertex_array(item, variant)
            program = programs[variant] = self._programs.get(variant)
            # Every uniform the variant declares gets a value (ShaderSourceError otherwise);
            # one the compiler dropped as unused is not written.
            self._programs.check_values(variant, item.uniform_bytes.keys() | self._frame_uniforms.keys())
            uploads = [(program[name], data) for name, data in item.uniform_bytes.items()
                       if program.get(name, None) is not None]
            cull = CULL_FLAGS[item.obj.cull]
            enable = moderngl.DEPTH_TEST | (moderngl.CULL_FACE if cull else 0)
            facets = self._face_normals(item) if variant.shadows else None
            displacement = item.obj.tessellation.displacement if variant.tessellation else None
            heights = None if displacement is None else (self._textures.texture(displacement.texture),
                                                         self._textures.sampler(DISPLACEMENT_SAMPLER))
            plan.append(_Draw(vao, enable, cull, uploads, item.texture if variant.texture else None,
                              facets, item.count, item.patches[2] if variant.tessellation else 0, heights))
        self._shadowed[linear] = any(variant.shadows for variant in programs)
        for program in programs.values():          # the same for every object: set once here
            for name, data in self._frame_uniforms.items():
                uniform = program.get(name, None)
                if uniform is not None:
                    # GL may keep only the first elements of an array (the all-features build
                    # of a flat or Gouraud receiver of shadows reads the scene's lights only:
                    # its light terms are sized so): write those. 4 bytes a component.
                    uniform.write(data[:4 * uniform.dimension * uniform.array_length])
        self._plans[linear] = plan
        return plan

    # -- rendering ---------------------------------------------------------------------------
    def render(self, out: Frame | None = None, *, linear: bool = False, depth: bool = True,
               sample_offset: tuple = (0.0, 0.0), samples: int = 1, progress=None) -> Frame:
        """Draw the scene; rgba8 always, the unclamped linear colour and depth as asked.

        `sample_offset` (dx, dy) samples each pixel that far from its centre (pixels, GL window
        coordinates; docs/conventions.md): only u_projection is uploaded again, as
        transforms.jitter(dx, dy, W, H) @ P. `samples` > 1 draws with MSAA into a multisample
        target (made once per sample count) resolved into rgba8; linear colour is then not
        available, and depth is the resolved sample GL picks.

        Each frame's arrays are new unless `out` names an earlier frame of this renderer:
        then they are written into that frame's arrays, which a loop over many frames (a
        viewer, a batch, a benchmark) can reuse to skip allocating (and page-faulting in)
        a few megabytes per frame.
        """
        start = time.perf_counter()
        fbo = self.draw(linear=linear, sample_offset=sample_offset, samples=samples)
        # GL returns rows bottom-up: read into staging arrays made once, then write each
        # output flipped (row 0 at the top) into a C-contiguous array the caller keeps.
        reuse = (out.rgba8, out.linear, out.depth) if out is not None else (None, None, None)
        rgba8 = flip_into(self._read(fbo, 0, np.uint8), reuse[0])
        linear_color = depth_map = None
        if linear:
            linear_color = flip_into(self._read(fbo, 1, np.float32), reuse[1])
        if depth:
            depth_map = self._depth_from_window(self._read(fbo, -1, np.float32)[::-1], reuse[2])
        if progress is not None:                 # one draw: done at once
            progress(self.height, self.height)
        return Frame(rgba8, linear_color, depth_map, (time.perf_counter() - start) * 1000.0,
                     gl_info=self._gl_info)

    def draw(self, *, linear: bool = False, sample_offset: tuple = (0.0, 0.0),
             samples: int = 1) -> moderngl.Framebuffer:
        """Draw the scene into this renderer's single-sample framebuffer (returned) and read
        nothing back: render() is draw() plus the read-back; a window viewer blits the
        framebuffer to the screen instead (renderer/viewer/presenter.py). Arguments as render()'s.
        With `wireframe` set, triangles are drawn as their edges (glPolygonMode GL_LINE)."""
        if self._released:
            raise RuntimeError("this GpuRenderer was released")
        ctx = self.ctx
        activate(ctx)
        if self._glDisable is not None:
            self._glDisable(GL_DITHER)              # unorm8 output must be the plain rounding
        if samples > 1 and linear:
            raise ValueError("linear colour is not available with MSAA (samples > 1)")
        fbo = self._linear_framebuffer() if linear else self._framebuffers[False]
        plan = self._plan(linear)
        self._set_sample_offset(linear, tuple(sample_offset))
        target = self._multisample_framebuffer(samples) if samples > 1 else fbo
        shadowed = self._shadowed[linear]
        self._drawn_shadow_plan = None
        if shadowed:
            # The light views first, with GL's default clip control (every frame leaves it
            # behind) whatever the camera's depth mapping.
            self._shadow_maps.draw()
            self._drawn_shadow_plan = self._shadow_maps.plan
        target.use()
        red, green, blue = self.scene.background
        mapping = depth_mapping(self.scene.camera.reversed_z)
        # The context may be shared: set the clip control for this frame either way, and
        # leave GL's default behind for whoever draws next.
        self._clip_control(mapping)
        try:
            if shadowed:
                self._shadow_maps.bind()
            target.clear(red, green, blue, 0.0, depth=mapping.clear_depth)
            ctx.depth_func = mapping.depth_func
            ctx.front_face = "ccw"
            ctx.wireframe = self.wireframe
            for draw in plan:
                ctx.enable_only(draw.enable)
                if draw.cull_face:
                    ctx.cull_face = draw.cull_face
                for uniform, data in draw.uploads:
                    uniform.write(data)
                if draw.texture is not None:
                    texture, sampler = draw.texture
                    texture.use(MATERIAL_TEXTURE_UNIT)
                    sampler.use(MATERIAL_TEXTURE_UNIT)
                if draw.face_normals is not None:
                    draw.face_normals.use(FACE_NORMALS_UNIT)
                if draw.heights is not None:
                    draw.heights[0].use(DISPLACEMENT_TEXTURE_UNIT)
                    draw.heights[1].use(DISPLACEMENT_TEXTURE_UNIT)
                if draw.patches:                  # a tessellated sphere: triangle patches
                    self._draw_patches(draw)
                else:
                    draw.vertex_array.render(moderngl.TRIANGLES, vertices=draw.count)
            if target is not fbo:
                ctx.copy_framebuffer(fbo, target)    # the MSAA resolve (glBlitFramebuffer)
        finally:
            textured = [draw.texture for draw in plan if draw.texture is not None]
            if textured:                              # unbinds (glBindSampler(unit, 0))
                textured[-1][1].clear(MATERIAL_TEXTURE_UNIT)
            displaced = [draw.heights for draw in plan if draw.heights is not None]
            if displaced:
                displaced[-1][1].clear(DISPLACEMENT_TEXTURE_UNIT)
            ctx.wireframe = False
            if mapping is not STANDARD_DEPTH:
                self._clip_control(STANDARD_DEPTH)
        return fbo

    def _draw_patches(self, draw: _Draw) -> None:
        """A tessellated object's patches, PATCHES_PER_DRAW at a time: llvmpipe's element
        indices wrap past 65,536 generated points in a run of patches (renderer/core/tessellation.py)."""
        before, self.ctx.patch_vertices = self.ctx.patch_vertices, 3
        try:
            for first in range(0, draw.patches, PATCHES_PER_DRAW):
                count = min(PATCHES_PER_DRAW, draw.patches - first)
                draw.vertex_array.render(moderngl.PATCHES, vertices=3 * count, first=3 * first)
        finally:
            self.ctx.patch_vertices = before

    def _clip_control(self, mapping: DepthMapping) -> None:
        """glClipControl with the depth mapping's depth mode (core/gl_rules.py)."""
        if self._glClipControl is None:
            if mapping is not STANDARD_DEPTH:
                raise ContextError("reversed_z needs glClipControl (OpenGL 4.5 or "
                                   "ARB_clip_control), which this GL does not have")
            return
        self._glClipControl(GL_LOWER_LEFT, mapping.clip_control)

    def _set_sample_offset(self, linear: bool, offset: tuple) -> None:
        """Upload u_projection jittered for `offset` to the plan's programs, if they hold
        another one (after _plan() they hold the unjittered projection)."""
        if self._jittered.get(linear, (0.0, 0.0)) == offset:
            return
        data = to_glsl(jitter(*offset, self.width, self.height) @ self._projection)
        for program in {id(d.vertex_array.program): d.vertex_array.program
                        for d in self._plans[linear]}.values():
            uniform = program.get("u_projection", None)
            if uniform is not None:
                uniform.write(data)
        self._jittered[linear] = offset

    def _read(self, fbo, attachment: int, dtype) -> np.ndarray:
        """The attachment's pixels, bottom row first, in a staging array reused every frame."""
        out = self._staging.get(attachment)
        if out is None:
            shape = (self.height, self.width) + ((4,) if attachment >= 0 else ())
            out = self._staging[attachment] = np.empty(shape, dtype)
        fbo.read_into(out, components=4 if attachment >= 0 else 1, attachment=attachment,
                      alignment=1, dtype="f1" if dtype is np.uint8 else "f4")
        return out

    # -- information -------------------------------------------------------------------------
    def _query_gl_info(self) -> dict:
        return self._context_info() | {"depth_format": self.depth_format}

    @property
    def sample_counts(self) -> list[int]:
        """The MSAA sample counts render(samples=...) can use: multisample_counts(ctx)."""
        return multisample_counts(self.ctx)

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        return self._framebuffers[False]

    @property
    def programs(self) -> dict:
        """ShaderVariant -> moderngl.Program, for the variants made so far."""
        return dict(self._programs.items())

    @property
    def shadows(self) -> bool:
        """Whether draw() draws shadows (default True): False leaves out the light views and
        draws with the programs that have no shadow code (the scene as if no light had
        shadows on). The frame's shadow plan is still made by update(), so that turning
        shadows on again needs no update(); the programs of both settings stay cached."""
        return self._shadows

    @shadows.setter
    def shadows(self, on: bool) -> None:
        if bool(on) != self._shadows:
            self._shadows = bool(on)
            self._plans.clear()                   # the draws name other programs now
            self._jittered.clear()

    @property
    def shadow_maps(self) -> ShadowMaps | None:
        """The maps' texture and depth pass (None while the scene has no shadow maps)."""
        return self._shadow_maps

    @property
    def drawn_shadow_plan(self):
        """The ShadowPlan whose light views the last draw() drew into shadow_maps, the maps
        its lighting read; None when it drew none (shadows off, no map, no receiver drawn
        with shadow code)."""
        return self._drawn_shadow_plan

    @property
    def drawn_objects(self) -> list[str]:
        """Names of the objects the current frame plan draws, in order: those with triangles
        and, when specialising, not wholly outside the view volume."""
        return [item.obj.name for item, visible in zip(self._objects, self._visible)
                if item.vbo is not None and visible and item.count != 0]

    @property
    def vertex_arrays(self) -> list:
        """Every vertex array made so far, objects in scene order."""
        return [vao for item in self._objects for vao in item.vertex_arrays.values()]

    # -- lifetime ----------------------------------------------------------------------------
    def _free(self) -> None:
        """Free every GL object (ContextRenderer.release: the context too if this renderer
        made it); gl_info also names the depth buffer's format."""
        self._plans.clear()
        try:
            if self._shadow_maps is not None:
                self._shadow_maps.release()
                self._shadow_maps = None
            for item in self._objects:
                self._release_buffers(item)
                if item.polygon is not None:
                    item.polygon.release()
            self._release_targets()
            self._programs.release()
            self._textures.release()
        finally:
            self._objects, self._framebuffers, self._renderbuffers = [], {}, []
            self._multisample = {}


def _depth_conversion(projection: np.ndarray, shape: tuple[int, int], reversed_z: bool = False):
    """A function from window depth z_w (float32, any strides) to a C-contiguous array of
    -z_eye (+inf where z_w is the depth buffer's clear value: 1, or 0 with reversed-Z), for the projection
    matrix P of the frame; the array is new unless a usable `out` is passed.

    z_ndc = s z_w + t, the depth mapping's inverse (core/gl_rules.py: (s, t) = (2, -1) for GL's
    default, (1, 0) for reversed-Z). Perspective (P[3] = (0, 0, -1, 0)): z_ndc = -P22 - P23 / z_eye,
    so -z_eye = P23 / (P22 + z_ndc) = a / (z_w + b) with a = P23 / s, b = (P22 + t) / s.
    Parallel (P[3] = (0, 0, 0, 1)): z_ndc = P22 z_eye + P23, so -z_eye = (s z_w + t - P23) / -P22.
    b is split into a float32 head and tail so that z_w + b loses nothing where z_w is near -b
    (the head's sum with z_w is exact there, Sterbenz), giving float64-like accuracy in float32.
    """
    p22, p23 = float(projection[2, 2]), float(projection[2, 3])
    mapping = depth_mapping(reversed_z)
    s_ndc, t_ndc = mapping.ndc_from_window
    cleared = mapping.clear_depth
    mask = np.empty(shape, dtype=bool)                     # reused: no allocation per frame
    perspective = projection[3, 2] == -1.0 and projection[3, 3] == 0.0
    if perspective:
        a = np.float32(p23 / s_ndc)
        b = (p22 + t_ndc) / s_ndc
        b_head = np.float32(b)
        b_tail = np.float32(b - float(b_head))

        def convert(window_depth: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
            out = np.add(window_depth, b_head, out=usable(out, window_depth))
            out += b_tail
            np.divide(a, out, out=out)
            np.copyto(out, np.inf, where=np.equal(window_depth, cleared, out=mask))
            return out
    else:
        s = np.float32(-s_ndc / p22)
        t = np.float32((p23 - t_ndc) / p22)

        def convert(window_depth: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
            out = np.multiply(window_depth, s, out=usable(out, window_depth))
            out += t
            np.copyto(out, np.inf, where=np.equal(window_depth, cleared, out=mask))
            return out
    return convert
