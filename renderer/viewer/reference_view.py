"""The viewer's reference view: the NumPy reference render of the current view, made in a
background process so that the window stays responsive while it runs (reference/pipeline.py
takes tens to hundreds of milliseconds a frame; a thread would share the GIL with the
window's loop).

    background = BackgroundReference()
    background.request(scene, width, height, version)   # the view as it is now
    done = background.poll()      # None, or (version, reference Frame) once one is ready
    background.close()

Only the newest request matters: while one render runs, a newer request waits in its place
(older waiting ones are dropped), and a result is handed out with the version it was asked
for, so the viewer compares it only with a GPU image of the same view.
"""

from __future__ import annotations

import multiprocessing
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from renderer.checks.compare import compare_frames, heat_map


def _render_reference(scene, width: int, height: int):
    """Runs in the worker process (spawned: it shares nothing with the window's GL)."""
    from renderer.methods import open_renderer
    frame = open_renderer(scene, (width, height), backend="reference").render(depth=False)
    return frame.rgba8, getattr(frame, "rgba8_tie", None), frame.milliseconds


@dataclass
class ReferenceResult:
    version: int
    rgba8: np.ndarray              # (H, W, 4) uint8, row 0 at the top
    rgba8_tie: np.ndarray | None   # the other surface's colour at depth ties (renderer/checks/compare.py)
    milliseconds: float


class BackgroundReference:
    """One worker process that renders the newest requested view; see the module docstring."""

    def __init__(self):
        self._pool: ProcessPoolExecutor | None = None
        self._running: tuple[int, Future] | None = None
        self._waiting: tuple | None = None          # (version, scene, width, height)
        self._done: ReferenceResult | None = None

    def request(self, scene, width: int, height: int, version: int) -> None:
        """Ask for the reference of `scene` at width x height, tagged `version`."""
        self._waiting = (version, scene, width, height)
        self._start_waiting()

    def _start_waiting(self) -> None:
        if self._running is not None or self._waiting is None:
            return
        if self._pool is None:
            # spawn, not fork: a forked child would inherit the window's GL and X connection.
            self._pool = ProcessPoolExecutor(max_workers=1,
                                             mp_context=multiprocessing.get_context("spawn"))
        version, scene, width, height = self._waiting
        self._waiting = None
        self._running = (version, self._pool.submit(_render_reference, scene, width, height))

    @property
    def busy(self) -> bool:
        return self._running is not None or self._waiting is not None

    def poll(self) -> ReferenceResult | None:
        """The newest finished result not handed out yet, or None. Never blocks."""
        if self._running is not None and self._running[1].done():
            version, future = self._running
            self._running = None
            rgba8, tie, milliseconds = future.result()   # a worker's bug is raised here
            self._done = ReferenceResult(version, rgba8, tie, milliseconds)
            self._start_waiting()
        done, self._done = self._done, None
        return done

    def wait(self, timeout: float | None = None) -> ReferenceResult | None:
        """Block until the running and waiting requests are done (scripted runs, tests)."""
        while self._running is not None:
            self._running[1].result(timeout)
            result = self.poll()
            if result is not None and self._running is None:
                return result
        return self.poll()

    def close(self) -> None:
        """Stop the worker at once, even in the middle of a render: otherwise the process
        would wait for it at exit (seconds, for a large window)."""
        if self._pool is not None:
            pool, self._pool = self._pool, None
            if hasattr(pool, "terminate_workers"):           # Python 3.14
                pool.terminate_workers()
            else:
                workers = list(getattr(pool, "_processes", {}).values())
                pool.shutdown(wait=False, cancel_futures=True)
                for process in workers:
                    process.terminate()
                for process in workers:
                    process.join(5)
        self._running = self._waiting = None


def difference_view(gpu_rgba8: np.ndarray, result: ReferenceResult) -> tuple[np.ndarray, dict]:
    """The heat map of the GPU image against the reference (renderer/checks/compare.py's: black where
    equal, red to white up to 8 levels off, magenta where the pixel fails the position-
    deviation compare) and the figures shown beside it."""
    comparison = compare_frames(gpu_rgba8, result.rgba8, reference_tie=result.rgba8_tie)
    image = heat_map(gpu_rgba8, result.rgba8, reference_tie=result.rgba8_tie)
    figures = {"rmse": comparison.rmse, "max_abs": comparison.max_abs,
               "mismatched": comparison.mismatched_pixels,
               "mismatched_fraction": comparison.mismatched_fraction,
               "reference_ms": result.milliseconds}
    return image, figures


def figures_line(figures: dict) -> str:
    return (f"GPU vs reference: rmse {figures['rmse']:.3f}/255, max {figures['max_abs']}/255, "
            f"{figures['mismatched']} mismatched px ({figures['mismatched_fraction']:.2%}); "
            f"reference {figures['reference_ms']:.0f} ms")
