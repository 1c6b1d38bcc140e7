"""The GPU path is deterministic: a built-in scene drawn again, whether by the same GpuRenderer,
by a new one on the same context, or in another process, gives the same RGBA8 frame byte for
byte, on both EGL and OSMesa.

Run as a script, this module is the other process: it renders every built-in scene once on
each context and prints {"scene/context": sha256 of the frame's RGBA8 bytes} as one JSON line.

Which cases run where: the full run (--all) holds every rasteriser scene on both contexts, in
this process and in the two workers. The default run holds the repetition rule (one renderer
drawing again, new renderers on the same context) with hierarchy, the scene that draws every
shading variant (flat with its geometry stage, Gouraud, Phong) and both kinds of shadow map,
on EGL and on OSMesa; the other processes are the full run's, since the default run already
holds each scene's EGL frame (Phong, and as authored where its modes mix), drawn in this
process, bit for bit to its golden, made in another process (tests/test_goldens.py,
test_gpu_matches_golden, on the GL implementation that made the goldens: this machine's).
"""

import functools
import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from renderer.core.builtin import builtin_scenes
from renderer.gpu.context import make_context
from renderer.gpu import GpuRenderer
from renderer.core.scene_file import load_scene

from conftest import raster_scene_params

SIZE = (256, 256)
CONTEXT_KINDS = ("egl", "osmesa")
SCENE_NAMES = sorted(builtin_scenes())
REUSED_FRAMES = 5              # frames 0-4: one renderer, drawing again and again
FRESH_RENDERERS = 5            # frames 5-9: a new renderer (buffers, programs) for each
WORKER_PROCESSES = 2
WORKER_TIMEOUT_S = 120
# The workers run this file as a script, so their sys.path starts at tests/, not at the
# checkout: put the checkout first, so that they import the renderer this process tests
# (not another copy installed in the environment, e.g. an editable install of another tree).
REPO = Path(__file__).resolve().parents[1]
WORKER_ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(
    filter(None, (str(REPO), os.environ.get("PYTHONPATH")))))


@functools.lru_cache(maxsize=None)
def scene_named(name):
    return load_scene(builtin_scenes()[name])


def case_key(name, kind):
    return f"{name}/{kind}"


def digest(rgba8):
    return hashlib.sha256(rgba8.tobytes()).hexdigest()


def render_once(name, ctx):
    with GpuRenderer(scene_named(name), *SIZE, context=ctx) as gpu:
        return gpu.render(depth=False).rgba8


def render_repeatedly(name, ctx):
    """[(label, rgba8)]: REUSED_FRAMES from one renderer, then one from each of FRESH_RENDERERS
    new renderers on the same context. Each array is copied, so that a renderer handing back
    a buffer it later overwrites could not make two frames equal by being the same memory."""
    frames = []
    with GpuRenderer(scene_named(name), *SIZE, context=ctx) as gpu:
        for i in range(REUSED_FRAMES):
            frames.append((f"reused renderer, draw {i + 1}", gpu.render(depth=False).rgba8.copy()))
    for i in range(FRESH_RENDERERS):
        frames.append((f"new renderer {i + 1}", render_once(name, ctx).copy()))
    return frames


def render_digests(contexts):
    """{"scene/context": sha256 hex} of one frame of every built-in scene on every context."""
    return {case_key(name, kind): digest(render_once(name, ctx))
            for name in SCENE_NAMES for kind, ctx in contexts.items()}


_in_process_digests = {}       # case key -> digest of the first frame drawn in this process


def in_process_digest(name, kind, ctx):
    """This process's digest of the case: the one the repetition test saw, else a new render."""
    key = case_key(name, kind)
    if key not in _in_process_digests:
        _in_process_digests[key] = digest(render_once(name, ctx))
    return _in_process_digests[key]


# -- one process ----------------------------------------------------------------------------

DEFAULT_RUN_SCENE = "hierarchy"     # the rest in the full run: the module's docstring says why
REPEATED = [pytest.param(*p.values, kind, id=f"{p.id}-{kind}", marks=[*p.marks, *(
    [] if p.values[0] == DEFAULT_RUN_SCENE else [pytest.mark.slow])])
    for p in raster_scene_params(SCENE_NAMES, SCENE_NAMES) for kind in CONTEXT_KINDS]


@pytest.mark.parametrize("name, context_kind", REPEATED)
def test_every_frame_of_a_scene_is_byte_identical(name, context_kind, gl_contexts):
    frames = render_repeatedly(name, gl_contexts[context_kind])
    (_, first), later = frames[0], frames[1:]
    assert first.dtype == np.uint8 and first.shape == (SIZE[1], SIZE[0], 4)
    # A frame of nothing but background would be deterministic for no credit.
    assert (first[..., 3] == 255).any(), f"{name} on {context_kind} drew nothing"
    differences = [
        f"frame {index} ({label}): {np.count_nonzero((rgba8 != first).any(axis=-1))} of "
        f"{SIZE[0] * SIZE[1]} pixels differ from frame 0"
        for index, (label, rgba8) in enumerate(later, start=1)
        if not np.array_equal(rgba8, first)]
    assert not differences, f"{name} on {context_kind}:\n" + "\n".join(differences)
    _in_process_digests[case_key(name, context_kind)] = digest(first)


# -- other processes ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def worker_digests():
    """The digests printed by WORKER_PROCESSES runs of this module as a script, started together."""
    workers = [subprocess.Popen([sys.executable, __file__], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, env=WORKER_ENV)
               for _ in range(WORKER_PROCESSES)]
    results = []
    try:
        for number, worker in enumerate(workers, start=1):
            stdout, stderr = worker.communicate(timeout=WORKER_TIMEOUT_S)
            lines = stdout.strip().splitlines()
            if worker.returncode != 0 or not lines:
                pytest.fail(f"worker {number} exited with status {worker.returncode}:\n"
                            f"{stderr.strip()}")
            results.append(json.loads(lines[-1]))
    finally:
        for worker in workers:
            if worker.poll() is None:
                worker.kill()
                worker.wait()
    return results


# The full run's (--all): the module's docstring says what holds this in the default run.
@pytest.mark.slow
def test_other_processes_render_every_case(worker_digests):
    expected = {case_key(name, kind) for name in SCENE_NAMES for kind in CONTEXT_KINDS}
    for number, digests in enumerate(worker_digests, start=1):
        assert set(digests) == expected, f"worker {number}"


@pytest.mark.slow
@pytest.mark.parametrize("context_kind", CONTEXT_KINDS)
@pytest.mark.parametrize("name", raster_scene_params(SCENE_NAMES))
def test_other_processes_render_the_same_bytes(name, context_kind, worker_digests, gl_contexts):
    key = case_key(name, context_kind)
    here = in_process_digest(name, context_kind, gl_contexts[context_kind])
    there = [digests.get(key) for digests in worker_digests]
    assert there == [here] * len(there), (
        f"{key}: sha256 of the RGBA8 frame in this process {here}, "
        f"in the worker processes {there}")


if __name__ == "__main__":
    contexts = {kind: make_context(kind) for kind in CONTEXT_KINDS}
    try:
        print(json.dumps(render_digests(contexts), sort_keys=True))
    finally:
        for ctx in contexts.values():
            ctx.release()
