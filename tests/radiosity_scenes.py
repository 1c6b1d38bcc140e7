"""Small radiosity scenes for the tests, built from world triangles (renderer/core/radiosity_elements.py
takes them as its meshes give them): a closed box seen from inside, two facing squares, two
squares at right angles, and a room with a box and a ball in it."""

import numpy as np

from renderer.core import primitives
from renderer.core.radiosity_elements import Elements, mesh_elements, mesh_triangles
from renderer.core.transforms import rotate_y, translate


def quad(origin, u, v) -> np.ndarray:
    """(2, 3, 3): the parallelogram origin + [0, 1] u + [0, 1] v, front towards u x v."""
    o, u, v = (np.asarray(x, float) for x in (origin, u, v))
    return np.array([[o, o + u, o + u + v], [o, o + u + v, o + v]])


def closed_box(side: float = 1.0) -> np.ndarray:
    """(12, 3, 3): the six faces of [0, side]^3, each front facing in."""
    s = side
    x, y, z = np.eye(3) * s
    o = np.zeros(3)
    return np.concatenate([quad(o, x, y), quad(z, y, x),          # z = 0 facing +z, z = s facing -z
                           quad(o, z, x), quad(y, x, z),          # y = 0, y = s
                           quad(o, y, z), quad(x, z, y)])         # x = 0, x = s


def parallel_squares(side=1.0, gap=1.0) -> np.ndarray:
    """Two coaxial side x side squares `gap` apart, facing each other (Howell's C-11)."""
    s = side
    return np.concatenate([quad((0, 0, 0), (s, 0, 0), (0, s, 0)),
                           quad((0, 0, gap), (0, s, 0), (s, 0, 0))])


def perpendicular_squares(side=1.0) -> np.ndarray:
    """A square on z = 0 facing +z and one on y = 0 facing +y, sharing the edge along x
    (Howell's C-14)."""
    s = side
    return np.concatenate([quad((0, 0, 0), (s, 0, 0), (0, s, 0)),
                           quad((0, 0, 0), (0, 0, s), (s, 0, 0))])


def furnished_room() -> tuple[np.ndarray, np.ndarray]:
    """(triangles, object): a closed 3 x 3 x 3 room (object 0), a turned cube on legs of air
    (object 1) and an icosphere (object 2), nothing touching."""
    cube = primitives.cube(0.8)
    cube_triangles, _ = mesh_triangles(cube.positions, cube.faces, cube.normals,
                                       translate(1.0, 0.45, 1.2) @ rotate_y(0.4))
    ball = primitives.icosphere(0.5, 2)
    ball_triangles, _ = mesh_triangles(ball.positions, ball.faces, ball.normals, translate(2.0, 0.55, 2.0))
    triangles = np.concatenate([closed_box(3.0), cube_triangles, ball_triangles])
    obj = np.repeat([0, 1, 2], [12, len(cube_triangles), len(ball_triangles)])
    return triangles, obj


def elements_of(triangles, obj, size, reflectance=0.5, emission=0.0) -> Elements:
    corners, owner = mesh_elements(triangles, obj, size)
    count = len(corners)
    return Elements(corners, owner, np.full((count, 3), reflectance, float),
                    np.full((count, 3), emission, float))
