"""Radiosity's form factors from the hemicubes' item buffers (issue 33): F_ij, the share of the
energy leaving element i that arrives at element j directly, summed over the pixels of i's
hemicube that see j's front, each weighing its delta form factor (renderer/core/hemicube.py
`weights`, normalised so that a whole hemicube weighs 1). One definition: the GPU path
(renderer/gpu/item_buffers.py) and its twin (reference/radiosity/item_buffer.py) draw the item
buffers, this module sums them alike, so identical item buffers give identical matrices.

Only the pairs that see each other are stored: rows in compressed sparse row form (`indptr`,
`columns` sorted within a row, `values`), and per row what its hemicube saw of nothing
(`unseen`: an open scene's sky) and of back faces (`backs`: light that is blocked and passes
nothing on). In a closed scene of one-sided surfaces seen from the front, every row sums to 1
exactly (to rounding) and `unseen` and `backs` are 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from renderer.core.hemicube import ITEM_BACK_BIT, ITEM_INDEX_MASK, weights

# rows_from_items sums a batch's pixels by (row, element) key in a dense array when there are at
# most this many keys (16 MiB of float64), else by sorting them.
DENSE_KEYS = 1 << 21

@dataclass(frozen=True)
class FormFactors:
    indptr: np.ndarray           # (E + 1,) int64
    columns: np.ndarray          # (nnz,) int64, ascending within each row
    values: np.ndarray           # (nnz,) float64
    unseen: np.ndarray           # (E,) float64
    backs: np.ndarray            # (E,) float64
    drawn: bool = True           # False: none drawn, the scene needing none (FormFactors.none)

    @classmethod
    def none(cls, elements: int, unseen: float = 0.0) -> "FormFactors":
        """No pair stored and no hemicube drawn: for a scene where light does not bounce
        (renderer/core/radiosity.py interreflects); `unseen` each row's share of nothing (1 for
        one convex solid seen from outside: its hemicubes would see nothing of it)."""
        return cls(np.zeros(elements + 1, np.int64), np.zeros(0, np.int64), np.zeros(0),
                   np.full(elements, float(unseen)), np.zeros(elements), drawn=False)

    def __len__(self) -> int:
        return len(self.indptr) - 1

    @property
    def rows(self) -> np.ndarray:
        """(nnz,) the row of each stored value."""
        return np.repeat(np.arange(len(self)), np.diff(self.indptr))

    def row_sums(self) -> np.ndarray:
        return np.bincount(self.rows, weights=self.values, minlength=len(self))

    def times(self, b: np.ndarray) -> np.ndarray:
        """F @ b for b (E,) or (E, C)."""
        products = self.values.reshape((-1,) + (1,) * (b.ndim - 1)) * b[self.columns]
        if b.ndim == 1:
            return np.bincount(self.rows, weights=products, minlength=len(self))
        return np.stack([np.bincount(self.rows, weights=products[:, c], minlength=len(self))
                         for c in range(b.shape[1])], axis=1)

    def by_column(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The same matrix column by column (compressed sparse column): (colptr (E + 1,),
        rows (nnz,) ascending within a column, values (nnz,)): column j lists the elements
        whose hemicubes see j."""
        order = np.lexsort((self.rows, self.columns))
        colptr = np.concatenate([[0], np.cumsum(np.bincount(self.columns, minlength=len(self)))])
        return colptr, self.rows[order], self.values[order]

    def dense(self) -> np.ndarray:
        """(E, E): for tests and small scenes."""
        matrix = np.zeros((len(self), len(self)))
        matrix[self.rows, self.columns] = self.values
        return matrix

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.indptr, self.columns, self.values, self.unseen, self.backs))


def rows_from_items(items: np.ndarray, resolution: int, elements: int):
    """The rows of the hemicubes whose item buffers are `items` (H, 5, N, N): (row of each
    entry (local, 0 .. H-1), column, value) sorted by row then column, and (H,) unseen and
    backs."""
    table = weights(resolution).ravel()
    h = len(items)
    flat = items.reshape(h, -1)
    index = (flat & ITEM_INDEX_MASK).astype(np.int64)
    front = (index > 0) & ((flat & ITEM_BACK_BIT) == 0)
    weight = np.broadcast_to(table, flat.shape)
    unseen = np.where(index == 0, weight, 0.0).sum(axis=1)
    backs = np.where((index > 0) & ~front, weight, 0.0).sum(axis=1)
    row = np.broadcast_to(np.arange(h)[:, None], flat.shape)[front]
    key = row * (elements + 1) + index[front]
    if h * (elements + 1) <= DENSE_KEYS:         # a dense count is faster than sorting the keys
        sums = np.bincount(key, weights=weight[front], minlength=h * (elements + 1))
        unique = np.flatnonzero(np.bincount(key, minlength=h * (elements + 1)))
        values = sums[unique]
    else:
        unique, inverse = np.unique(key, return_inverse=True)
        values = np.bincount(inverse, weights=weight[front])
    return unique // (elements + 1), unique % (elements + 1) - 1, values, unseen, backs


class RowsDrawn:
    """Form factors gathered a batch of hemicubes at a time, in element order: `add(items)` takes
    the item buffers (H, 5, N, N) of the next H elements' hemicubes; `matrix()` the FormFactors
    once every element's is in (form_factors at once; a viewer a batch a frame,
    renderer/core/radiosity_progressive.py)."""

    def __init__(self, elements: int, resolution: int):
        self.elements, self.resolution = elements, resolution
        self.done = 0
        self._parts = []

    def add(self, items: np.ndarray) -> None:
        row, column, value, unseen, backs = rows_from_items(items, self.resolution, self.elements)
        self._parts.append((row + self.done, column, value, unseen, backs))
        self.done += len(items)

    def next_indices(self, most: int) -> np.ndarray:
        """The next at most `most` elements whose hemicubes are not in yet."""
        return np.arange(self.done, min(self.done + most, self.elements))

    def matrix(self) -> FormFactors:
        if self.done != self.elements:
            raise ValueError(f"{self.done} of {self.elements} hemicubes drawn")
        parts = self._parts or [(np.zeros(0, np.int64),) * 2 + (np.zeros(0),) * 3]
        row, columns, values, unseen, backs = (np.concatenate([p[k] for p in parts]) for k in range(5))
        indptr = np.concatenate([[0], np.cumsum(np.bincount(row, minlength=self.elements))])
        return FormFactors(indptr, columns, values, unseen, backs)


def form_factors(elements: int, resolution: int, draw: Callable[[np.ndarray], np.ndarray],
                 batch: int) -> FormFactors:
    """Every element's row, from its hemicube drawn by `draw(indices)` (item buffers (len, 5,
    N, N), row 0 at the top: the GPU's ItemBuffers.draw or the twin's), `batch` at a time."""
    rows = RowsDrawn(elements, resolution)
    while rows.done < elements:
        rows.add(draw(rows.next_indices(batch)))
    return rows.matrix()
