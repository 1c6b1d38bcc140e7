"""The golden suite's GPU half through the executor: in this process against Ray workers.

    .venv/bin/python benchmarks/bench_golden_spread.py [--workers 2] [--context egl]

The frames that tests/test_goldens.py holds to its raster goldens (every built-in scene in
each shading mode, and as authored where modes mix, at 256x256) are drawn by a worker holding
one GL context (renderer/cluster/executor.py), in batches of executor.batch_size, first in
this process, then on a local Ray of --workers actors; each frame's pixel digest must equal
its golden sidecar's. Printed: wall seconds of each, Ray's included its start and stop.
What pytest-xdist does with the whole suite is in docs/goldens.md ("Spreading the suite").
Not a test: this machine is shared and noisy; the load average is printed.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from common import machine                                # benchmarks/common.py
from renderer.checks.goldens import pixels_sha256
from renderer.cluster.executor import InProcessExecutor, batch_size, batches_of
from renderer.core.builtin import builtin_scenes
from renderer.core.scene import SHADING_MODES
from renderer.core.scene_file import load_scene

GOLDENS = Path(__file__).resolve().parent.parent / "tests" / "goldens"
SIZE = (256, 256)
SECONDS_PER_FRAME = 0.1          # about what a golden frame costs here, for the batch size


def variants() -> list[tuple[str, str]]:
    """(scene, mode) of every raster golden, as tests/test_goldens.py lists them."""
    out = []
    for name in sorted(builtin_scenes()):
        scene = load_scene(builtin_scenes()[name])
        modes = [*SHADING_MODES, *(["as-authored"] if len(scene.shading_modes()) > 1 else [])]
        out += [(name, mode) for mode in modes]
    return out


class GoldenWorker:
    """Draws golden frames on one context; answers each frame's pixels_sha256 (the sidecar's)."""

    def __init__(self, context_kind: str):
        self.context_kind, self.ctx = context_kind, None

    def run(self, batch: list[tuple[str, str]]) -> list[str]:
        from renderer.gpu.context import make_context
        from renderer.methods import open_renderer
        self.ctx = self.ctx or make_context(self.context_kind)
        digests = []
        for name, mode in batch:
            scene = load_scene(builtin_scenes()[name])
            scene = scene if mode == "as-authored" else scene.with_shading(mode)
            with open_renderer(scene, SIZE, context=self.ctx) as gpu:
                digests.append(pixels_sha256(gpu.render(depth=False).rgba8))
        return digests


def timed_run(open_executor, units: list, context_kind: str) -> tuple[float, int]:
    """(wall seconds, workers) of every unit through the executor open_executor() makes."""
    from functools import partial
    start = time.perf_counter()
    with open_executor() as executor:
        batches = batches_of(units, batch_size(SECONDS_PER_FRAME, len(units), executor.workers))
        for index, digests in executor.map(partial(GoldenWorker, context_kind), batches):
            for (name, mode), digest in zip(batches[index], digests):
                sidecar = json.loads((GOLDENS / f"{name}-{mode}.json").read_text())
                assert digest == sidecar["rgba_sha256"], f"{name}-{mode} differs from its golden"
        workers = executor.workers
    return time.perf_counter() - start, workers


def main() -> None:
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    from renderer.cluster.ray_executor import RayExecutor
    units = variants()
    print(machine())
    here, _ = timed_run(InProcessExecutor, units, args.context)
    ray, workers = timed_run(lambda: RayExecutor(workers=args.workers), units, args.context)
    print(f"{len(units)} golden frames at {SIZE[0]}x{SIZE[1]}, each equal to its golden")
    print(f"in this process: {here:.1f} s; on a local Ray of {workers} workers: {ray:.1f} s "
          f"(start and stop included); ratio {here / ray:.2f}")


if __name__ == "__main__":
    main()
