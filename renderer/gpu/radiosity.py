"""Radiosity on the GPU (issue 33; the method "radiosity", renderer/methods/radiosity.py): the
scene's elements, their hemicubes drawn by GL (renderer/gpu/item_buffers.py), the equation
solved (renderer/core/radiosity.py), and each frame the elements drawn with their corners'
radiosity interpolated (glsl/radiosity/display.vert, display.frag; Gouraud shading).

The solution is kept while only the camera moves: update() compares the new scene's elements
with the last ones and draws the hemicubes again only when the geometry changed; new
reflectances or emissions re-solve with the same form factors, moved lights draw only the
lights' buffers again (`solves`, `form_factor_draws`, `light_draws` count each). Frames: RGBA32F colour and R32F view depth, read back row 0 at the top; GL's
standard depth test (or reversed-Z's, with glClipControl, as the camera says), no culling
(an element's back hides what is behind it, and shows black: elements reflect and emit from
their front only).

Twin: reference/radiosity/display.py (with reference/radiosity/item_buffer.py).
"""

from __future__ import annotations

import contextlib
import ctypes
import time
from typing import Iterator

import moderngl
import numpy as np

from renderer.core.frame import Frame, image_size
from renderer.core.gl_rules import GL_LOWER_LEFT, STANDARD_DEPTH, depth_mapping, to_unorm8
from renderer.core.radiosity import (RadiositySolution, SpecularDisplay, elements_for, lighting_for, refreshed,
                                     specular_display)
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_progressive import Progress, progressive_solution
from renderer.core.scene import Scene
from renderer.core.transforms import to_glsl
from renderer.errors import ContextError
from renderer.gpu.base import ContextRenderer
from renderer.gpu.context import activate, gl_function
from renderer.gpu.item_buffers import ItemBuffers
from renderer.gpu.readback import flip_into
from renderer.gpu.shaders import shader_source


class RadiosityRenderer(ContextRenderer):
    """The method "radiosity" on the GPU, for the Renderer protocol (renderer/gpu/base.py)."""

    def __init__(self, scene: Scene, width: int, height: int, options: RadiosityOptions | None = None, *,
                 context: moderngl.Context | None = None, context_kind: str = "auto", solve: bool = True):
        """`solve`: solve now (update()); False leaves it to progressive() (a viewer), and the
        frames show the background until a step brings a solution."""
        self.scene = scene
        self.width, self.height = image_size(width, height)
        self.options = options or RadiosityOptions()
        self.solution: RadiositySolution | None = None
        self.solves = self.form_factor_draws = self.light_draws = 0
        self._open_context(context, context_kind)
        self._resources: list = []
        self._mesh: list = []
        self._programs: dict = {}                  # by defines: with or without the specular term
        self._surfaces = None                      # (LightSurfaces, its texture) uploaded
        self._specular: SpecularDisplay | None = None
        self._materials = None
        try:
            activate(self.ctx)
            ctx = self.ctx
            self._clip_control = gl_function(ctx, "glClipControl", None, ctypes.c_uint, ctypes.c_uint)
            self.program = self._program_for(None)
            self._gl_info = self._context_info()
            self._build_targets()
            if solve:
                self.update()
        except BaseException:
            self.release()
            raise

    def _build_targets(self) -> None:
        ctx = self.ctx
        self._targets = [ctx.texture((self.width, self.height), 4, dtype="f4"),
                         ctx.texture((self.width, self.height), 1, dtype="f4"),
                         ctx.depth_renderbuffer((self.width, self.height))]
        self._fbo = ctx.framebuffer(self._targets[:2], self._targets[2])

    def _release_targets(self) -> None:
        for thing in (self._fbo, *self._targets):
            thing.release()

    # -- the solution ----------------------------------------------------------------------------
    def update(self, scene: Scene | None = None) -> None:
        """Take `scene` (or the scene changed in place): the hemicubes are drawn again only if
        its elements moved; the equation is solved again if anything but the camera changed."""
        self._check_alive()
        if scene is not None:
            self.scene = scene
        activate(self.ctx)
        solution = refreshed(self.solution, elements_for(self.scene, self.options),
                             lighting_for(self.scene, self.options), self.options, self._item_buffers,
                             "gpu", self.scene.name)
        if solution is None:                       # only the camera moved (or k_s and n: render())
            return
        self.solution = solution
        self.solves += 1
        self._upload_mesh()

    def progressive(self, scene: Scene | None = None, **steps) -> Iterator[Progress]:
        """Radiosity solved a step at a time for `scene` (or the scene changed in place), for a
        viewer (renderer/core/radiosity_progressive.py; `steps`: its keywords): each step's
        estimate becomes this renderer's solution, drawn by the next render(), and its Progress
        is yielded. The last solution's form factors are kept where the geometry is the same."""
        self._check_alive()
        if scene is not None:
            self.scene = scene
        activate(self.ctx)
        for progress in progressive_solution(self.solution, elements_for(self.scene, self.options),
                                             lighting_for(self.scene, self.options), self.options,
                                             self._item_buffers, "gpu", self.scene.name, **steps):
            if progress.solution is not self.solution:
                self.solution = progress.solution
                self._upload_mesh()
            if progress.done:
                self.solves += 1
            yield progress
            activate(self.ctx)                     # a viewer may have drawn elsewhere meanwhile

    def _program_for(self, display: SpecularDisplay | None) -> moderngl.Program:
        """The display's program: with the specular term's arrays sized for `display`, or without."""
        defines = None if display is None else {"SPECULAR": True, "NUM_SOURCES": len(display.where),
                                                "NUM_VIEWS": len(display.views)}
        key = tuple(sorted((defines or {}).items()))
        if key not in self._programs:
            program = self.ctx.program(vertex_shader=shader_source("radiosity/display.vert", defines).text,
                                       fragment_shader=shader_source("radiosity/display.frag", defines).text)
            self._resources.append(program)
            self._programs[key] = program
        return self._programs[key]

    @contextlib.contextmanager
    def _item_buffers(self, elements, resolution, what):
        """GL's item buffers for `elements` at `resolution`, released after (`refreshed`); each
        use counted (`form_factor_draws`, `light_draws`) by `what` it drew."""
        buffers = ItemBuffers(self.ctx, elements, resolution)
        try:
            yield buffers
        finally:
            buffers.release()
        if what == "hemicubes":
            self.form_factor_draws += 1
        else:
            self.light_draws += 1

    def _upload_mesh(self, origin=None) -> None:
        """The elements' corners relative to the camera's `origin` (the frame's) and their values."""
        for thing in self._mesh:
            thing.release()
        self._mesh = []
        origin = self.scene.matrices(self.width, self.height).origin if origin is None else origin
        self._origin = np.array(origin, np.float64)
        solution = self.solution
        self._materials = SpecularDisplay.materials(self.scene)
        display = self._specular = specular_display(solution, self.scene, origin)
        self.program = self._program_for(display)
        columns = [(solution.elements.corners - origin).reshape(-1, 3), solution.corner_radiosity.reshape(-1, 3)]
        names = ["in_position", "in_radiosity"]
        if display is not None:
            columns += [display.normals.reshape(-1, 3), np.repeat(display.ks, 3, axis=0),
                        np.repeat(display.shininess, 3)[:, None]]
            names += ["in_normal", "in_ks", "in_shininess"]
            self._upload_surfaces(solution.light_surfaces)
        data = np.concatenate(columns, axis=1).astype(np.float32)
        if len(data):
            vbo = self.ctx.buffer(data.tobytes())
            content = [(vbo, " ".join(f"{c.shape[1]}f" for c in columns), *names)]
            self._mesh = [vbo]
            if display is not None:
                objects = self.ctx.buffer(np.repeat(display.obj, 3).astype(np.int32).tobytes())
                content.append((objects, "1i", "in_object"))
                self._mesh.append(objects)
            self._mesh.insert(0, self.ctx.vertex_array(self.program, content))

    def _upload_surfaces(self, surfaces) -> None:
        """The light buffers' surfaces as an R32UI array texture, a layer a view, GL's rows
        (bottom first), once per LightSurfaces."""
        if self._surfaces is not None and self._surfaces[0] is surfaces:
            return
        self._release_surfaces()
        views, n, _ = surfaces.surfaces.shape
        texture = self.ctx.texture_array((n, n, views), 1, np.ascontiguousarray(surfaces.surfaces[:, ::-1]).tobytes(),
                                         dtype="u4")
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._surfaces = (surfaces, texture)

    def _release_surfaces(self) -> None:
        if self._surfaces is not None:
            self._surfaces[1].release()
            self._surfaces = None

    # -- frames ----------------------------------------------------------------------------------
    def render(self, out: Frame | None = None, *, linear: bool = True, depth: bool = True,
               progress=None) -> Frame:
        """The elements drawn from the scene's camera: rgba8, linear (alpha the coverage) and
        view depth, row 0 at the top, into `out`'s arrays when given."""
        self._check_alive()
        start = time.perf_counter()
        activate(self.ctx)
        ctx = self.ctx
        matrices = self.scene.matrices(self.width, self.height)
        mapping = depth_mapping(self.scene.camera.reversed_z)
        if mapping is not STANDARD_DEPTH and self._clip_control is None:
            raise ContextError("reversed_z needs glClipControl (OpenGL 4.5 or ARB_clip_control), "
                               "which this GL does not have")
        if self.solution is not None and (not np.array_equal(matrices.origin, self._origin)
                                          or SpecularDisplay.materials(self.scene) != self._materials):
            self._upload_mesh(matrices.origin)     # the camera moved, or k_s and n changed
        background = tuple(float(c) for c in self.scene.background)
        self._fbo.use()
        ctx.viewport = (0, 0, self.width, self.height)
        self._fbo.clear(*background, 0.0, depth=mapping.clear_depth)
        if self._mesh:
            ctx.enable_only(moderngl.DEPTH_TEST)
            ctx.depth_func = mapping.depth_func
            ctx.wireframe = False
            self.program["u_view"].write(to_glsl(matrices.view))
            self.program["u_projection"].write(to_glsl(matrices.projection))
            if self._specular is not None:
                self._write_specular(self._specular)
            if mapping is not STANDARD_DEPTH:
                self._clip_control(GL_LOWER_LEFT, mapping.clip_control)
            try:
                self._mesh[0].render(moderngl.TRIANGLES)
            finally:                                  # GL's defaults back for whoever draws next
                if mapping is not STANDARD_DEPTH:
                    self._clip_control(GL_LOWER_LEFT, STANDARD_DEPTH.clip_control)
                ctx.depth_func = STANDARD_DEPTH.depth_func
                ctx.disable(moderngl.DEPTH_TEST)
        h, w = self.height, self.width
        colour = np.frombuffer(self._fbo.read(components=4, attachment=0, dtype="f4"), np.float32)
        colour = flip_into(colour.reshape(h, w, 4), None if out is None else out.linear)
        view_depth = np.frombuffer(self._fbo.read(components=1, attachment=1, dtype="f4"), np.float32)
        view_depth = flip_into(view_depth.reshape(h, w), None if out is None else out.depth)
        drawn = colour[..., 3] > 0
        view_depth[~drawn] = np.inf
        rgba8 = to_unorm8(colour)
        if progress is not None:
            progress(h, h)
        return Frame(rgba8, colour if linear else None, view_depth if depth else None,
                     (time.perf_counter() - start) * 1000.0, gl_info=self.gl_info)

    def _write_specular(self, display: SpecularDisplay) -> None:
        """The specular term's uniforms (glsl/radiosity/specular.glsl) and its texture on unit 0."""
        program = self.program
        program["u_light_view"].write(np.ascontiguousarray(
            np.swapaxes(display.views, -1, -2)).astype(np.float32).tobytes())            # by columns
        for name, values in (("u_source_where", display.where), ("u_source_intensity", display.intensity),
                             ("u_source_attenuation", display.attenuation), ("u_source_emitter", display.emitter)):
            if name in program:
                program[name].write(np.ascontiguousarray(values, np.float32).tobytes())
        program["u_light_surfaces"].value = 0
        self._surfaces[1].use(0)

    def resize(self, width: int, height: int) -> None:
        self._check_alive()
        activate(self.ctx)
        self.width, self.height = image_size(width, height)
        self._release_targets()
        self._build_targets()
        if self.solution is not None:
            self._upload_mesh()                    # camera-relative to the new size's origin

    def _free(self) -> None:
        try:
            for thing in (*self._mesh, *reversed(self._resources)):
                thing.release()
            self._release_surfaces()
            if getattr(self, "_fbo", None) is not None:
                self._release_targets()
        finally:
            self._resources, self._mesh, self._fbo, self._programs = [], [], None, {}

