"""Equation-error updating: recovery of known rigidity, the case-study crack, IPOPT vs SDP."""

import os

import numpy as np
import pytest

from gfe_opt import elements as el
from gfe_opt import updating
from gfe_opt.assembly import discretise
from gfe_opt.measured import make_measured
from gfe_opt.modal import discretisation_modes
from gfe_opt.model import Effect
from gfe_opt.parameterisation import beam_parameterisation
from gfe_opt.synthetic import full_shapes_at_nodes, reference_with_rigidity, synthetic_measurement
from gfe_opt.updating import active_constraints, cross_check, update_generic, update_sdp

from .conftest import STEEL_BAR, make_model


def _all_dof_data(model, rigidity, n_modes, ratio=8):
    """Noise-free modes of an independent fine reference, every DOF at the model's nodes."""
    ref = reference_with_rigidity(model, rigidity, ratio * model.elements)
    freqs, shapes = full_shapes_at_nodes(ref, model, n_modes)
    measured = make_measured(model.nodes[1:-1], "w", freqs, shapes[2:-2:2], "reference")
    return measured, shapes


def _taper(model):
    return lambda x: model.bending_rigidity * (1 + 0.5 * x / model.length)


def _dip(model):
    return lambda x: model.bending_rigidity * (
        1 - 0.3 * np.exp(-(((x - 0.35 * model.length) / (0.08 * model.length)) ** 2)))


def _assert_physical(result):
    assert result.ok, result.summary()
    p = result.element_parameters
    K = el.generic_beam_stiffness(p["k_ww"], p["k_wt"], p["k_tt"])
    lam = np.linalg.eigvalsh(K)
    assert np.all(lam[:, :2] > -1e-9 * lam[:, -1:])   # semidefinite
    assert np.all(lam[:, 2] > 1e-6 * lam[:, -1])       # exactly two zero eigenvalues
    assert np.allclose(np.einsum("eij,jk->eik", K, el.BEAM_RIGID_MODES), 0.0,
                       atol=1e-9 * np.abs(K).max())


@pytest.mark.parametrize("shape,parameterisation,tol", [
    ("taper", "nodal", 0.01), ("taper", "linear", 0.005), ("taper", "element", 0.01),
    ("dip", "nodal", 0.005), ("dip", "element", 0.005),
])
def test_recovers_smooth_rigidity_from_all_dof_modes(shape, parameterisation, tol):
    model = make_model(elements=24)
    rigidity = {"taper": _taper, "dip": _dip}[shape](model)
    measured, shapes = _all_dof_data(model, rigidity, 4)
    result = update_generic(model, measured, parameterisation=parameterisation,
                            full_shapes=shapes, noise=0.0)
    _assert_physical(result)
    assert result.objective < 1e-2 * result.objective_initial
    if parameterisation == "element":
        L = model.element_length
        exact = np.array([el.beam_stiffness_from_rigidity(rigidity, e * L, L)
                          for e in range(model.elements)])
        got = np.stack([result.element_parameters[k] for k in ("k_ww", "k_wt", "k_tt")], 1)
        # the end elements of a pinned beam store little strain energy: held, not recovered
        assert np.max(np.abs(got / exact - 1)[1:-1]) < tol
    else:
        k = result.q[:model.elements + 1]
        assert np.max(np.abs(k / rigidity(model.nodes) - 1)) < tol


def test_constant_parameterisation_cannot_hold_a_taper():
    # the paper: k constant (or zero slope) per element is a zero-order estimate
    model = make_model(elements=24)
    measured, shapes = _all_dof_data(model, _taper(model), 4)
    nodal = update_generic(model, measured, parameterisation="nodal", full_shapes=shapes,
                           noise=0.0)
    constant = update_generic(model, measured, parameterisation="constant", full_shapes=shapes,
                              noise=0.0)
    assert constant.objective > 100 * nodal.objective


@pytest.mark.parametrize("seed", [4, 5])
def test_case_study_crack_located_from_noisy_translations(seed):
    model = make_model()  # 46 elements, sensors at the interior nodes, first mode only
    truth = model.with_effects([Effect("crack", {"position": 0.2875, "depth_ratio": 2 / 3})])
    measured = synthetic_measurement(truth, 1, model.nodes[1:-1], shape_noise=0.005,
                                     freq_noise=0.0005, seed=seed)
    result = update_generic(model, measured, noise=0.005)
    _assert_physical(result)
    k = result.element_parameters["k_ww"] / 12
    centres = 0.5 * (model.nodes[:-1] + model.nodes[1:])
    assert abs(centres[np.argmin(k)] - 0.2875) <= model.element_length
    assert k.min() < 0.5 * model.bending_rigidity


@pytest.mark.parametrize("weighting", ["rows", "energy"])
def test_ipopt_direct_and_sdp_agree_on_a_convex_instance(weighting):
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _dip(model), 3)
    a = update_generic(model, measured, full_shapes=shapes, noise=0.0, solver="ipopt",
                       weighting=weighting)
    b = update_sdp(model, measured, full_shapes=shapes, noise=0.0, weighting=weighting)
    direct = update_generic(model, measured, full_shapes=shapes, noise=0.0,
                            weighting=weighting)
    assert a.solver == "ipopt" and direct.solver == "direct"
    for check in (cross_check(a, b, tol=1e-5), cross_check(direct, b, tol=1e-5)):
        assert check["agree"], check
        assert check["active_ipopt"] == check["active_sdp"] == []


def _conic_step(model, measured, shapes, margin, parameterisation):
    """The convex step of ``update_generic(..., full_shapes=shapes)`` solved by another
    method, cvxpy/Clarabel: the objective ||B z + b||² + ||V (z - z0)||² and the energy
    balance from the update's own problem data; a bar's k ≥ m, a beam's k_ww, k_θθ ≥ m and
    k_ww k_θθ - k_wθ² ≥ m as the second-order cone k_ww + k_θθ ≥ ||(k_ww - k_θθ, 2 k_wθ,
    2√m)|| (all scaled by k0).  Returns (x, the scaled element parameters, the objective
    as a function of x)."""
    import cvxpy as cp

    from gfe_opt import updating

    disc = discretise(model)
    par = parameterisation
    pb = updating._prepare(disc, par, measured, 0.0, updating.default_regularisation(True),
                           margin, par.fit(disc.stiffness_params), shapes)
    B, b, reg = updating._expanded_least_squares(pb)
    E, c = updating._energy_balance(pb)
    z = cp.Variable(pb.x0.size)
    P = par.matrix @ np.diag(pb.x_scale) / pb.k0
    p = P @ z
    constraints = [(E * pb.x_scale) @ z + c == 0]
    if model.kind == "bar":
        constraints.append(p >= margin)
    else:
        n = par.n_elements
        ww, wt, tt = p[:n], p[n:2 * n], p[2 * n:]
        constraints += [ww >= margin, tt >= margin] + [
            cp.SOC(ww[i] + tt[i], cp.hstack([ww[i] - tt[i], 2 * wt[i], 2 * np.sqrt(margin)]))
            for i in range(n)]
    cp.Problem(cp.Minimize(cp.sum_squares(B @ z + b)
                           + cp.sum_squares(cp.multiply(reg, z - pb.x0 / pb.x_scale))),
               constraints).solve(solver="CLARABEL", tol_gap_abs=1e-12, tol_gap_rel=1e-12,
                                  tol_feas=1e-12)

    def objective(x):
        y = x / pb.x_scale
        return np.sum((B @ y + b) ** 2) + np.sum((reg * (y - pb.x0 / pb.x_scale)) ** 2)

    return pb.x_scale * z.value, P @ z.value, objective


@pytest.mark.parametrize("reduced_by", ["clarabel", "ipopt"])
def test_active_constraint_is_solved_on_the_reduced_problem(reduced_by, monkeypatch):
    # a margin the 30 % dip must cross: the direct KKT point is infeasible, so "auto" solves
    # the step as the small problem of the elements it breaks (its cone program by Clarabel,
    # or IPOPT on it); its point sits on the bound, satisfies every condition, and is the
    # convex step's optimum: another method (a conic solver on the whole step) finds it too,
    # and IPOPT on the whole step within its own accuracy (it relaxes the bounds by 1e-8 and
    # stops at a tolerance of 1e-8: 2.4e-7 of the largest parameter here; 2e-4 relative on a
    # parameter near zero with no bound active at all)
    monkeypatch.setattr(updating, "REDUCED_SOLVER", reduced_by)
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _dip(model), 3)
    auto = update_generic(model, measured, full_shapes=shapes, noise=0.0, margin=3.5)
    forced = update_generic(model, measured, full_shapes=shapes, noise=0.0, margin=3.5,
                            solver="ipopt")
    assert auto.stats["steps"] == ["reduced"] and auto.solver == reduced_by, auto.summary()
    assert auto.ok and not auto.violations
    assert active_constraints(auto) == active_constraints(forced) != []
    conic, _, _ = _conic_step(model, measured, shapes, 3.5, auto.parameterisation)
    scale = np.max(np.abs(conic))
    assert np.max(np.abs(auto.q - conic)) < 1e-7 * scale        # measured 7.3e-9
    assert np.max(np.abs(auto.q - forced.q)) < 1e-5 * scale     # measured 2.4e-7
    free = update_generic(model, measured, full_shapes=shapes, noise=0.0, margin=2.0)
    assert free.solver == "direct" and not active_constraints(free)


@pytest.mark.parametrize("reduced_by", ["clarabel", "ipopt"])
def test_reduced_step_frees_the_neighbours_a_binding_condition_pushes_on(reduced_by,
                                                                         monkeypatch):
    # a 40-element bar updated from its closed-form modes with a margin of 0.99 of its
    # rigidity: the direct point breaks the last 6 elements, the optimum holds 7 at the bound
    # (a neighbour's condition binds in the first small problem, and it reads a parameter
    # outside it: without freeing it the step stopped at a feasible point 0.7 % above the
    # optimum's objective, with 6 held).  Another method (a QP by Clarabel) finds the same
    # bound set and objective; the parameters agree to 1.5e-5 of the largest, along a
    # direction whose curvature is 5e-9 of the largest (the reduced problem holds its bounds
    # 1e-9 above the margin, which that direction amplifies)
    monkeypatch.setattr(updating, "REDUCED_SOLVER", reduced_by)
    bar = make_model(STEEL_BAR, elements=40)
    measured, shapes = _exact_bar_modes(bar, 3)
    auto = update_generic(bar, measured, full_shapes=shapes, noise=0.0, margin=0.99)
    assert auto.stats["steps"] == ["reduced"] and auto.ok and not auto.violations
    assert auto.solver == reduced_by
    qp, p, objective = _conic_step(bar, measured, shapes, 0.99, auto.parameterisation)
    held = np.flatnonzero(auto.element_parameters["k"] / auto.k0 - 0.99 < 1e-7)
    assert held.tolist() == np.flatnonzero(p - 0.99 < 1e-7).tolist()
    assert held.size == 7
    assert abs(objective(auto.q) / objective(qp) - 1) < 1e-6        # measured 1.1e-7
    assert np.max(np.abs(auto.q - qp)) < 1e-3 * np.max(np.abs(qp))   # measured 1.5e-5


def _taper_measured(model):
    ref = reference_with_rigidity(model, _taper(model), 2 * model.elements)
    freqs, shapes = full_shapes_at_nodes(ref, model, 5)
    return make_measured(model.nodes[1:-1], "w", freqs, shapes[2:-2:2], "reference")


def test_energy_weighting_recovers_a_taper_on_10000_elements():
    # 5 modes, translations at every node of 10,000 elements from a 20,000-element reference:
    # the row-weighted residual (K - ω²M)φ amplifies rounding in φ by (N/jπ)^4 ~ 1e14 and
    # loses the taper; measured in the initial model's flexibility it does not
    model = make_model(elements=10000)
    rigidity = _taper(model)
    ref = reference_with_rigidity(model, rigidity, 2 * model.elements)
    freqs, shapes = full_shapes_at_nodes(ref, model, 5)
    measured = make_measured(model.nodes[1:-1], "w", freqs, shapes[2:-2:2], "reference")
    middle = slice(model.elements // 20, -model.elements // 20)  # pinned ends: held
    errors = {}
    for weighting in ("rows", "energy"):
        result = update_generic(model, measured, noise=0.0, weighting=weighting)
        assert result.ok and result.solver == "direct", result.summary()
        k = result.q[:model.elements + 1]
        errors[weighting] = np.max(np.abs(k / rigidity(model.nodes) - 1)[middle])
    assert errors["energy"] < 0.025   # measured 0.020 (0.5 % on the middle 80 %)
    assert errors["rows"] > 5 * errors["energy"]   # measured 0.24
    # the default chooses the weighting from the mesh: energy here, rows on the paper's mesh
    auto = update_generic(model, measured, noise=0.0)
    assert auto.stats["weighting"] == "energy"
    np.testing.assert_array_equal(auto.q, result.q)
    coarse = make_model(elements=46)
    assert update_generic(coarse, _taper_measured(coarse), noise=0.0).stats["weighting"] \
        == "rows"


def test_cross_check_reports_disagreement():
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _dip(model), 3)
    a = update_generic(model, measured, full_shapes=shapes, noise=0.0)
    b = update_sdp(model, measured, full_shapes=shapes, noise=0.0, regularisation=1.0)
    check = cross_check(a, b)
    assert not check["agree"] and check["parameter_difference"] > 1e-3


def test_infeasible_start_is_handled():
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _taper(model), 3)
    par = beam_parameterisation("element", 20, model.element_length)
    q0 = par.fit(discretise(model).stiffness_params)
    q0[3] = -q0[3]  # element 3: k_ww < 0, indefinite
    assert el.feasibility_violations(el.BEAM_STIFFNESS_CONDITIONS, par.element_parameters(q0))
    result = update_generic(model, measured, parameterisation=par, full_shapes=shapes,
                            noise=0.0, q0=q0)
    _assert_physical(result)


def test_failed_solve_is_reported_not_hidden():
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _dip(model), 3)
    result = update_generic(model, measured, full_shapes=shapes, noise=0.0, max_iter=2,
                            solver="ipopt")
    assert not result.success and not result.ok
    assert "Maximum_Iterations" in result.status
    assert any("must not be used" in n for n in result.notes)


def _exact_bar_modes(bar, n_modes):
    """Closed-form fixed-free bar modes, u at every node (all DOFs of a bar)."""
    n = np.arange(1, n_modes + 1)
    k = (2 * n - 1) * np.pi / (2 * bar.length)
    freqs = k * np.sqrt(bar.E / bar.rho) / (2 * np.pi)
    shapes = np.sin(np.outer(bar.nodes, k))
    return make_measured(bar.nodes[1:], "u", freqs, shapes[1:], "closed form"), shapes


@pytest.mark.parametrize("start", ["lumped", "consistent"])
def test_bar_mass_update_finds_minimum_error_beta(start):
    # eq. 2: beta = 1/12 has the smallest discretisation error; updating beta (and EA) from
    # closed-form modes must find it, from below (lumped, 0) and from above (consistent, 1/6)
    bar = make_model(STEEL_BAR, elements=40, mass=start)
    measured, shapes = _exact_bar_modes(bar, 3)
    result = update_generic(bar, measured, parameterisation="nodal", full_shapes=shapes,
                            noise=0.0, update_mass=True)
    assert result.ok, result.summary()
    assert abs(result.mass_parameters["beta"] - 1 / 12) < 2e-3
    check = update_sdp(bar, measured, parameterisation="nodal", full_shapes=shapes, noise=0.0,
                       update_mass=True)
    assert abs(check.mass_parameters["beta"] - result.mass_parameters["beta"]) < 1e-4


def test_beam_mass_update_stays_positive_definite_and_matches_sdp():
    beam = make_model(elements=12)
    k = np.arange(1, 4) * np.pi / beam.length
    freqs = k**2 * np.sqrt(beam.bending_rigidity / beam.mass_per_length) / (2 * np.pi)
    shapes = np.zeros((beam.n_dof, 3))
    shapes[0::2] = np.sin(np.outer(beam.nodes, k))
    shapes[1::2] = np.cos(np.outer(beam.nodes, k)) * k
    measured = make_measured(beam.nodes[1:-1], "w", freqs, shapes[2:-2:2], "closed form")
    a = update_generic(beam, measured, full_shapes=shapes, noise=0.0, update_mass=True)
    b = update_sdp(beam, measured, full_shapes=shapes, noise=0.0, update_mass=True)
    assert a.ok and b.ok
    assert np.allclose(list(a.mass_parameters.values()), list(b.mass_parameters.values()),
                       atol=1e-6)
    M = el.symmetric_beam_mass(**a.mass_parameters)
    assert np.linalg.eigvalsh(M).min() > 0
    before = discretisation_modes(discretise(beam), 3).frequencies_hz
    after = discretisation_modes(a.discretisation, 3).frequencies_hz
    assert np.max(np.abs(after / freqs - 1)) < 1e-3 * np.max(np.abs(before / freqs - 1))


@pytest.mark.parametrize("options,message", [
    ({"solver": "gurobi"}, "unknown solver"), ({"weighting": "mass"}, "unknown weighting"),
    ({"weighting": "energy", "method": "bilinear"}, "expand"),
])
def test_bad_update_options_are_refused(options, message):
    model = make_model(elements=10)
    measured, shapes = _all_dof_data(model, _taper(model), 2)
    with pytest.raises(ValueError, match=message):
        update_generic(model, measured, **options)


def _threads() -> int:
    return len(os.listdir(f"/proc/{os.getpid()}/task"))


@pytest.mark.skipif(not os.path.isdir(f"/proc/{os.getpid()}/task"), reason="needs /proc")
def test_the_reduced_cone_program_is_ipopts_problem_and_starts_no_threads():
    # a frame member's reduced problem (30 elements, 90 free parameters; random conditions,
    # some broken): Clarabel's cone program and IPOPT on the conditions as CasADi
    # expressions reach the same optimum, every condition held above the margin.  Clarabel
    # runs on this thread alone: with its defaults this problem started two threads in the
    # process (faer's pool), and a pool of fits forked after such a solve waited for ever
    rng = np.random.default_rng(1)
    n, m, margin = 30, 90, 1e-3
    p = np.concatenate([rng.uniform(-0.5, 2, n), rng.uniform(-0.3, 0.3, n),
                        rng.uniform(0.5, 2, n), rng.uniform(-0.5, 2, n)])
    A = rng.standard_normal((4 * n, m))
    before = _threads()
    conic, info = updating._conic_reduced(p, A, n, "frame", margin)
    assert _threads() == before
    ipopt, _ = updating._ipopt_reduced(p, A, n, "frame", margin, 500)
    assert info["solver"] == "clarabel" and conic is not None and ipopt is not None
    g = np.concatenate(updating._condition_values(p + A @ conic["x"], n, "frame"))
    assert np.min(g) > margin and np.min(p) < margin        # broken before, held after
    f_conic, f_ipopt = 0.5 * conic["x"] @ conic["x"], 0.5 * ipopt["x"] @ ipopt["x"]
    assert abs(f_conic / f_ipopt - 1) < 1e-7                                 # 1.6e-10
    assert np.max(np.abs(conic["x"] - ipopt["x"])) < 1e-4 * np.max(np.abs(ipopt["x"]))  # 1.8e-6


def _quasi_definite(rng, n_u=30, n_z=20, scale=1.0):
    """[[-Q, B], [Bᵀ, R]] with Q, R symmetric positive definite and sparse (the generic
    update's KKT system's shape)."""
    import scipy.sparse as sp

    def spd(n):
        a = sp.random(n, n, density=0.1, random_state=rng)
        return (a @ a.T + sp.identity(n)).tocsc()

    B = sp.random(n_u, n_z, density=0.2, random_state=rng) * scale
    return sp.bmat([[-spd(n_u), B], [B.T, spd(n_z)]], format="csc")


def test_the_kkt_factor_solves_and_its_order_serves_the_next_matrix():
    """The generic update's KKT factor (QDLDL, no pivoting: a quasi-definite matrix needs
    none) solves to rounding; a second matrix of the same pattern (the update's next step)
    reuses its order and solves that matrix, not the first; a matrix it cannot factor
    without pivots (a zero diagonal) is solved by SuperLU."""
    import scipy.sparse as sp

    rng = np.random.default_rng(4)
    A = _quasi_definite(rng)
    b = rng.standard_normal(A.shape[0])
    first = updating._Ldl(A)
    assert first.qdldl is not None
    x = first.solve(b)
    assert np.linalg.norm(A @ x - b) < 1e-12 * np.linalg.norm(b)
    A2 = A.copy()
    A2.data = A2.data * (1.0 + 0.5 * rng.random(A2.data.size))   # same pattern, new values
    A2 = 0.5 * (A2 + A2.T)
    second = updating._Ldl(A2, first)
    assert second.qdldl is not None and first.qdldl is None     # handed on, not rebuilt
    X = second.solve(np.stack([b, 2 * b], axis=1))
    assert np.linalg.norm(A2 @ X[:, 0] - b) < 1e-12 * np.linalg.norm(b)
    assert np.allclose(X[:, 1], 2 * X[:, 0], rtol=1e-12, atol=0)
    assert np.linalg.norm(A @ X[:, 0] - b) > 1e-3 * np.linalg.norm(b)
    swap = sp.csc_matrix(np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0]]))
    third = updating._Ldl(swap)
    assert third.qdldl is None and third.superlu is not None
    assert np.allclose(third.solve(np.array([1.0, 2.0, 3.0])), [2.0, 1.0, 1.5])


def test_an_inaccurate_ldl_solve_falls_back_to_superlu(monkeypatch):
    """Where the solve from QDLDL's unpivoted factor stays inaccurate, the step is solved
    from SuperLU's factor (not sent whole to IPOPT): the same update, to the KKT solve's
    rounding."""
    model = make_model(elements=20)
    measured, shapes = _all_dof_data(model, _dip(model), 3)
    plain = update_generic(model, measured, full_shapes=shapes, noise=0.0)
    solve, used = updating._Kkt.solve, []

    def refuse_ldl(self, *args):
        used.append(self.lu.qdldl is None)
        return None if self.lu.qdldl is not None else solve(self, *args)

    monkeypatch.setattr(updating._Kkt, "solve", refuse_ldl)
    fallback = update_generic(model, measured, full_shapes=shapes, noise=0.0)
    assert plain.solver == fallback.solver == "direct"
    assert used[:2] == [False, True]
    assert np.allclose(fallback.q, plain.q, rtol=1e-8, atol=0)
