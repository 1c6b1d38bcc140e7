"""GLSL's vector built-ins on llvmpipe against their twin reference/glsl_builtins.py, bit for bit
on EGL and OSMesa (tests/glsl/builtins.frag): dot summed z first, normalize as v times
1 / sqrt(dot(v, v)), length, cross. And what the other orders would give: summed x first, or
normalize as v / sqrt, a good share of the results are an ulp off (so that the probe can tell)."""

import numpy as np
import pytest

from glsl_harness import float_probe
from reference import glsl_builtins

F32 = np.float32
SIZE = 64


def gpu_builtins(ctx, a, b):
    return float_probe(ctx, "builtins.frag", {"u_a": a, "u_b": b}, outputs=2)


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_twins_built_ins_are_llvmpipes_bit_for_bit(gl_contexts, kind):
    rng = np.random.default_rng(40)
    a, b = (rng.normal(scale=3.0, size=(SIZE, SIZE, 3)).astype(F32) for _ in range(2))
    first, second = gpu_builtins(gl_contexts[kind], a, b)
    cross = glsl_builtins.cross(a, b)
    assert np.array_equal(first[..., 0], glsl_builtins.dot(a, b))
    assert np.array_equal(first[..., 1], glsl_builtins.length(a))
    assert np.array_equal(first[..., 2:], cross[..., :2]) and np.array_equal(second[..., 3], cross[..., 2])
    assert np.array_equal(second[..., :3], glsl_builtins.normalize(a))
    # the orders the twins used before: each an ulp off a good share of the time
    x_first = a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]
    assert (x_first != first[..., 0]).mean() > 0.1
    divided = a / np.sqrt(glsl_builtins.dot(a, a))[..., None]
    assert (divided != second[..., :3]).any(axis=-1).mean() > 0.1
