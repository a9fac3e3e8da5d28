"""Analytic sensitivities (issue 22): the fits' Jacobian from eigenvalue and eigenvector
derivatives agrees with central differences of the modal solves on every built-in effect,
beam and bar, with sensors between the nodes and frequency-only data; and the eigenpair
derivatives match a closed form."""

from __future__ import annotations

import numpy as np
import pytest

from gfe_opt.effects import EFFECTS, effect_type
from gfe_opt.fitting import Noise, fit_problem
from gfe_opt.measured import make_measured
from gfe_opt.modal import model_modes
from gfe_opt.model import Effect
from gfe_opt.sensitivity import RepeatedEigenvalue, eigen_derivatives

from .conftest import STEEL_BAR, make_model

NOISE = Noise(0.0005, 0.003, True)


def _measured(model, n_modes, x, frequency_only=False):
    """Modes of another structure (E 3 % up, a 4 % point mass at 0.62 L), with a few
    per cent of disorder: residuals of every sign, no optimum at the evaluation point."""
    other = model.with_effects([Effect("material", {"E": 1.03 * model.youngs_modulus}),
                                Effect("point_mass", {"position": 0.62 * model.length,
                                                      "mass": 0.04 * model.mass_per_length
                                                              * model.length})])
    modes = model_modes(other, n_modes + 2)
    elastic = modes.frequencies_hz > 0
    freqs = modes.frequencies_hz[elastic][:n_modes]
    dof = "w" if model.kind == "beam" else "u"
    from gfe_opt.measured import sensor_matrix

    C = sensor_matrix(other.nodes, other.kind, x, dof)
    shapes = (C @ modes.shapes[:, elastic])[:, :n_modes]
    rng = np.random.default_rng(7)
    shapes = shapes * (1 + 0.02 * rng.standard_normal(shapes.shape))
    if frequency_only:
        return make_measured(np.zeros(0), dof, freqs, None, "check")
    return make_measured(x, dof, freqs, shapes, "check")


def _instance(model, name):
    """The effect with its chosen parameters (a side, knots) from its own starts."""
    kind = effect_type(name)
    for start in kind.starts(model, 0.37):
        fixed = {k: start[k] for k in kind.fixed_keys(model) if k in start}
        if len(fixed) == len(kind.fixed_keys(model)):
            return Effect(name, fixed)
    return Effect(name, {})


def _cases():
    for name, kind in EFFECTS.items():
        if "beam" in kind.kinds:
            yield pytest.param("beam", name, False, id=f"beam-{name}")
        if "bar" in kind.kinds:
            yield pytest.param("bar", name, False, id=f"bar-{name}")
    yield pytest.param("beam", "crack", True, id="beam-crack-frequency-only")
    yield pytest.param("beam", "point_mass", True, id="beam-point_mass-frequency-only")


def _central(residual, z, h):
    J = np.empty((residual(z).size, z.size))
    for k in range(z.size):
        up, down = z.copy(), z.copy()
        up[k] += h
        down[k] -= h
        J[:, k] = (residual(up) - residual(down)) / (2 * h)
    return J


@pytest.mark.parametrize("kind,name,frequency_only", list(_cases()))
def test_analytic_jacobian_matches_central_differences(kind, name, frequency_only):
    if kind == "beam":
        model = make_model(supports={"left": "clamped", "right": "pinned"}, elements=24)
        x = np.linspace(0.013, model.length - 0.011, 17)   # between the nodes
    else:
        model = make_model(STEEL_BAR)
        x = np.linspace(0.05, model.length, 9)
    measured = _measured(model, 4, x, frequency_only)
    problem = fit_problem(model, measured, [_instance(model, name)], noise=NOISE)
    lower, upper = problem.lower, problem.upper
    # a point inside the bounds, off every grid: 40 % of the way from the lower bound
    z = lower + 0.4 * (upper - lower)
    variables = [v for slot in problem.slots for v in slot.variables]
    for i, v in enumerate(variables):   # positions: off the supports and element boundaries
        if v.key in ("position", "centre"):
            z[i] = np.clip(v.order_one(model, 0.437 * model.length), lower[i], upper[i])
    residual = problem.residual
    r = residual(z)
    assert np.all(np.abs(r) < 1e5), "the evaluation point must solve"
    J = residual.jacobian(z, r, lower, upper)
    assert residual.fallbacks == 0
    # Richardson-extrapolated central differences of the modal solves: truncation ~h⁴,
    # rounding of the solves (~1e-9 of a residual) / h, and a step that crosses a change
    # of the pairing (a mode of the disordered data pairs with another model mode 7e-4
    # away on the bar with a point mass) is no derivative: the best of a ladder of steps
    error = np.full(z.size, np.inf)
    for h in (3e-3, 1e-3, 3e-4, 1e-4):
        reference = (4 * _central(residual, z, h / 2) - _central(residual, z, h)) / 3
        scale = np.linalg.norm(reference, axis=0)
        assert np.all(scale > 0), "every variable moves the residual"
        error = np.minimum(error, np.linalg.norm(J - reference, axis=0) / scale)
    assert np.max(error) < 1e-6, (name, error)


@pytest.mark.parametrize("frequency_only", [False, True], ids=["shapes", "frequencies"])
def test_a_jacobians_chosen_columns_are_the_full_ones_to_the_last_bit(frequency_only):
    """Profile starts ask for the inner effects' columns only (the others' matrices are not
    built) and a frequency-only fit for no eigenvector systems: each column must still be
    the full Jacobian's bit for bit, or the fits would start elsewhere than before."""
    model = make_model(supports={"left": "clamped", "right": "pinned"}, elements=24)
    x = np.linspace(0.013, model.length - 0.011, 17)
    measured = _measured(model, 4, x, frequency_only)
    pairs = [("material", "crack"), ("support_spring", "section_loss"),
             ("point_mass", "point_spring")]
    for first, second in pairs:
        problem = fit_problem(model, measured, [_instance(model, first),
                                                _instance(model, second)], noise=NOISE)
        lower, upper = problem.lower, problem.upper
        z = lower + 0.4 * (upper - lower)
        r = problem.residual(z)
        full = problem.residual.jacobian(z, r, lower, upper)
        assert problem.residual.fallbacks == 0
        inner = np.arange(len(problem.slots[0].variables))
        part = problem.residual.jacobian(z, r, lower, upper, columns=inner)
        assert np.array_equal(part[:, inner], full[:, inner]), (first, second)
        assert not np.any(part[:, inner.size:]), "the columns not asked for are not built"
        assert np.any(full[:, inner.size:]), "the full Jacobian has them"


def test_eigen_derivatives_of_a_two_dof_system_match_the_closed_form():
    """K = [[2k, -k], [-k, k]], M = I: λ = k (3 ∓ √5)/2; d/dk at fixed M is λ/k, shapes
    do not change (they do not depend on k)."""
    k = 3.0
    K = np.array([[2 * k, -k], [-k, k]])
    M = np.eye(2)
    lam, phi = np.linalg.eigh(K)
    dlam, dphi = eigen_derivatives(K, M, [0, 1], lam, phi, [K / k], [np.zeros((2, 2))],
                                   all_lam=lam)
    assert np.allclose(dlam[:, 0], lam / k, rtol=1e-13)
    assert np.allclose(dphi, 0.0, atol=1e-13)
    # a mass change: φᵀMφ = 1 holds to first order, λ' = -λ φᵀ M' φ
    dM = np.diag([1.0, 0.0])
    dlam, dphi = eigen_derivatives(K, M, [0, 1], lam, phi, [np.zeros((2, 2))], [dM],
                                   all_lam=lam)
    assert np.allclose(dlam[:, 0], -lam * phi[0] ** 2, rtol=1e-12)
    for j in range(2):
        assert abs(2 * phi[:, j] @ dphi[:, j, 0] + phi[:, j] @ dM @ phi[:, j]) < 1e-12


def test_repeated_eigenvalues_are_refused():
    K, M = np.diag([1.0, 1.0, 4.0]), np.eye(3)
    lam, phi = np.linalg.eigh(K)
    with pytest.raises(RepeatedEigenvalue):
        eigen_derivatives(K, M, [0, 1, 2], lam[:1], phi[:, :1], [np.eye(3)], [np.eye(3)],
                          all_lam=lam)


def test_dense_and_sparse_solves_agree(monkeypatch):
    """Small models solve the bordered systems dense, large ones sparse: the same numbers."""
    import scipy.linalg as sla
    import scipy.sparse as sp

    import gfe_opt.sensitivity as sensitivity

    rng = np.random.default_rng(0)
    n = 30
    A = rng.standard_normal((n, n))
    K, M = A @ A.T + n * np.eye(n), np.diag(rng.uniform(1, 2, n))
    lam, phi = sla.eigh(K, M)
    B = sp.random(n, n, 0.2, random_state=1).toarray()
    dK, dM = [B + B.T], [np.diag(rng.uniform(0, 1, n))]
    dense = eigen_derivatives(K, M, np.arange(n), lam[:4], phi[:, :4], dK, dM, all_lam=lam)
    monkeypatch.setattr(sensitivity, "DENSE_DOFS", 0)
    sparse = eigen_derivatives(sp.csr_matrix(K), sp.csr_matrix(M), np.arange(n), lam[:4],
                               phi[:, :4], dK, dM, all_lam=lam)
    for a, b in zip(dense, sparse):
        assert np.allclose(a, b, rtol=0, atol=1e-12 * np.max(np.abs(a)))
    # without the shapes (frequencies alone): no system is solved, the same λ' to the bit
    for dense in (True, False):
        both = eigen_derivatives(K, M, np.arange(n), lam[:4], phi[:, :4], dK, dM,
                                 all_lam=lam, dense=dense)
        alone = eigen_derivatives(K, M, np.arange(n), lam[:4], phi[:, :4], dK, dM,
                                  all_lam=lam, dense=dense, shapes=False)
        assert np.array_equal(alone[0], both[0]) and not np.any(alone[1])
        assert np.any(both[1])


def test_nelsons_shifted_pencil_is_sparse_arithmetic_and_slicing_bit_for_bit():
    """The scaled K − λM without the row and column of the shape's peak, built from arrays
    (:class:`~gfe_opt.sensitivity._Pencil`), is the matrix sparse subtraction and slicing
    give: the same entries, the same numbers, so the same factorisation (a frame with a
    semi-rigid joint and a point mass: entries of K alone, of M alone and of both)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from gfe_opt.assembly import discretise
    from gfe_opt.modal import discretisation_modes
    from gfe_opt.problems import portal_frame
    from gfe_opt.sensitivity import _Pencil

    model = portal_frame().with_effects([
        Effect("joint_spring", {"node": "B", "member": "beam", "stiffness": 3000.0}),
        Effect("point_mass", {"member": "beam", "position": 0.1, "mass": 0.05})])
    disc = discretise(model)
    K, M = disc.global_matrices()
    free = disc.free
    modes = discretisation_modes(disc, 6)
    Kf, Mf = sp.csc_matrix(K)[free][:, free], sp.csc_matrix(M)[free][:, free]
    D = sp.diags(1.0 / np.sqrt(np.abs(Kf.diagonal())))
    Ks, Ms = (D @ Kf @ D).tocsc(), (D @ Mf @ D).tocsc()
    pencil = _Pencil(Ks, Ms)
    rng = np.random.default_rng(3)
    for lam in (2 * np.pi * modes.frequencies_hz) ** 2:
        for k in (0, int(rng.integers(free.size)), free.size - 1):
            keep = np.flatnonzero(np.arange(free.size) != k)
            plain = (Ks - lam * Ms).tocsc()[keep][:, keep].tocsc()
            fast = pencil.without(lam, k)
            for A in (plain, fast):
                A.sort_indices()
            assert np.array_equal(plain.indptr, fast.indptr)
            assert np.array_equal(plain.indices, fast.indices)
            assert np.array_equal(plain.data, fast.data)
            b = rng.standard_normal(keep.size)
            assert np.array_equal(spla.splu(plain).solve(b), spla.splu(fast).solve(b))
