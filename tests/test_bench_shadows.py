"""benchmarks/bench_shadows.py runs: at a tiny size, --quick, it prints a row per scene with
its three frame times and ratios, the machine and the line that reproduces it (the figures
themselves are the benchmark's to print, never a test's to assert)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_the_shadow_benchmark_prints_a_row_per_scene_and_how_to_reproduce_it():
    result = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_shadows.py"), "--quick",
                             "--size", "64x48", "--scenes", "shadow_plane,shadow_room"],
                            capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    number = r"\d+\.\d+"
    rows = [line for line in lines if re.match(rf"shadow_(plane|room) .* {number} +{number} +{number} +"
                                               rf"{number}x +{number}x +(yes|NO) ", line)]
    assert [row.split()[0] for row in rows] == ["shadow_plane", "shadow_room"]
    assert "128 (1x128²), 1 passes" in rows[0]                # auto resolution: 2 x 64 texels
    assert "64x6 (6x64²)" in rows[1]                          # a point light's cube, 6 layers
    assert any("load average" in line for line in lines)
    assert lines[-1] == ("Reproduce: .venv/bin/python benchmarks/bench_shadows.py --size 64x48 "
                         "--quick --scenes shadow_plane,shadow_room --context egl")
