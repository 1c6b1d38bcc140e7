"""Solving the radiosity equation B = E + rho F B (renderer/core/radiosity_solve.py, issue 33):
Gauss-Seidel and progressive refinement. By hand: two elements facing each other; the white
furnace (a closed room of uniform reflectance rho and emission E) gives B = E / (1 - rho) on
every element within 1e-6, with the form factors of the GPU's item buffers and of the twin's;
residuals fall at every iteration; progressive refinement's ambient term makes the furnace
exact from the first shot."""

import numpy as np
import pytest

from reference.radiosity.item_buffer import draw
from renderer.core.form_factors import FormFactors, form_factors
from renderer.core.radiosity_solve import ambient, direct, gauss_seidel, progressive, residual
from renderer.gpu.item_buffers import ItemBuffers
from tests.radiosity_scenes import closed_box, elements_of


def two_elements(f, g):
    """F = [[0, f], [g, 0]] as sparse rows."""
    return FormFactors(np.array([0, 1, 2]), np.array([1, 0]), np.array([f, g]), np.zeros(2), np.zeros(2))


def test_two_elements_by_hand():
    """B1 = E1 + rho1 f B2, B2 = E2 + rho2 g B1, so B1 = (E1 + rho1 f E2) / (1 - rho1 rho2 f g)."""
    f, g, rho, e = 0.3, 0.6, np.array([[0.5], [0.8]]), np.array([[1.0], [0.25]])
    b1 = (e[0, 0] + rho[0, 0] * f * e[1, 0]) / (1 - rho[0, 0] * rho[1, 0] * f * g)
    b2 = e[1, 0] + rho[1, 0] * g * b1
    areas = np.array([g / f, 1.0])          # reciprocity A1 f = A2 g: not needed, but true here
    for solution in (gauss_seidel(two_elements(f, g), rho, e),
                     progressive(two_elements(f, g), areas, rho, e), direct(two_elements(f, g), rho, e)):
        assert solution.converged
        assert np.allclose(solution.radiosity[:, 0], [b1, b2], rtol=1e-12)


def furnace(rho, size=0.5):
    return elements_of(closed_box(1.0), np.arange(12) // 2, size, reflectance=rho, emission=1.0)


def gpu_matrix(ctx, elements, n):
    buffers = ItemBuffers(ctx, elements, n)
    try:
        return form_factors(len(elements), n, buffers.draw, buffers.batch)
    finally:
        buffers.release()


@pytest.mark.parametrize("backend", ["egl", "osmesa", "twin"])
def test_the_white_furnace_gives_e_over_one_minus_rho(gl_contexts, backend):
    elements = furnace(0.5)
    if backend == "twin":
        matrix = form_factors(len(elements), 16, lambda ix: draw(elements, 16, ix).items, 64)
    else:
        matrix = gpu_matrix(gl_contexts[backend], elements, 16)
    exact = 1.0 / (1 - 0.5)
    for solution in (gauss_seidel(matrix, elements.reflectance, elements.emission),
                     progressive(matrix, elements.areas, elements.reflectance, elements.emission),
                     direct(matrix, elements.reflectance, elements.emission)):
        assert solution.converged
        assert np.abs(solution.radiosity / exact - 1).max() < 1e-6


def test_the_direct_solve_is_exact_at_rho_0_9999():
    """The stiff furnace (B = 10,000 E) in one LU solve, where Gauss-Seidel would need tens of
    thousands of sweeps: within 1e-9 relative (the rows sum to 1 within 1e-15, and the
    condition number is about 1 / (1 - rho))."""
    from reference.radiosity.item_buffer import draw
    elements = furnace(0.9999, size=1.0)
    matrix = form_factors(len(elements), 16, lambda ix: draw(elements, 16, ix).items, 64)
    solution = direct(matrix, elements.reflectance, elements.emission)
    assert np.abs(solution.radiosity / 10000.0 - 1).max() < 1e-9
    assert solution.residuals[0] < 1e-9


def test_a_bright_furnace_is_stiff_but_still_exact(gl_contexts):
    """rho = 0.95: B = 20 E, reached only after well over a hundred sweeps (the residual falls by
    about rho^2 a sweep here, Gauss-Seidel being about two of Jacobi's sweeps of rho each)."""
    elements = furnace(0.95, size=1.0)
    matrix = gpu_matrix(gl_contexts["egl"], elements, 16)
    solution = gauss_seidel(matrix, elements.reflectance, elements.emission)
    assert solution.converged and np.abs(solution.radiosity / 20.0 - 1).max() < 1e-6
    ratios = np.array(solution.residuals[2:]) / np.array(solution.residuals[1:-1])
    assert np.all((0.85 < ratios) & (ratios < 0.95)) and solution.iterations > 150


def test_residuals_fall_every_iteration(gl_contexts):
    elements = elements_of(closed_box(1.0), np.arange(12) // 2, 0.5, reflectance=0.7)
    elements.emission[elements.obj == 1] = 5.0                 # one face lights the box
    matrix = gpu_matrix(gl_contexts["egl"], elements, 16)
    sweeps = gauss_seidel(matrix, elements.reflectance, elements.emission)
    shots = progressive(matrix, elements.areas, elements.reflectance, elements.emission)
    assert np.all(np.diff(sweeps.residuals) < 0) and np.all(np.diff(shots.residuals) <= 0)
    assert np.allclose(shots.radiosity, sweeps.radiosity, rtol=1e-8)
    assert residual(matrix, elements.reflectance, elements.emission, sweeps.radiosity) < 1e-9


def test_the_ambient_term_shows_the_furnace_before_the_shots_converge(gl_contexts):
    """Before any shot, B + rho ambient is the furnace's answer exactly (uniform unshot E over
    the room, times 1 / (1 - rho)); after some shots it stays several times closer than B
    alone (measured: 0.29 against 1.50 after 5 shots of 108, 0.07 against 0.38 after 200)."""
    elements = furnace(0.6)
    matrix = gpu_matrix(gl_contexts["egl"], elements, 16)
    exact = 1 / (1 - 0.6)
    for shots in (0, 5, 40, 200):
        solution = progressive(matrix, elements.areas, elements.reflectance, elements.emission,
                               max_shots=shots)
        shown = solution.radiosity + elements.reflectance * ambient(elements.areas, elements.reflectance,
                                                                    solution.unshot)
        shown_error, bare_error = np.abs(shown - exact).max(), np.abs(solution.radiosity - exact).max()
        assert shown_error < 1e-12 if shots == 0 else shown_error < 0.25 * bare_error, (shots, shown_error)
