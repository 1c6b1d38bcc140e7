"""The BVH's build time and its speed-up over brute force on the 20,480-triangle icosphere, printed.

    .venv/bin/python benchmarks/bench_bvh.py [--rays 4096] [--brute-rays 256] [--context egl]
    .venv/bin/python benchmarks/bench_bvh.py --builds [--recursive]

--builds: the build alone (issue 32) on generated meshes of about 5k, 131k and 1M triangles
(the torus knot of tools/make_meshes.py at three resolutions, an icosphere, a randomly
perturbed grid): median seconds of 3 builds (5 above 500k triangles), nodes, depth and the
tree's SAH cost (traversal and intersection cost 1: the sum over nodes of their area over the
root's, a leaf's times its triangles); --recursive times the node-at-a-time build it replaced
(tests/bvh_recursive.py) beside it, once (a minute or more at a million triangles), with its
SAH cost and whether the trees agree. Written to benchmarks/results/bvh.json and .md.

Builds the BVH of icosphere(subdivisions=5) (renderer/core/bvh.py) and times the closest hit of
seeded random rays (a third from inside the sphere, a third aimed at it, a third anywhere):
- twin (NumPy, reference/raytrace/bvh.py): the BVH's wavefront traversal against brute force
  (every ray against every triangle, closest_hit_brute_force) on --brute-rays of the rays;
- GPU (llvmpipe, glsl/raytrace/bvh.glsl through tests/glsl/raytrace_bvh.frag): the BVH against
  a shader that loops over every triangle (tests/glsl/raytrace_brute.frag).
Rays per second are the median of 3 runs (brute force: 1). Not a test: this machine is shared
and noisy.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from reference.raytrace.bvh import closest_hit, closest_hit_brute_force
from renderer.core.bvh import build_bvh, mesh_vertices
from renderer.core.primitives import icosphere
from renderer.gpu.bvh import bvh_textures
from renderer.gpu.context import make_context
from renderer.gpu.shaders import shader_source

from common import machine, write_results                         # benchmarks/common.py

GLSL = Path(__file__).resolve().parent.parent / "tests" / "glsl"
F32 = np.float32


def rays(count: int, seed: int = 20):
    rng = np.random.default_rng(seed)
    O = rng.uniform(-1.5, 1.5, (count, 3)).astype(F32)
    D = rng.normal(size=(count, 3)).astype(F32)
    O[::3] *= F32(0.5)
    D[1::3] = -O[1::3] + rng.normal(scale=0.3, size=D[1::3].shape).astype(F32)
    return O, D


def timed(function, repeats: int):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def gpu_pass(ctx, fragment: str, O, D, bvh, width: int):
    """A callable that traces the rays (count a multiple of width) on the GPU, and its cleanup."""
    height = len(O) // width
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=shader_source(fragment, directory=GLSL).text)
    textures = [ctx.texture((width, height), 3, a[: width * height].tobytes(), dtype="f4") for a in (O, D)]
    nodes, triangles = bvh_textures(ctx, bvh)
    textures += [nodes, triangles]
    output = ctx.texture((width, height), 4, dtype="f4")
    framebuffer = ctx.framebuffer([output])
    vao = ctx.vertex_array(program, [])
    for unit, (texture, name) in enumerate(zip(textures, ("u_origins", "u_directions", "u_nodes", "u_triangles"))):
        texture.filter = (ctx.NEAREST, ctx.NEAREST)
        texture.use(unit)
        if program.get(name, None) is not None:
            program[name].value = unit
    program["u_s_min"].value = 0.0
    program["u_s_max"].value = 1e30
    if program.get("u_count", None) is not None:
        program["u_count"].value = len(bvh.triangles)

    def run():
        framebuffer.use()
        vao.render(vertices=3)
        return np.frombuffer(output.read(), F32).reshape(-1, 4)

    def release():
        for thing in (vao, framebuffer, program, *textures, output):
            thing.release()
    return run, release


def sah_cost(bvh) -> float:
    """The tree's SAH cost (the module docstring)."""
    d = bvh.bounds_max.astype(np.float64) - bvh.bounds_min
    area = d[:, 0] * d[:, 1] + d[:, 1] * d[:, 2] + d[:, 2] * d[:, 0]
    weight = np.where(bvh.is_leaf, bvh.nodes[:, 1, 3], 1.0)
    return float((area * weight).sum() / area[0])


def build_meshes():
    """(name, (T, 3, 3) float32) of the generated meshes --builds times."""
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
    from make_meshes import torus_knot
    out = []
    for segments, sides in ((160, 16), (512, 128), (2048, 256)):
        positions, _, faces = torus_knot(segments=segments, sides=sides)
        out.append((f"torus knot {segments}x{sides}", mesh_vertices(positions, faces)))
    for level in (3, 5, 8):
        mesh = icosphere(subdivisions=level)
        out.append((f"icosphere({level})", mesh_vertices(mesh.positions, mesh.faces)))
    n = 724                                     # 2 n^2 = 1,048,352 triangles
    rng = np.random.default_rng(32)
    x, y = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(n + 1, dtype=float))
    z = rng.normal(scale=0.3, size=x.shape)
    points = np.stack([x + rng.uniform(-0.3, 0.3, x.shape), y + rng.uniform(-0.3, 0.3, x.shape), z], -1)
    a, b, c, d = points[:-1, :-1], points[:-1, 1:], points[1:, :-1], points[1:, 1:]
    grid = np.concatenate([np.stack([a, b, c], -2), np.stack([b, d, c], -2)]).reshape(-1, 3, 3)
    out.append(("perturbed grid", grid.astype(F32)))
    return out


def builds(recursive: bool) -> None:
    """The builds' table, printed; written to benchmarks/results/bvh.json and .md."""
    if recursive:
        import sys
        sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
        from bvh_recursive import build_bvh_recursive
    print(machine())
    print(f"{'mesh':24} {'triangles':>10} {'build s':>8} {'nodes':>8} {'depth':>5} {'SAH cost':>9}"
          + (f" {'recursive s':>11} {'its SAH':>8} {'same tree':>9}" if recursive else ""))
    rows = []
    for name, V in build_meshes():
        repeats = 3 if len(V) < 500_000 else 5
        seconds, bvh = timed(lambda: build_bvh(V), repeats)
        row = {"mesh": name, "triangles": len(V), "build_s": round(seconds, 3), "repeats": repeats,
               "nodes": len(bvh.nodes), "depth": bvh.depth, "sah": round(sah_cost(bvh), 2)}
        line = (f"{name:24} {len(V):>10,} {seconds:>8.2f} {len(bvh.nodes):>8,} {bvh.depth:>5} "
                f"{sah_cost(bvh):>9.1f}")
        if recursive:
            old_seconds, old = timed(lambda: build_bvh_recursive(V), 1)
            same = ((old.nodes + 0.0).tobytes() == (bvh.nodes + 0.0).tobytes()
                    and old.triangles.tobytes() == bvh.triangles.tobytes())
            row.update(recursive_s=round(old_seconds, 2), recursive_sah=round(sah_cost(old), 2), same_tree=same)
            line += f" {old_seconds:>11.2f} {sah_cost(old):>8.1f} {str(same):>9}"
        rows.append(row)
        print(line, flush=True)
    print(f"wrote {write_results('bvh', {'rows': rows, 'recursive': recursive}, markdown)}")


def markdown(document: dict) -> str:
    """docs/ray-tracing.md's table of BVH builds, from a results document (write_results)."""
    figures = document["figures"]
    recursive = figures["recursive"]
    lines = ["The build alone (renderer/core/bvh.py `build_bvh`), median of the runs shown; SAH cost: the "
             "sum over nodes of their surface area over the root's, a leaf's times its triangles"
             + ("; beside it the node-at-a-time build it replaced (tests/bvh_recursive.py), one run." if recursive
                else "."), "",
             "| mesh | triangles | build | runs | nodes | depth | SAH cost |"
             + (" node at a time | its SAH cost | same tree |" if recursive else ""),
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: |" + (" ---: | ---: | --- |" if recursive else "")]
    for row in figures["rows"]:
        line = (f"| {row['mesh']} | {row['triangles']:,} | {row['build_s']:.2f} s | {row['repeats']} | "
                f"{row['nodes']:,} | {row['depth']} | {row['sah']:.1f} |")
        if recursive:
            line += (f" {row['recursive_s']:.1f} s | {row['recursive_sah']:.1f} | "
                     f"{'yes' if row['same_tree'] else 'no'} |")
        lines.append(line)
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rays", type=int, default=4096)
    parser.add_argument("--brute-rays", type=int, default=256)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    parser.add_argument("--builds", action="store_true", help="the build alone, on 5k to 1M triangles")
    parser.add_argument("--recursive", action="store_true", help="with --builds: the old build beside it")
    args = parser.parse_args()
    if args.builds:
        builds(args.recursive)
        return

    mesh = icosphere(subdivisions=5)
    V = mesh_vertices(mesh.positions, mesh.faces)
    build_s, bvh = timed(lambda: build_bvh(V), 1)
    print(f"icosphere(5): {len(V)} triangles; BVH build {build_s:.2f} s: {len(bvh.nodes)} nodes, "
          f"depth {bvh.depth}, {int(bvh.is_leaf.sum())} leaves")

    O, D = rays(args.rays)
    t_bvh, (hit, s, _, tri) = timed(lambda: closest_hit(bvh, O, D), 3)
    n = args.brute_rays
    t_brute, (hit_b, s_b, _, tri_b) = timed(lambda: closest_hit_brute_force(V, O[:n], D[:n]), 1)
    agree = (hit[:n] == hit_b).all() and (s[:n][hit_b] == s_b[hit_b]).all()
    twin_bvh, twin_brute = len(O) / t_bvh, n / t_brute
    print(f"twin (NumPy): BVH {twin_bvh:,.0f} rays/s, brute force {twin_brute:,.0f} rays/s, "
          f"speed-up {twin_bvh / twin_brute:.0f}x (hit rate {hit.mean():.2f}; same hits: {agree})")

    ctx = make_context(args.context)
    width = 64
    run, release = gpu_pass(ctx, "raytrace_bvh.frag", O, D, bvh, width)
    run()                                                   # compile and warm up
    t_gpu, out = timed(run, 3)
    release()
    count = (len(O) // width) * width
    brute_count = max(width, (n // width) * width)
    run, release = gpu_pass(ctx, "raytrace_brute.frag", O[:brute_count], D[:brute_count], bvh, width)
    t_gpu_brute, out_b = timed(run, 1)
    release()
    same = (out[: brute_count, 1] == out_b[:, 1]).mean()
    gpu_bvh, gpu_brute = count / t_gpu, brute_count / t_gpu_brute
    print(f"GPU ({args.context}, llvmpipe): BVH {gpu_bvh:,.0f} rays/s, brute force "
          f"{gpu_brute:,.0f} rays/s, speed-up {gpu_bvh / gpu_brute:.0f}x "
          f"(same triangle as brute force: {same:.3f})")
    ctx.release()


if __name__ == "__main__":
    main()
