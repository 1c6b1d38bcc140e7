"""What the path tracer's next-event estimation samples (docs/pathtrace.md, "Emitting
surfaces"): the scene's emitting triangles, each chosen with probability in proportion to its
power (area times mean emission), a point on it uniform in area. Made once per scene in float64
and handed to both twins in float32 (glsl/raytrace/pathtrace.glsl through
renderer/gpu/pathtracer.py's textures, reference/raytrace/pathtrace.py), so that both choose
the same triangle from the same number.

An emitting object is *sampled* when its triangles are in the table: a mesh (an analytic sphere
or plane has no triangles; its light is found only by the paths that hit it) that does not move
during the shutter. Every point of a sampled object has the same density per unit area, its
mean emission over the total power (a triangle's probability over its area), which both
strategies' weights read (multiple importance sampling, docs/pathtrace.md): next-event
estimation's and that of a diffuse bounce that hits the emitter. An unsampled emitter has
density 0: a path that hits it counts all its emission.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PathEmitters:
    emission: np.ndarray     # (M, 4) float32 per object: E (exitance, linear RGB), its density
    triangles: np.ndarray    # (K, 3, 3) float32 camera-relative vertices of the sampled triangles
    cdf: np.ndarray          # (K,) float32: the chosen triangle is the first with u < cdf; last 1
    owner: np.ndarray        # (K,) int: the triangle's object

    @property
    def count(self) -> int:
        return int(len(self.cdf))

    def texels(self) -> np.ndarray:
        """(K, 3, 4) float32 rows per triangle: (A, cdf), (B, 0), (C, object)."""
        rows = np.zeros((self.count, 3, 4), np.float32)
        rows[:, :, :3] = self.triangles
        rows[:, 0, 3] = self.cdf
        rows[:, 2, 3] = self.owner
        return rows


def path_emitters(scene, rs) -> PathEmitters:
    """The emitters of `scene` as its ray scene `rs` (renderer/core/raytrace_scene.py) holds
    its triangles (module docstring)."""
    emission = np.array([obj.material.emission for obj in scene.objects], np.float64).reshape(-1, 3)
    emits = (emission > 0).any(axis=1)
    moving = rs.mesh_object[rs.mesh_object >= 0]
    candidate = emits.copy()
    candidate[moving] = False
    chosen = candidate[rs.triangle_object] if len(rs.triangle_object) else np.zeros(0, bool)
    tris = rs.triangles[chosen]
    owner = rs.triangle_object[chosen]
    area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
    power = area * emission[owner].mean(axis=1)
    keep = power > 0
    tris, owner, area, power = tris[keep], owner[keep], area[keep], power[keep]
    density = np.zeros(len(emission))
    if len(power):
        density[owner] = emission[owner].mean(axis=1) / power.sum()
    table = np.concatenate([emission, density[:, None]], axis=1).astype(np.float32)
    if not len(power):
        return PathEmitters(table, np.zeros((0, 3, 3), np.float32), np.zeros(0, np.float32),
                            np.zeros(0, np.int64))
    cdf = np.cumsum(power / power.sum()).astype(np.float32)
    cdf[-1] = 1.0                    # u < 1 always chooses some triangle
    return PathEmitters(table, tris.astype(np.float32), cdf, owner)
