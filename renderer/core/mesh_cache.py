"""A cache of what is computed from a Mesh once: a mesh is not changed in place (a renderer
uploads a new Mesh object, docs/conventions.md), so a result is kept for as long as its Mesh
object lives, and forgotten with it."""

from __future__ import annotations

import functools
import weakref


def per_mesh(function):
    """Decorate `function(mesh)` so that it runs once per Mesh object (by identity)."""
    cache: dict[int, tuple[weakref.ref, object]] = {}

    @functools.wraps(function)
    def cached(mesh):
        key = id(mesh)
        hit = cache.get(key)
        if hit is not None and hit[0]() is mesh:
            return hit[1]
        result = function(mesh)
        cache[key] = (weakref.ref(mesh, lambda _ref, key=key: cache.pop(key, None)), result)
        return result
    return cached
