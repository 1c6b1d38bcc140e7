"""The viewer's shadow-map view (renderer/viewer/shadow_view.py, glsl/viewer/shadow_map.frag),
drawn headless: the map's texels as grey levels, each texel a block of pixels with GL's rows
(row 0 at the bottom), the nearest stored depth black, the farthest 0.85, 1.0 white; a point
light's faces in a 3 x 2 grid, an undrawn face white; what the lighting reads is untouched.
Maps of 64 texels shown 64 pixels a face, so that pixel (x, y) is texel (x, y) exactly."""

import numpy as np
import pytest

from renderer.core.primitives import icosphere, plane
from renderer.core.scene import Camera, DirectionalLight, PointLight, Scene, SceneObject, Transform
from renderer.core.shadow_settings import Shadow
from renderer.gpu.pipeline import GpuRenderer
from renderer.viewer.shadow_view import ShadowMapView, drawn_faces

R = 64
W, H = 64, 48
BACKGROUND = (0.0, 0.0, 1.0)                 # blue: never a grey level


def ball_on_floor(light) -> Scene:
    """A ball hovering over a floor, seen from above and aside, lit by `light` alone."""
    objects = [SceneObject("floor", plane(4.0)),
               SceneObject("ball", icosphere(0.5, 2), transform=Transform(translate=(0.0, 1.0, 0.0)))]
    lights = {"directional_lights" if isinstance(light, DirectionalLight) else "point_lights": [light]}
    return Scene(Camera(eye=(0.0, 4.0, 4.0)), objects, **lights)


@pytest.fixture(scope="module")
def ctx(gl_contexts):
    return gl_contexts["egl"]


def shown(ctx, gpu, size) -> np.ndarray:
    """The view of the first map, (H, W, 3) uint8, GL rows (row 0 at the bottom)."""
    view = ShadowMapView(ctx)
    try:
        plan = gpu.drawn_shadow_plan
        fbo = view.draw(gpu.shadow_maps, plan, plan.layout.maps[0], size, BACKGROUND)
        image = np.frombuffer(fbo.read(components=3, alignment=1), np.uint8)
        return image.reshape(size[1], size[0], 3), view.depth_range
    finally:
        view.release()


def grey(depths: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The grey levels of the module docstring, unorm8, for float32 depths."""
    level = np.where(depths < 1.0, 0.85 * np.clip((depths - lo) / (hi - lo), 0.0, 1.0), 1.0)
    return np.round(level * 255.0)


def test_a_directional_map_is_its_texels_stretched_to_grey(ctx):
    scene = ball_on_floor(DirectionalLight(direction=(0.3, -1.0, 0.2), shadow=Shadow(resolution=R)))
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        before = gpu.render(depth=False).rgba8
        image, (lo, hi) = shown(ctx, gpu, (R + 20, R))          # letterboxed: 10 px each side
        layer = gpu.shadow_maps.read_layer("directional", 0)
        after = gpu.render(depth=False).rgba8
    assert np.array_equal(before, after)                # the lighting's lookups are untouched
    stored = layer[layer < 1.0]
    assert (lo, hi) == (stored.min(), stored.max()) and 0 < stored.size < layer.size
    assert (image[:, :10] == (0, 0, 255)).all() and (image[:, -10:] == (0, 0, 255)).all()
    assert np.abs(image[:, 10:-10, 0] - grey(layer, lo, hi)).max() <= 1
    map_pixels = image[:, 10:-10]
    assert (map_pixels[..., 0] == map_pixels[..., 1]).all() and (map_pixels[..., 1] == map_pixels[..., 2]).all()
    # The sphere, nearest the light, is the darkest: its texels are black.
    j, i = np.unravel_index(np.argmin(layer), layer.shape)
    assert image[j, 10 + i, 0] == 0 and image[:, 10:-10, 0].mean() > 60
    assert (image[:, 10:-10, 0][layer == 1.0] == 255).all()         # cleared: nothing drawn


def test_a_point_lights_faces_are_a_3x2_grid_and_undrawn_faces_are_white(ctx):
    """The light above the sphere: only the -y face (3, bottom left) sees a caster."""
    scene = ball_on_floor(PointLight((0.3, 3.0, 0.2), shadow=Shadow(resolution=R)))
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        gpu.draw()
        image, (lo, hi) = shown(ctx, gpu, (3 * R, 2 * R))
        assert drawn_faces(gpu.drawn_shadow_plan, gpu.drawn_shadow_plan.layout.maps[0]) == [3]
        face = gpu.shadow_maps.read_layer("point", 3)
    bottom_left, others = image[:R, :R, 0], [image[R:, :R], image[R:, R:2 * R], image[R:, 2 * R:],
                                            image[:R, R:2 * R], image[:R, 2 * R:]]
    assert all((other == 255).all() for other in others)
    assert np.abs(bottom_left - grey(face, lo, hi)).max() <= 1
    assert (bottom_left == 255).mean() > 0.5 and bottom_left.min() == 0   # the sphere on the cleared
