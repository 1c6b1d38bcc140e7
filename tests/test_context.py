"""renderer/gpu/context.py and renderer/gpu/osmesa.py: headless contexts of both kinds, one process."""

import numpy as np
import pytest

from renderer.gpu import context as context_module
from renderer.gpu.context import activate, context_kind, make_context, release_context
from renderer.errors import ContextError
from renderer.gpu import GpuRenderer
from renderer.core.scene import Camera, Material, Mesh, Scene, SceneObject

SIZE = (40, 30)


def triangle_scene() -> Scene:
    """One lit triangle, off-centre, with edges crossing pixel rows at odd slopes."""
    mesh = Mesh(positions=np.array([[-0.9, -0.7, 0.0], [0.8, -0.3, 0.0], [-0.2, 0.85, 0.0]]),
                normals=np.tile([0.0, 0.0, 1.0], (3, 1)), faces=np.array([[0, 1, 2]]), source="triangle")
    return Scene(camera=Camera(eye=(0.0, 0.0, 3.0)), ambient=(0.3, 0.2, 0.1),
                 objects=[SceneObject("triangle", mesh, Material(ka=(1.0, 1.0, 1.0), shading="gouraud"))],
                 background=(0.0, 0.0, 0.25))


def render_triangle(ctx):
    with GpuRenderer(triangle_scene(), *SIZE, context=ctx) as gpu:
        return gpu.render()


def test_egl_context_starts_and_reports_llvmpipe():
    ctx = make_context("egl")
    try:
        assert context_kind(ctx) == "egl"
        assert ctx.version_code >= 330
        # The reference models llvmpipe's rasteriser (8 sub-pixel bits, its fill rule).
        assert "llvmpipe" in ctx.info["GL_RENDERER"]
    finally:
        release_context(ctx)


def test_osmesa_context_renders_the_pixels_egl_renders(gl_contexts):
    ctx = make_context("osmesa")
    try:
        assert context_kind(ctx) == "osmesa"
        assert ctx.version_code >= 330 and "Core Profile" in ctx.info["GL_VERSION"]
        osmesa = render_triangle(ctx)
    finally:
        release_context(ctx)
    egl = render_triangle(gl_contexts["egl"])
    assert (osmesa.rgba8[..., 3] == 255).sum() > 100          # the triangle is there
    np.testing.assert_array_equal(osmesa.rgba8, egl.rgba8)
    np.testing.assert_array_equal(osmesa.depth, egl.depth)


def test_osmesa_contexts_come_and_go_repeatedly():
    frames = []
    for _ in range(3):
        ctx = make_context("osmesa")
        loader = context_module._bindings[ctx].loader
        frames.append(render_triangle(ctx).rgba8)
        release_context(ctx)
        assert loader.handle is None                           # destroyed, not leaked
        release_context(ctx)                                   # twice is harmless
    for frame in frames[1:]:
        np.testing.assert_array_equal(frame, frames[0])


def test_interleaved_egl_and_osmesa_renderers_stay_apart(gl_contexts):
    """Both kinds share Mesa's dispatch: each render must bind its own context again."""
    scene = triangle_scene()
    with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as egl, \
            GpuRenderer(scene, *SIZE, context=gl_contexts["osmesa"]) as osmesa:
        frames = [egl.render(), osmesa.render(), egl.render(), osmesa.render()]
    for frame in frames[1:]:
        np.testing.assert_array_equal(frame.rgba8, frames[0].rgba8)


def test_auto_picks_egl():
    ctx = make_context("auto")
    try:
        assert context_kind(ctx) == "egl"
    finally:
        release_context(ctx)


def test_unknown_kind_is_a_clear_error():
    with pytest.raises(ContextError, match=r"unknown GL context kind 'vulkan'.*auto, egl, osmesa"):
        make_context("vulkan")


def test_no_context_names_the_packages_on_one_line(monkeypatch):
    def fail(message):
        def maker():
            raise Exception(message)
        return maker

    monkeypatch.setitem(context_module._MAKERS, "egl", fail("libEGL.so.1 not loaded\n(details)"))
    monkeypatch.setitem(context_module._MAKERS, "osmesa", fail("cannot load libOSMesa"))
    with pytest.raises(ContextError) as error:
        make_context("auto")
    message = str(error.value)
    assert "\n" not in message
    assert "libegl1 libegl-mesa0 libgl1-mesa-dri" in message and "libosmesa6" in message
    assert "libEGL.so.1 not loaded" in message and "cannot load libOSMesa" in message
    with pytest.raises(ContextError, match="libosmesa6") as error:
        make_context("osmesa")
    assert "libegl1" not in str(error.value)


def test_external_context_is_used_as_it_is(gl_contexts):
    """A context made elsewhere is not ours to bind; activate() leaves it alone."""
    import moderngl
    ctx = moderngl.create_standalone_context(backend="egl")
    try:
        assert context_kind(ctx) == "external"
        activate(ctx)                                   # no error, nothing to do
        with GpuRenderer(triangle_scene(), *SIZE, context=ctx) as gpu:
            assert gpu.gl_info["context"] == "external"
            external = gpu.render()
    finally:
        ctx.release()
    np.testing.assert_array_equal(external.rgba8, render_triangle(gl_contexts["egl"]).rgba8)
