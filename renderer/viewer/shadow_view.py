"""The viewer's shadow-map view (the D key): one light's shadow map as a grey-scale image.

It shows what the lighting pass of the frame just drawn read: the layers of
GpuRenderer.shadow_maps that its `drawn_shadow_plan` filled, each texel's stored depth z_w as
a grey level, stretched: the nearest depth the map holds black, the farthest light grey
(0.85), and 1.0, the cleared value (nothing drawn there), white. A light view's depths may
span a sliver of [0, 1] (0.4979 to 0.5006 on shadow_plane at 480x320: the light view's
depth range covers every receiver, far deeper than the casters), too little to see unstretched; `depth_range`
gives the range shown, found on the CPU from the layers read back once per plan (a still
view reads nothing). A directional light's map is a square; a point light's six cube faces are a
3 x 2 grid, +x -x +y on top and -y +z -z below (CUBE_FACE_AXES order, renderer/core/shadows.py),
a face the frame did not draw shown white (the lookup reads it as lit without reading it).
The map's R x R texels fill the largest square (or 3:2 rectangle) centred in the window,
nearest texel, with GL's rows: up in the light's view is up on the screen
(glsl/viewer/shadow_map.frag).

The maps' texture compares depth (COMPARE_REF_TO_TEXTURE, as the lookup needs); the view
reads raw depths through a sampler object with compare off, bound to its texture unit for
its one draw and unbound after it: a sampler object overrides the texture's own sampling
state on its unit, so left bound it could change another pass's lookups.
"""

from __future__ import annotations

import moderngl
import numpy as np

from renderer.core.shadows import LightMap, ShadowPlan
from renderer.gpu.shaders import shader_source
from renderer.gpu.shadow_maps import ShadowMaps
from renderer.viewer.presenter import fit

VIEW_UNIT = 1                      # the texture unit the view reads the maps on
CUBE_GRID = (3, 2)                 # a point light's faces across and down
CUBE_FACE_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")    # CUBE_FACE_AXES, the grid's order


def drawn_faces(plan: ShadowPlan, light_map: LightMap) -> list[int]:
    """The faces of `light_map` (0 for a directional light's) that `plan`'s passes draw."""
    return [p.face for p in plan.passes if (p.kind, p.light) == (light_map.kind, light_map.index)]


def stored_depth_range(maps: ShadowMaps, light_map: LightMap, faces: list[int]) -> tuple | None:
    """(nearest, farthest) depth below 1.0 in texels [0, R)^2 of the given faces' layers;
    None when they hold nothing but 1.0."""
    r = light_map.resolution
    depths = np.concatenate([maps.read_layer(light_map.kind, light_map.tiles[f].layer)[:r, :r].ravel()
                             for f in faces] or [np.ones(1, np.float32)])
    stored = depths[depths < 1.0]
    return (float(stored.min()), float(stored.max())) if stored.size else None


class ShadowMapView:
    """Draws a light's map into an RGBA8 framebuffer of the window's size (made again when
    the size changes); `draw` returns it for the presenter."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=shader_source("raytrace/fullscreen.vert").text,
                                   fragment_shader=shader_source("viewer/shadow_map.frag").text)
        self.program["u_maps"].value = VIEW_UNIT
        self._vao = ctx.vertex_array(self.program, [])
        self._sampler = ctx.sampler(filter=(moderngl.NEAREST, moderngl.NEAREST), compare_func="",
                                    repeat_x=False, repeat_y=False)
        self._colour = self._fbo = None
        self._range_of: tuple | None = None          # (plan, light map) depth_range is for
        self.depth_range: tuple[float, float] | None = None   # of the map drawn last

    def _target(self, size: tuple[int, int]) -> moderngl.Framebuffer:
        if self._fbo is None or self._fbo.size != size:
            self._release_target()
            self._colour = self.ctx.renderbuffer(size, 4)
            self._fbo = self.ctx.framebuffer([self._colour])
        return self._fbo

    def draw(self, maps: ShadowMaps, plan: ShadowPlan, light_map: LightMap,
             size: tuple[int, int], background: tuple[float, float, float]) -> moderngl.Framebuffer:
        """`light_map` (a map of `plan`'s layout) as the frame that drew `plan` left it in
        `maps`, centred in a `size` framebuffer cleared to `background`."""
        ctx = self.ctx
        fbo = self._target(size)
        faces = drawn_faces(plan, light_map)
        if self._range_of is None or self._range_of[0] is not plan or self._range_of[1] != light_map:
            self.depth_range = stored_depth_range(maps, light_map, faces)   # (reads: before use())
            self._range_of = (plan, light_map)
        fbo.use()
        fbo.clear(*background, 1.0)
        grid = CUBE_GRID if len(light_map.tiles) == 6 else (1, 1)
        x0, y0, x1, y1 = fit(grid, (0, 0, *size))
        values = {"u_region": (x0, y0, x1 - x0, y1 - y0), "u_grid": grid,
                  "u_first_layer": light_map.tiles[0].layer, "u_resolution": light_map.resolution,
                  "u_depth_range": self.depth_range or (0.0, 1.0),
                  "u_drawn_faces": sum(1 << face for face in faces)}
        for name, value in values.items():
            self.program[name].value = value
        ctx.viewport = (x0, y0, x1 - x0, y1 - y0)
        ctx.enable_only(moderngl.NOTHING)
        maps.texture(light_map.kind).use(VIEW_UNIT)
        self._sampler.use(VIEW_UNIT)
        try:
            self._vao.render(moderngl.TRIANGLES, vertices=3)
        finally:
            self._sampler.clear(VIEW_UNIT)
        ctx.viewport = (0, 0, *size)
        return fbo

    def _release_target(self) -> None:
        for item in (self._fbo, self._colour):
            if item is not None:
                item.release()
        self._colour = self._fbo = None

    def release(self) -> None:
        self._release_target()
        for item in (self._vao, self._sampler, self.program):
            item.release()
