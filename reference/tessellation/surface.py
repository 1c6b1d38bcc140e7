"""# Twin: glsl/tess_control.glsl, glsl/tess_evaluation.glsl (the stages together)

A tessellated object's triangles as the camera pass draws them through the tessellation
stages (issue 34): its patches (renderer/core/tessellation.py: a sphere's patch_mesh, a mesh's
pn_patches), each patch's levels (reference/tessellation/control.py; a PN patch's net too),
the tessellator's points and triangles
(reference/tessellation/tessellator.py), each point placed on the surface
(reference/tessellation/evaluation.py), patch after patch in draw order, so that the vertex
stage's twin (reference/vertex.py) then runs on the points as the evaluation stage runs
glsl/vertex_stage.glsl on them.

Inputs: the object (its shape and Tessellation), its camera-relative model matrix, the frame's
view and projection matrices and height (renderer/core/uniforms.py tessellation_uniforms).
Output: (positions (P, 3), normals (P, 3)) float32 object space and faces (T, 3) int64.
"""

from __future__ import annotations

import numpy as np

from reference.tessellation.control import (ControlUniforms, displaced_patch_levels, displaced_tangents,
                                            patch_levels, pn_net, pn_patch_levels)
from reference.tessellation.evaluation import evaluate, evaluate_displaced, evaluate_pn
from reference.tessellation.tessellator import tess_coord, tessellate
from reference.texture import lookup_coordinates
from renderer.core.tessellation import check_tessellated, displaced_patches, patch_mesh, pn_patches
from renderer.core.uniforms import tessellation_uniforms


def control_stage(obj, object_matrices, view: np.ndarray, projection: np.ndarray, height: int):
    """The control stage's work on the object's patches: (their levels (P, 4) float32, and a
    function of (patch, tess coords) giving the evaluation stage's points and normals)."""
    check_tessellated(obj)
    values = tessellation_uniforms(obj, object_matrices, height)
    u = ControlUniforms(object_matrices.model, view, projection, float(values["u_viewport_height"]),
                        float(values["u_target_error"]), float(values["u_surface_radius"]),
                        float(values["u_max_level"]), float(values["u_fixed_level"]))
    sphere = values["u_sphere"]
    surface = obj.tessellation.surface
    if surface == "displaced":
        corners, normals, uv = displaced_patches(obj.mesh)
        displacement = obj.tessellation.displacement
        uvs = lookup_coordinates(uv.reshape(-1, 2), values["u_height_uv_scale"],
                                 values["u_height_uv_offset"]).reshape(uv.shape)
        tangent_s, tangent_t = displaced_tangents(corners, uvs)
        levels = displaced_patch_levels(corners, normals, uvs, u, values["u_height_size"],
                                        float(values["u_height_slope"]), float(values["u_displacement_scale"]))
    elif surface == "pn_triangles":
        net = pn_patches(obj.mesh)
        corners, normals = net.positions, net.normals
        offsets, centres, mids = pn_net(corners, normals, net.straight)
        levels = pn_patch_levels(corners, offsets, centres, u)
    else:
        patches = patch_mesh(obj.shape)
        corners = patches.positions[patches.faces].astype(np.float32)
        normals = patches.normals[patches.faces].astype(np.float32)
        levels = patch_levels(corners, u)

    def evaluation_stage(patch: int, coords: np.ndarray):
        def each(value):
            return np.broadcast_to(value[patch], (len(coords), *value.shape[1:]))
        if surface == "displaced":
            return evaluate_displaced(coords, each(corners), each(normals), each(uvs), each(tangent_s),
                                      each(tangent_t), displacement.texture, displacement.scale)
        if surface == "pn_triangles":
            return evaluate_pn(coords, each(corners), each(normals), each(offsets), each(centres), each(mids))
        return evaluate(coords, each(corners), each(normals), (sphere[:3], sphere[3]))
    return levels, evaluation_stage


def tessellated_mesh(obj, object_matrices, view: np.ndarray, projection: np.ndarray, height: int):
    """The object's generated points, normals and triangles (module docstring)."""
    levels, evaluation_stage = control_stage(obj, object_matrices, view, projection, height)
    positions, shading_normals, faces, offset = [], [], [], 0
    for patch, level in enumerate(levels):
        t = tessellate("triangles", obj.tessellation.spacing, level[:3], level[3:])
        coords = tess_coord(t)
        p, n = evaluation_stage(patch, coords)
        positions.append(p)
        shading_normals.append(n)
        faces.append(np.asarray(t.indices, np.int64).reshape(-1, 3) + offset)
        offset += len(coords)
    return (np.concatenate(positions), np.concatenate(shading_normals),
            np.concatenate(faces) if faces else np.zeros((0, 3), np.int64))


def levels_in_view(scene, width: int, height: int) -> list[tuple[str, float, float]]:
    """(name, least, largest level) of each tessellated object as the camera pass draws it at
    width x height (outer and inner levels of all its patches): the viewer's title."""
    matrices = scene.matrices(width, height)
    out = []
    for obj, object_matrices in zip(scene.objects, matrices.objects):
        if obj.tessellation is not None:
            levels, _ = control_stage(obj, object_matrices, matrices.view, matrices.projection, height)
            out.append((obj.name, float(levels.min()), float(levels.max())))
    return out
