"""Radiosity's item buffers (issue 33): renderer/gpu/item_buffers.py (GL's rasteriser running
glsl/radiosity/item_buffer.*) against its twin reference/radiosity/item_buffer.py. By hand: what
a hemicube sees of a square over it, from in front and from behind, and nothing below the
horizon; the twin's vertex product is llvmpipe's bit for bit (transform feedback); then the two
draw identical item buffers, pixel for pixel, on EGL and OSMesa."""

import numpy as np
import pytest

from reference.radiosity.item_buffer import _clip_coordinates, draw
from renderer.core.hemicube import FACES, ITEM_BACK_BIT
from renderer.gpu.context import activate
from renderer.gpu.item_buffers import ItemBuffers, batch_size
from renderer.gpu.shaders import shader_source
from tests.radiosity_scenes import elements_of, furnished_room, quad


def both(ctx, elements, resolution, indices=None):
    indices = np.arange(len(elements)) if indices is None else np.asarray(indices)
    buffers = ItemBuffers(ctx, elements, resolution)
    try:
        gpu = np.concatenate([buffers.draw(indices[k:k + buffers.batch])
                              for k in range(0, len(indices), buffers.batch)])
    finally:
        buffers.release()
    return gpu, draw(elements, resolution, indices)


def a_floor_and_a_ceiling(flip_ceiling=False):
    """A small floor element (index 0) under a 6 x 6 ceiling 1 above (indices 1, 2)."""
    floor = quad((-0.05, -0.05, 0), (0.1, 0, 0), (0, 0.1, 0))[:1]
    ceiling = quad((-3, -3, 1), (0, 6, 0), (6, 0, 0))
    if flip_ceiling:
        ceiling = ceiling[:, [0, 2, 1]]
    return elements_of(np.concatenate([floor, ceiling]), np.array([0, 1, 1]), 100.0)


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_a_ceiling_over_an_element_fills_its_top_face_and_the_upper_sides(gl_contexts, kind):
    elements = a_floor_and_a_ceiling()
    gpu, twin = both(gl_contexts[kind], elements, 8, [0])
    items = gpu[0]
    top, sides = items[0], items[1:]
    assert set(np.unique(top)) <= {2, 3}                     # the ceiling's two triangles, fronts
    # each side face: the ceiling (3 units out, 1 up) above 1/3 of the way up, nothing under it,
    # and nothing in the lower half (below the element's plane)
    assert np.all(sides[:, 4:] == 0)
    assert np.all(np.isin(sides[:, :2], (2, 3))) and np.all(sides[:, 3] == 0)
    assert np.array_equal(gpu, twin.items)


def test_a_back_face_seen_carries_the_back_bit(gl_contexts):
    gpu, twin = both(gl_contexts["egl"], a_floor_and_a_ceiling(flip_ceiling=True), 8, [0])
    top = gpu[0, 0]
    assert np.all(top & ITEM_BACK_BIT) and set(np.unique(top & ~np.uint32(ITEM_BACK_BIT))) <= {2, 3}
    assert np.array_equal(gpu, twin.items)


def test_the_twins_vertex_product_is_llvmpipes_bit_for_bit(gl_contexts):
    """item_buffer.vert's M * vec4(p, 1) captured by transform feedback equals the twin's
    _clip_coordinates in every bit (sums in column order, no fused multiply-add)."""
    ctx = gl_contexts["egl"]
    activate(ctx)
    rng = np.random.default_rng(7)
    positions = (rng.normal(size=(4096, 3)) * 3).astype(np.float32)
    matrices = rng.normal(size=(2, 4, 4))
    program = ctx.program(vertex_shader=shader_source("radiosity/item_buffer.vert").text,
                          varyings=["gl_Position"])
    columns = ctx.texture((8, 1), 4, np.swapaxes(matrices, 1, 2).astype(np.float32).tobytes(), dtype="f4")
    vbo, out = ctx.buffer(positions.tobytes()), ctx.buffer(reserve=2 * len(positions) * 16)
    vao = ctx.vertex_array(program, [(vbo, "3f", "in_position")])
    framebuffer = ctx.simple_framebuffer((4, 4))          # transform feedback needs one bound
    try:
        framebuffer.use()
        columns.use(0)
        program["u_clip_from_world"].value = 0
        vao.transform(out, mode=0, vertices=len(positions), instances=2)    # mode 0: GL_POINTS
        captured = np.frombuffer(out.read(), np.float32).reshape(2, len(positions), 4)
    finally:
        for item in (vao, vbo, out, columns, program, framebuffer):
            item.release()
    assert np.array_equal(captured, _clip_coordinates(positions, matrices))


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_gpu_and_the_twin_draw_identical_item_buffers(gl_contexts, kind):
    """A closed room with a turned cube and a ball in it: every hemicube of 524 elements at
    N = 16, every pixel the same item (and no depth tie: nothing is near-coincident)."""
    elements = elements_of(*furnished_room(), 1.2)
    gpu, twin = both(gl_contexts[kind], elements, 16)
    assert len(elements) == 524 and gpu.shape == (524, len(FACES), 16, 16)
    assert not twin.tied.any()
    assert np.array_equal(gpu, twin.items), f"{(gpu != twin.items).sum()} pixels differ"


@pytest.mark.slow
def test_the_gpu_and_the_twin_draw_identical_item_buffers_finer(gl_contexts):
    elements = elements_of(*furnished_room(), 0.5)
    indices = np.arange(0, len(elements), 7)
    gpu, twin = both(gl_contexts["egl"], elements, 64, indices)
    differ = gpu != twin.items
    assert not (differ & ~twin.tied).any(), f"{(differ & ~twin.tied).sum()} pixels differ where no depth tie"


def test_a_batch_fits_its_textures():
    assert batch_size(16, 1000) == 819                     # the matrices' texture: 16384 texels
    assert batch_size(1024, 10) == 1                       # 40 MiB a hemicube: one at a time
    assert batch_size(64, 5, most=3) == 3
