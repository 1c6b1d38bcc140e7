"""Solving the radiosity equation (notes 2, indirect illumination; issue 33) for each element i
and colour channel:

    B_i = E_i + rho_i sum_j F_ij B_j

with the form factors of renderer/core/form_factors.py. Two solvers, both reporting a residual
per iteration:

- Gauss-Seidel (`gauss_seidel`): sweep the rows in order, each B_i from the newest values of
  the others. Converges for rho < 1 and row sums <= 1 (the matrix I - rho F is then diagonally
  dominant); the error shrinks about as rho^2 a sweep here, so slowly when rho is near 1 (the
  stiff case: the solution grows as 1 / (1 - rho)). Residual of a sweep: the largest change it
  made, which is each row's residual E_i + rho_i (F B)_i - B_i just before its update (no
  extra product with F a sweep); `residual()` gives the whole residual of a solution.
- Direct (`direct`): the dense system (I - diag(rho) F) B = E solved by LAPACK's LU
  (numpy.linalg.solve), one right-hand side a channel: exact to rounding whatever rho, for as
  many elements as an E x E matrix of float64 fits in memory (the stiff cases' answer).
- Progressive refinement (`progressive`; Cohen, Chen, Wallace and Greenberg, "A Progressive
  Refinement Approach to Fast Radiosity Image Generation", SIGGRAPH 1988): repeatedly shoot
  the unshot radiosity dB_i of the element with the most unshot power (area times unshot
  radiosity, summed over the channels) to every element j that sees it, B_j += rho_j F_ji dB_i
  and dB_j likewise. The paper draws the shooter's hemicube as it shoots and takes F_ji =
  F_ij A_i / A_j by reciprocity; here every hemicube is drawn before solving, so F_ji is read
  from column i (j's own hemicube) and no reciprocity is assumed: the shots are then Southwell
  relaxation of the same equation as Gauss-Seidel's (dB is its residual E + rho F B - B), and
  both converge to the same B (with the paper's reciprocity they would differ by the
  hemicube's reciprocity error). Residual: the unshot power left, after each shot. For
  display before it converges, the ambient term (`ambient`) spreads the unshot power over the
  room as the paper does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from renderer.core.form_factors import FormFactors


@dataclass
class Solution:
    radiosity: np.ndarray                      # (E, C)
    residuals: list = field(default_factory=list)   # one per iteration (sweep or shot)
    unshot: np.ndarray | None = None           # (E, C) progressive refinement's unshot radiosity
    iterations: int = 0
    converged: bool = False


def residual(form_factors: FormFactors, reflectance, emission, radiosity) -> float:
    """max over elements and channels of |E + rho (F B) - B|."""
    return float(np.abs(emission + reflectance * form_factors.times(radiosity) - radiosity).max())


def gauss_seidel(form_factors: FormFactors, reflectance, emission, *, tolerance: float = 1e-10,
                 max_sweeps: int = 10000, initial=None) -> Solution:
    """Sweeps until the residual is at most `tolerance` times the largest emission (or
    `max_sweeps`). reflectance, emission: (E, C)."""
    rho, e = np.asarray(reflectance, np.float64), np.asarray(emission, np.float64)
    b = e.copy() if initial is None else np.array(initial, np.float64)
    indptr, columns, values = form_factors.indptr, form_factors.columns, form_factors.values
    scale = max(float(np.abs(e).max(initial=0.0)), np.finfo(float).tiny)
    solution = Solution(b)
    for sweep in range(1, max_sweeps + 1):
        largest = 0.0
        for i in range(len(b)):
            lo, hi = indptr[i], indptr[i + 1]
            new = e[i] + rho[i] * (values[lo:hi] @ b[columns[lo:hi]])
            largest = max(largest, float(np.abs(new - b[i]).max()))
            b[i] = new
        solution.residuals.append(largest)
        solution.iterations = sweep
        if solution.residuals[-1] <= tolerance * scale:
            solution.converged = True
            break
    return solution


def direct(form_factors: FormFactors, reflectance, emission) -> Solution:
    """B from the dense system (I - diag(rho) F) B = E, by LU (module docstring); its one
    residual, max |E + rho (F B) - B|, recorded."""
    rho, e = np.asarray(reflectance, np.float64), np.asarray(emission, np.float64)
    count = len(e)
    solution = Solution(np.zeros_like(e))
    if count:
        dense = form_factors.dense()
        for c in range(e.shape[1]):
            system = np.eye(count) - rho[:, c, None] * dense
            solution.radiosity[:, c] = np.linalg.solve(system, e[:, c])
    solution.residuals.append(residual(form_factors, rho, e, solution.radiosity) if count else 0.0)
    solution.iterations, solution.converged = 1, True
    return solution


class Shooter:
    """Progressive refinement that can stop and go on (module docstring): `shoot(count)` makes
    up to `count` more shots and says whether the unshot power is down to `tolerance` times the
    emitted power; `solution` is the radiosity so far (Solution.unshot what is left to shoot);
    `shown()` what a display shows meanwhile, B + rho ambient (Cohen et al. 1988). The solver
    (`progressive`) shoots to the end; the viewer a few shots a frame (renderer/core/
    radiosity_progressive.py)."""

    def __init__(self, form_factors: FormFactors, areas, reflectance, emission, *, tolerance: float = 1e-10):
        self.rho, e = np.asarray(reflectance, np.float64), np.asarray(emission, np.float64)
        self.areas = np.asarray(areas, np.float64)
        self.tolerance = tolerance
        self.emitted = max(float((self.areas[:, None] * e).sum()), np.finfo(float).tiny)
        self.columns = form_factors.by_column()
        self.solution = Solution(e.copy(), unshot=e.copy())
        self.power = self.areas * e.sum(axis=1)
        self.solution.converged = float(self.power.sum()) <= tolerance * self.emitted

    def shoot(self, count: int) -> bool:
        colptr, rows, values = self.columns
        solution, power, rho = self.solution, self.power, self.rho
        b, unshot = solution.radiosity, solution.unshot
        for _ in range(count):
            if solution.converged:
                break
            i = int(np.argmax(power))
            lo, hi = colptr[i], colptr[i + 1]
            j = rows[lo:hi]                                  # the elements that see i, each once
            received = rho[j] * values[lo:hi, None] * unshot[i]
            unshot[i] = 0.0
            b[j] += received
            unshot[j] += received
            power[i] = 0.0
            power[j] = self.areas[j] * unshot[j].sum(axis=1)
            solution.residuals.append(float(power.sum()))
            solution.iterations += 1
            solution.converged = solution.residuals[-1] <= self.tolerance * self.emitted
        return solution.converged

    @property
    def unshot_fraction(self) -> float:
        """The unshot power left over the emitted power (1 before the first shot)."""
        return float(self.power.sum()) / self.emitted

    def shown(self) -> np.ndarray:
        """(E, C): B + rho ambient, the picture before convergence (`ambient`)."""
        solution = self.solution
        return solution.radiosity + self.rho * ambient(self.areas, self.rho, solution.unshot)


def progressive(form_factors: FormFactors, areas, reflectance, emission, *, tolerance: float = 1e-10,
                max_shots: int | None = None) -> Solution:
    """Shoots until the unshot power is at most `tolerance` times the emitted power (or
    `max_shots`, default 100 times the element count)."""
    shooter = Shooter(form_factors, areas, reflectance, emission, tolerance=tolerance)
    shooter.shoot(100 * len(shooter.areas) if max_shots is None else max_shots)
    return shooter.solution


def ambient(areas, reflectance, unshot) -> np.ndarray:
    """(C,): the ambient radiosity that stands in for the unshot power while progressive
    refinement runs (Cohen et al. 1988): the area-weighted mean unshot radiosity times the
    interreflection factor 1 / (1 - mean rho). Each element shows B_i + rho_i ambient."""
    areas = np.asarray(areas, np.float64)
    total = areas.sum()
    mean_rho = (areas[:, None] * reflectance).sum(axis=0) / total
    return (areas[:, None] * unshot).sum(axis=0) / total / (1.0 - mean_rho)
