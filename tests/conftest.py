"""Shared fixtures and the default selection.

The default run (`python -m pytest`) leaves out the tests marked `slow` (several seconds
each: a wheel build, the golden suite run in a copy of the repository, a `renderer report`)
and `window` (a real window on a virtual X display). `pytest --all` runs every test; CI
does (.ci/run). A `-m` expression on the command line chooses by itself instead.

Why an option rather than `-m "not slow and not window"` in addopts: undoing an addopts
`-m` takes another `-m` with an expression that selects everything, which nobody guesses,
and a user's own `-m` would silently replace ours; `--all` says what it does.

The built-in scenes made for the ray tracer (RAYTRACE_SCENES) and for textures
(TEXTURE_SCENES) are rasterised by the tests that take every built-in scene only in the full
run: `raster_scene_params(names)` marks them.

Fixtures: `gl_contexts` (one EGL and one OSMesa context for the session), `x_display` and
`on_x_display` (Xvfb), `cli` (the command line in a new process), `gpu_stand_in` (the command
line's GPU frames replaced, in this process), `reference_frames` (NumPy reference frames,
each rendered once per test run), `traced_references` (the NumPy ray tracer's frames of the
built-in scenes, likewise) and `ray_executor` (the run's one local Ray, for a test module; a test using it
is marked slow and put in the xdist group "ray").
"""

import os
import subprocess
import sys
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from renderer.gpu.context import make_context

CONTEXT_KINDS = ("egl", "osmesa")
DEFAULT_LEFT_OUT = ("slow", "window")
CLI_TIMEOUT_S = 120
RAY_TEST_CPUS = 2                # the test Ray's CPUs: 2 workers at most, as on this machine
# Under pytest-xdist with --dist loadgroup (.ci/run) every Ray test runs in one xdist worker,
# so a test module starts one Ray, not one per xdist worker (each ~4 s and ~630 MiB).
RAY_XDIST_GROUP = "ray"
_LEFT_OUT = pytest.StashKey[int]()


# -- the default selection --------------------------------------------------------------------

def pytest_addoption(parser):
    parser.addoption("--all", action="store_true", dest="run_all",
                     help="run every test, also those marked slow or window (the default run "
                          "leaves them out; CI runs with --all)")


def pytest_itemcollected(item):
    # Every test on the virtual X display opens a window, and every test on a local Ray is
    # slow (the Ray alone starts in ~4 s): marked here, so none is missed (and before `-m`
    # chooses, so that `-m window` finds them).
    if "x_display" in item.fixturenames:
        item.add_marker(pytest.mark.window)
    if "ray_executor" in item.fixturenames:
        item.add_marker(pytest.mark.slow)
        item.add_marker(pytest.mark.xdist_group(RAY_XDIST_GROUP))


@pytest.hookimpl(trylast=True)          # after -k: only what it kept counts as left out here
def pytest_collection_modifyitems(config, items):
    if config.option.run_all or config.option.markexpr:
        return
    kept, left_out = [], []
    for item in items:
        marked = any(item.get_closest_marker(name) for name in DEFAULT_LEFT_OUT)
        (left_out if marked else kept).append(item)
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        items[:] = kept
    config.stash[_LEFT_OUT] = len(left_out)


def pytest_report_header(config):
    if not (config.option.run_all or config.option.markexpr):
        return "default run: tests marked slow or window are left out (pytest --all runs them)"


def pytest_sessionfinish(session, exitstatus):
    # Naming only slow or window tests without --all runs nothing, as asked: not an error
    # (a -k or a path that matches no test at all still is).
    if exitstatus == pytest.ExitCode.NO_TESTS_COLLECTED and session.config.stash.get(_LEFT_OUT, 0):
        session.exitstatus = pytest.ExitCode.OK


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    left_out = config.stash.get(_LEFT_OUT, 0)
    if left_out:
        tests = "test" if left_out == 1 else "tests"
        terminalreporter.write_line(f"left out {left_out} {tests} marked slow or window; "
                                    f"pytest --all runs every test")


# -- the built-in scenes -----------------------------------------------------------------------

# The built-in scenes made for `--method raytrace` (their descriptions say so; tests/
# test_scene_shapes.py holds this set to the scene files). They rasterise too, and the
# rasteriser's tests over every built-in scene (GPU against reference, goldens, determinism,
# specialisation) hold them in the full run: in the default run they would add about 6 s
# (measured at load average 3, 2026-12-01) for no rasteriser feature the other scenes lack.
# Their ray-tracing tests are tests/test_raytrace_scenes.py.
RAYTRACE_SCENES = frozenset({"classic", "cornell_box", "mesh_shadow", "tir_bubble",
                             "depth_of_field", "soft_shadows", "glossy",
                             "motion_blur"})
# The built-in scenes made for shadow maps (issue 15): rasteriser scenes, held in the default
# run like the others; their spheres and floors are analytic shapes so that the ray tracer's
# shadow rays, their truth, see exact surfaces (tests/test_scene_shapes.py).
SHADOW_SCENES = frozenset({"shadow_plane", "shadow_room", "shadow_curved"})
# The built-in scenes made for textures (issue 17). The rasteriser's tests over every built-in
# scene hold them in the full run, as the ray tracer's: in the default run they would add
# about 5 s (goldens, determinism, specialisation: measured at load average 2, 2026-12-02),
# where tests/test_texture_raster.py and tests/test_shadow_shading.py hold the textured path,
# GPU against the twin, on small cases in 2 s. Their own bar (every filter, both contexts,
# 320 x 240) is tests/test_texture_raster.py's full run.
TEXTURE_SCENES = frozenset({"textured_mesh", "checker_horizon", "globe"})
# The built-in scenes made for the shadow maps' failure modes (issue 28): concave corners,
# thin casters in contact, a huge receiver, a low-poly smooth sphere under a grazing light, a
# caster sunk into its receiver. tests/test_shadow_truth.py holds them to ray-cast truth (every
# filter; 320 x 240, 640 x 480 in the full run); the rasteriser's tests over every built-in
# scene hold them in the full run, as the texture scenes: they draw nothing the shadow scenes
# above do not draw in the default run.
SHADOW_CASE_SCENES = frozenset({"shadow_boxes", "shadow_thin_contact", "shadow_big_floor",
                                "shadow_lowpoly_sphere", "shadow_knot_floor"})
# The built-in scenes made for `--method radiosity` (issue 33): lit by emitting surfaces, which
# the rasteriser does not read (it shows them by their ambient term), or by the sun through a
# window (radiosity_window); the rasteriser's tests over every built-in scene hold them in the
# full run only, as the ray tracer's scenes.
# Their radiosity tests are tests/test_radiosity_method.py and their goldens tests/test_goldens.py.
# The built-in scenes made for the rasteriser's tessellation stages (issue 34): analytic spheres
# and meshes as PN triangles or displaced by a height image drawn through them, and no ray-tracer
# terms (tests/test_tessellation_raster.py, tests/test_pn_triangles.py, tests/test_displacement.py).
TESSELLATION_SCENES = frozenset({"tessellated_sphere", "pn_triangles", "displaced_plane"})
RADIOSITY_SCENES = frozenset({"radiosity_furnace", "radiosity_plates", "cornell_box_radiosity", "radiosity_window",
                              "radiosity_specular"})


def raster_scene_params(names, ids=None):
    """pytest.param for each case of a rasteriser test over built-in scenes: `names` are scene
    names, or tuples whose first item is one; a ray-tracing or texture scene's case is marked
    slow (as a shadow case scene's, SHADOW_CASE_SCENES)."""
    params = []
    for index, case in enumerate(names):
        name = case[0] if isinstance(case, tuple) else case
        marks = ([pytest.mark.slow] if name in RAYTRACE_SCENES | TEXTURE_SCENES | SHADOW_CASE_SCENES
                 | RADIOSITY_SCENES else [])
        params.append(pytest.param(*(case if isinstance(case, tuple) else (case,)), marks=marks,
                                   id=None if ids is None else ids[index]))
    return params


# -- GL contexts and the virtual display --------------------------------------------------------

@pytest.fixture(scope="session")
def gl_contexts():
    """{"egl": ctx, "osmesa": ctx}. Both must start: CI installs both (install.sh)."""
    contexts = {kind: make_context(kind) for kind in CONTEXT_KINDS}
    yield contexts
    for ctx in contexts.values():
        ctx.release()


@pytest.fixture(scope="session")
def x_display():
    """A virtual X display (Xvfb) for the window viewer's tests, ":N". It must start: CI
    installs xvfb (install.sh). A test using it is marked `window`."""
    from renderer.viewer.virtual_display import virtual_display
    with virtual_display() as display:
        yield display


@pytest.fixture
def on_x_display(x_display, monkeypatch):
    """DISPLAY set to the virtual display for this test (glfw reads it when it starts)."""
    monkeypatch.setenv("DISPLAY", x_display)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    return x_display


# -- the command line ---------------------------------------------------------------------------

@pytest.fixture(scope="session")
def cli():
    """cli(*args, cwd=None, display=None, timeout=CLI_TIMEOUT_S): `python -m renderer ARGS`
    in a new process, as a user types it; returns the CompletedProcess (text stdout, stderr).

    cwd      the folder it runs in (default: this process's);
    display  None: no display (DISPLAY and WAYLAND_DISPLAY removed: every command but `view`
             works without one, and `view` says so); ":N": that X display;
    timeout  seconds until it is killed and the test fails.
    Arguments may be paths."""
    def run(*args, cwd=None, display=None, timeout=CLI_TIMEOUT_S) -> subprocess.CompletedProcess:
        env = {key: value for key, value in os.environ.items()
               if key not in ("DISPLAY", "WAYLAND_DISPLAY")}
        if display is not None:
            env["DISPLAY"] = display
        return subprocess.run([sys.executable, "-m", "renderer", *map(str, args)],
                              capture_output=True, text=True, cwd=cwd, env=env, timeout=timeout)
    return run


@pytest.fixture
def gpu_stand_in(monkeypatch):
    """gpu_stand_in(frame): from now on, in this test, the command line's GPU render
    (renderer.cli.compare._render_gpu, which `compare` calls) hands back
    `frame` instead of drawing, so that `renderer.cli.main([...])` can be run in-process on a
    frame made to order (e.g. a reference frame with some pixels changed)."""
    from renderer.cli import compare
    from renderer.core.gl_rules import SUBPIXEL_BITS

    def stand_in(frame):
        def render(scene, args, frames=1):
            assert frame.size == tuple(args.size), "the stand-in frame has another size"
            return frame, 1.0, {"GL_RENDERER": "llvmpipe (stand-in)", "context": "stand-in"}, SUBPIXEL_BITS
        monkeypatch.setattr(compare, "_render_gpu", render)
    return stand_in


@pytest.fixture
def cli_here(monkeypatch):
    """cli_here(*args, cwd=None): like `cli`, but renderer.cli.main in this process (tens of
    milliseconds instead of half a second), for what does not need a process of its own; a
    Python warning counts as a line on stderr, as a real process prints it. Returns a
    CompletedProcess (text stdout, stderr)."""
    import contextlib
    import io
    import warnings

    from renderer.cli import main

    def run(*args, cwd=None) -> subprocess.CompletedProcess:
        argv = [str(arg) for arg in args]
        out, err = io.StringIO(), io.StringIO()
        with monkeypatch.context() as here:
            if cwd is not None:
                here.chdir(cwd)
            with warnings.catch_warnings(record=True) as caught, \
                    contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                warnings.simplefilter("always")
                status = main(argv)
        stderr = err.getvalue() + "".join(
            warnings.formatwarning(w.message, w.category, w.filename, w.lineno) for w in caught)
        return subprocess.CompletedProcess(argv, status, out.getvalue(), stderr)
    return run


# -- Ray ----------------------------------------------------------------------------------------

@pytest.fixture(scope="session")
def _local_ray():
    """One local Ray for the whole run (~4 s and ~630 MiB to start, ~1.4 s to stop): every
    test that uses it is in one xdist group (pytest_itemcollected), so one process holds it."""
    from renderer.cluster.ray_executor import LocalRay
    local = LocalRay(RAY_TEST_CPUS)
    try:
        yield local
    finally:
        local.stop()


@pytest.fixture(scope="module")
def ray_executor(request, _local_ray):
    """ray_executor(workers=RAY_TEST_CPUS): a RayExecutor on the run's local Ray (_local_ray),
    started once and stopped after the last test that uses it; each executor's close() leaves
    that Ray running. `ray_executor.address` is its HOST:PORT, for a command line in another
    process (`--address`). The test module's own classes and functions travel to the actors
    by value (a Ray worker process cannot import a test module). Tests using it are marked
    slow (pytest_itemcollected). Ray is imported here, never at the top of this file: `import
    ray` alone takes ~0.6 s."""
    import ray
    from renderer.cluster.ray_executor import RayExecutor

    ray.cloudpickle.register_pickle_by_value(request.module)

    def executor(workers: int = RAY_TEST_CPUS) -> RayExecutor:
        return RayExecutor(workers=workers)

    executor.address = _local_ray.address
    try:
        yield executor
    finally:
        ray.cloudpickle.unregister_pickle_by_value(request.module)


# -- reference frames ---------------------------------------------------------------------------

@pytest.fixture(scope="session")
def reference_frames():
    """reference_frames(scene, width, height, *, shading=None, **options): the Frame of
    `reference.render(scene, width, height, **options)`, rendered once per test run.

    `scene` is a built-in scene's name or a scene file; `shading` renders every material
    flat, gouraud or phong (Scene.with_shading). Frames are cached by scene, shading, size
    and options, and their arrays are read-only: a test that changes one copies it first."""
    import reference
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene

    frames = {}

    def frame(scene, width: int, height: int, *, shading: str | None = None, **options):
        path = Path(resolve_scene(str(scene))).resolve()
        key = (path, shading, width, height, tuple(sorted(options.items())))
        if key not in frames:
            loaded = load_scene(path)
            if shading is not None:
                loaded = loaded.with_shading(shading)
            frames[key] = read_only(reference.render(loaded, width, height, **options))
        return frames[key]

    return frame


def read_only(frame):
    """The frame, its arrays made read-only (a frame shared by tests is not changed by one)."""
    for field in fields(frame):
        value = getattr(frame, field.name)
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return frame


class TracedReferences:
    """The NumPy ray tracer's view of the built-in scenes, each piece made once per test run:
    scene(name) the loaded Scene, ray_scene(name) its packed ray scene (the BVH built once:
    about a second for mesh_shadow's 5,040 triangles), frame(name, width, height, **options)
    reference.raytrace.pipeline.render's Frame, its arrays read-only."""

    def __init__(self):
        self._scenes, self._ray_scenes, self._frames = {}, {}, {}

    def scene(self, name: str):
        from renderer.core.scene_file import load_scene
        if name not in self._scenes:
            self._scenes[name] = load_scene(name)
        return self._scenes[name]

    def ray_scene(self, name: str):
        from renderer.core.raytrace_scene import ray_scene
        if name not in self._ray_scenes:
            self._ray_scenes[name] = ray_scene(self.scene(name))
        return self._ray_scenes[name]

    def frame(self, name: str, width: int, height: int, **options):
        from reference.raytrace.pipeline import render
        key = (name, width, height, tuple(sorted(options.items())))
        if key not in self._frames:
            self._frames[key] = read_only(render(self.scene(name), width, height,
                                                 rs=self.ray_scene(name), **options))
        return self._frames[key]


@pytest.fixture(scope="session")
def traced_references():
    """A TracedReferences: the NumPy ray tracer's scenes and frames, made once per test run."""
    return TracedReferences()


# -- the output stage ---------------------------------------------------------------------------

@pytest.fixture(scope="session")
def output_passes(gl_contexts):
    """{"egl": OutputPass, "osmesa": OutputPass}: the GPU output stage on each context, made
    once per test run (its programs and tables are kept across tests, as in a viewer)."""
    from renderer.gpu.output import OutputPass
    passes = {kind: OutputPass(ctx) for kind, ctx in gl_contexts.items()}
    yield passes
    for output_pass in passes.values():
        output_pass.release()
