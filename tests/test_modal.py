"""Modal analysis against closed forms, and observed convergence rates."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from gfe_opt import elements as el
from gfe_opt.assembly import discretise
from gfe_opt.modal import discretisation_modes, model_modes
from gfe_opt.model import Effect

from .conftest import STEEL_BAR, make_model


def _roots(f, count):
    """First ``count`` positive roots of f, bracketed on a fine grid."""
    grid = np.linspace(0.1, 4 * count + 4, 4000)
    vals = f(grid)
    idx = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[:count]
    return np.array([brentq(f, grid[i], grid[i + 1]) for i in idx])


def _beam_omega(model, beta_l):
    return beta_l**2 / model.length**2 * np.sqrt(model.bending_rigidity / model.mass_per_length)


def test_simply_supported_beam(beam):
    f = model_modes(beam, 5).frequencies_hz
    exact = _beam_omega(beam, np.arange(1, 6) * np.pi) / (2 * np.pi)
    assert np.allclose(f, exact, rtol=2e-5)


def test_clamped_free_beam():
    m = make_model(supports={"left": "clamped", "right": "free"})
    roots = _roots(lambda x: np.cos(x) * np.cosh(x) + 1, 4)
    assert np.isclose(roots[0], 1.8751, atol=1e-4)
    f = model_modes(m, 4).frequencies_hz
    assert np.allclose(f, _beam_omega(m, roots) / (2 * np.pi), rtol=2e-5)


def test_free_free_beam_has_two_rigid_modes():
    m = make_model(supports={"left": "free", "right": "free"})
    modes = model_modes(m, 5)
    f = modes.frequencies_hz
    assert np.all(np.abs(f[:2]) < 1e-8 * f[2])
    roots = _roots(lambda x: np.cos(x) * np.cosh(x) - 1, 3)
    assert np.allclose(f[2:], _beam_omega(m, roots) / (2 * np.pi), rtol=2e-5)


def test_fixed_free_bar():
    bar = make_model(STEEL_BAR, elements=200)
    f = model_modes(bar, 4).frequencies_hz
    n = np.arange(1, 5)
    exact = (2 * n - 1) * np.pi / (2 * bar.length) * np.sqrt(bar.E / bar.rho) / (2 * np.pi)
    assert np.allclose(f, exact, rtol=2e-4)


def _slope(h, err):
    return np.polyfit(np.log(h), np.log(np.abs(err)), 1)[0]


@pytest.mark.parametrize("mass,order", [("lumped", 2), ("consistent", 2),
                                        ("minimum_error", 4)])
def test_bar_convergence_rate(mass, order):
    meshes = np.array([8, 16, 32, 64])
    base = make_model(STEEL_BAR, mass=mass)
    exact = 3 * np.pi / (2 * base.length) * np.sqrt(base.E / base.rho) / (2 * np.pi)
    err = [model_modes(base.with_elements(n), 2).frequencies_hz[1] / exact - 1 for n in meshes]
    assert abs(_slope(1.0 / meshes, err) - order) < 0.25


def _beam_mode2_errors(meshes, mass_params):
    base = make_model()
    k = 2 * np.pi / base.length
    exact = k**4 * base.bending_rigidity / base.mass_per_length
    out = []
    for n in meshes:
        disc = discretise(base.with_elements(n))
        t = el.beam_dof_scaling(disc.element_length)
        scaled = el.symmetric_beam_mass(**{k_: np.full(n, v) for k_, v in mass_params.items()})
        mass = base.mass_per_length * disc.element_length * scaled * (t[:, None] * t[None, :])
        modes = discretisation_modes(replace(disc, mass=mass), 3)
        out.append((2 * np.pi * modes.frequencies_hz[1]) ** 2 / exact - 1)
    return np.array(out), k


@pytest.mark.parametrize("name,order,leading", [
    ("CONSISTENT_BEAM_MASS", 4, 1 / 720),          # +(kh)^4/720 (REFERENCES, computed)
    ("PAPER_HIGHER_ORDER_BEAM_MASS", 4, -1 / 360),  # the paper's printed numbers: 4th order
    ("HIGHER_ORDER_BEAM_MASS", 6, None),            # (2 consistent + printed) / 3
])
def test_beam_eigenvalue_convergence_rate(name, order, leading):
    meshes = np.array([6, 8, 12, 16])
    err, k = _beam_mode2_errors(meshes, getattr(el, name))
    assert abs(_slope(1.0 / meshes, err) - order) < 0.3
    if leading is not None:
        h = make_model().length / meshes[-1]
        assert np.isclose(err[-1], leading * (k * h) ** 4, rtol=0.05)


def test_higher_order_mass_model_key_selects_sixth_order_mass():
    plain, better = make_model(elements=8), make_model(elements=8, mass="higher_order")
    exact = (np.pi / plain.length) ** 2 * np.sqrt(plain.bending_rigidity / plain.mass_per_length)
    f = [model_modes(m, 1).frequencies_hz[0] * 2 * np.pi / exact - 1 for m in (plain, better)]
    assert abs(f[1]) < abs(f[0]) / 50


def test_cracked_beam_frequency_ratios_match_reference():
    # REFERENCES: a/d = 2/3 at mid-span (d half-depth) lowers mode 1 to 0.757, mode 3 to 0.8321
    plain = make_model()
    cracked = plain.with_effects([Effect("crack", {"position": 0.2875, "depth_ratio": 2 / 3})])
    ratio = model_modes(cracked, 3).frequencies_hz / model_modes(plain, 3).frequencies_hz
    assert np.allclose(ratio, [0.757, 0.9985, 0.8321], atol=6e-4)


SUPPORT_ROOTS = {
    ("pinned", "pinned"): lambda n: np.arange(1, n + 1) * np.pi,
    ("clamped", "clamped"): lambda n: _roots(lambda b: np.cos(b) * np.cosh(b) - 1, n),
    ("clamped", "free"): lambda n: _roots(lambda b: np.cos(b) * np.cosh(b) + 1, n),
}


@pytest.mark.parametrize("elements", [1000, 10000, 30000])
@pytest.mark.parametrize("supports", list(SUPPORT_ROOTS))
def test_fine_meshes_keep_the_closed_forms(elements, supports):
    """The condensed, self-checking route: within 1e-9 (measured: 1e-11 at 30 000) where
    raw shift-invert loses eps N^4 (1e-3 at 3000 elements, wrong at 20 000).  1e-9: the
    banded Cholesky of K_II keeps 1e-11 where the sparse LU before it left 6e-9."""
    m = make_model(elements=elements, supports=dict(zip(("left", "right"), supports)))
    f = model_modes(m, 5).frequencies_hz
    exact = _beam_omega(m, SUPPORT_ROOTS[supports](5)) / (2 * np.pi)
    assert np.max(np.abs(f / exact - 1)) < 1e-9


def test_the_condensed_routes_band_reads_are_the_sparse_matrixs_entries():
    """The condensed route reads K_II's band and the interior–boundary couplings from K's
    diagonals (modal._plan): the same numbers as sparse indexing, bit for bit, on a beam
    with a crack, a foundation and an axial load (entries in every diagonal used); the
    banded Cholesky solve agrees with the sparse LU to rounding, and a K_II that is not
    positive definite falls back to the LU."""
    import scipy.sparse.linalg as spla

    from gfe_opt import modal

    m = make_model(elements=401).with_effects([
        Effect("crack", {"position": 0.31, "depth_ratio": 0.4}),
        Effect("foundation", {"stiffness": 3e5}), Effect("axial_load", {"tension": -40.0})])
    K = discretise(m).global_matrices()[0]
    plan = modal._plan(401, 2, modal.condensation_groups(401, 5))
    rows, cols = plan.interior, plan.boundary[plan.local]
    diagonals = {k: K.diagonal(k) for k in range(-plan.width, plan.width + 1)}
    coupling = modal._couplings(plan, diagonals)
    sparse = np.stack([np.asarray(K[rows, cols[:, j]]).ravel() for j in range(4)], 1)
    assert np.count_nonzero(sparse) > 0 and np.array_equal(coupling, sparse)
    K_II = K[rows][:, rows].tocsc()
    x = np.random.default_rng(5).standard_normal((rows.size, 3))
    lu = spla.splu(K_II).solve(x)
    banded = modal._interior_solver(K, plan, diagonals)(x)
    assert np.max(np.abs(banded - lu)) < 1e-9 * np.max(np.abs(lu))
    # not positive definite: one interior diagonal entry negative
    bad = K.tolil()
    bad[rows[7], rows[7]] = -K[rows[7], rows[7]]
    bad = bad.tocsr()
    bad_diagonals = {k: bad.diagonal(k) for k in range(-plan.width, plan.width + 1)}
    fallback = modal._interior_solver(bad, plan, bad_diagonals)(x)
    assert np.array_equal(fallback, spla.splu(bad[rows][:, rows].tocsc()).solve(x))
    # stiffness outside the band (no beam element couples nodes apart): refused, not read
    # wrong
    from gfe_opt.errors import GfeSolverError

    far = K.tolil()
    far[rows[3], rows[40]] = far[rows[40], rows[3]] = 1.0
    disc = discretise(m)
    with pytest.raises(GfeSolverError, match="outside the beam's band"):
        modal._reduce_and_solve(disc, far.tocsr(), disc.global_matrices()[1], 5,
                                modal.condensation_groups(401, 5), None)
    with pytest.raises(ValueError):   # the plan, shared by every solve, is read-only
        plan.interior[0] = 1


def test_meshes_above_the_verified_ceiling_are_refused_with_the_limit():
    from gfe_opt.errors import GfeInputError
    from gfe_opt.modal import MAX_BEAM_ELEMENTS

    # a model file says so when it is read; a mesh refined in code, when it is solved
    with pytest.raises(GfeInputError, match=f"above {MAX_BEAM_ELEMENTS}, the finest beam"):
        make_model(elements=MAX_BEAM_ELEMENTS + 1)
    with pytest.raises(GfeInputError, match=f"above {MAX_BEAM_ELEMENTS}, the finest mesh"):
        model_modes(make_model().with_elements(MAX_BEAM_ELEMENTS + 1), 5)


def test_solves_are_deterministic():
    beam = make_model(elements=3000)  # condensed route
    bar = make_model(STEEL_BAR, elements=20000)  # sparse shift-invert route
    for model in (beam, bar):
        a, b = model_modes(model, 5), model_modes(model, 5)
        assert np.array_equal(a.frequencies_hz, b.frequencies_hz)
        assert np.array_equal(a.shapes, b.shapes)


def test_a_long_bar_keeps_its_closed_form():
    m = make_model(STEEL_BAR, elements=200000, mass="minimum_error")
    f = model_modes(m, 5).frequencies_hz
    c = np.sqrt(m.axial_rigidity / m.mass_per_length)
    exact = (2 * np.arange(1, 6) - 1) * np.pi / (2 * m.length) * c / (2 * np.pi)
    assert np.max(np.abs(f / exact - 1)) < 1e-9


def test_rigid_body_modes_are_counted_for_every_support_and_spring():
    from gfe_opt.modal import rigid_body_count

    supports = ("pinned", "clamped", "free", "sliding")
    count = {(a, b): rigid_body_count(discretise(make_model(
        supports={"left": a, "right": b}))) for a in supports for b in supports}
    assert count[("free", "free")] == 2
    assert count[("pinned", "free")] == count[("free", "sliding")] == 1
    assert count[("sliding", "sliding")] == 1 and count[("pinned", "pinned")] == 0
    free = make_model(supports={"left": "free", "right": "free"})
    # one spring leaves the turn about it; a foundation leaves nothing
    spring = free.with_effects([Effect("point_spring", {"position": 0.1, "stiffness": 1e5})])
    found = free.with_effects([Effect("foundation", {"stiffness": 1e5})])
    assert rigid_body_count(discretise(spring)) == 1
    assert rigid_body_count(discretise(found)) == 0
    f = model_modes(spring, 3).frequencies_hz
    assert f[0] == 0.0 and f[1] > 10.0


def _ss_exact(model, n, extra_stiffness=0.0, tension=0.0):
    a = n * np.pi / model.length
    return np.sqrt((model.bending_rigidity * a**4 + tension * a**2 + extra_stiffness)
                   / model.mass_per_length) / (2 * np.pi)


def test_axial_tension_closed_form():
    m = make_model(elements=60)
    t = 2.0e4
    f = model_modes(m.with_effects([Effect("axial_load", {"tension": t})]), 3).frequencies_hz
    assert np.allclose(f, _ss_exact(m, np.arange(1, 4), tension=t), rtol=1e-5)


def test_winkler_foundation_closed_form():
    m = make_model(elements=60)
    k = 5.0e6
    f = model_modes(m.with_effects([Effect("foundation", {"stiffness": k})]), 3).frequencies_hz
    assert np.allclose(f, _ss_exact(m, np.arange(1, 4), extra_stiffness=k), rtol=1e-5)


@pytest.mark.parametrize("h_over_l,ratio", [(0.05, 0.99580), (0.10, 0.98357), (0.20, 0.93966)])
def test_timoshenko_ratio_matches_reference(h_over_l, ratio):
    # REFERENCES: rectangle, kappa = 5/6, nu = 0.3; shear and rotary inertia
    length = 1.0
    h = h_over_l * length
    m = make_model(length=length, elements=200, section={"b": 0.01, "h": h})
    g_mod = m.E / (2 * (1 + m.nu))
    shear = Effect("shear", {"shear_rigidity": 5 / 6 * g_mod * m.area})
    f = model_modes(m.with_effects([shear]), 1).frequencies_hz[0]
    assert np.isclose(f / _ss_exact(m, 1), ratio, atol=2e-5)


def test_point_mass_and_support_spring_bounds():
    m = make_model(elements=40)
    f0 = model_modes(m, 2).frequencies_hz
    heavy = m.with_effects([Effect("point_mass", {"position": m.length / 2, "mass": 0.5})])
    f = model_modes(heavy, 2).frequencies_hz
    assert f[0] < f0[0] and np.isclose(f[1], f0[1], rtol=1e-6)  # mode 2 has a node at mid-span
    stiff = m.with_effects([Effect("support_spring", {"stiffness": 1e12, "side": "both"})])
    clamped = make_model(elements=40, supports={"left": "clamped", "right": "clamped"})
    assert np.allclose(model_modes(stiff, 2).frequencies_hz,
                       model_modes(clamped, 2).frequencies_hz, rtol=1e-5)


def test_the_sparse_solves_direct_products_are_scipys_bit_for_bit():
    """ARPACK's mass products in the sparse solve call scipy's own kernel directly
    (``modal._product``): the same vector ``A @ x`` gives, to the last bit; and the
    sparse solve of a frame agrees with the dense one."""
    import scipy.sparse as sp

    from gfe_opt import modal
    from gfe_opt.assembly import discretise
    from gfe_opt.problems import three_storey_frame

    rng = np.random.default_rng(3)
    A = sp.random(60, 60, density=0.1, random_state=rng, format="csc")
    product = modal._product(A)
    assert product.__name__ == "product"   # scipy's kernel called directly, not A @ x
    for _ in range(5):
        x = rng.standard_normal(60)
        assert np.array_equal(product(x), A @ x)
    disc = discretise(three_storey_frame())
    K, M = disc.global_matrices()
    sparse, dense = (modal.solve_modes(K, M, 8, disc.constrained, disc.eigenvalue_scale,
                                       dense=d, free=disc.free) for d in (False, True))
    # (the raw eigenvalues of the pencil, before the Rayleigh quotients of
    # discretisation_modes: the two routes round them differently, by up to 5e-9 relative
    # here, measured)
    assert np.allclose(sparse.frequencies_hz, dense.frequencies_hz, rtol=1e-7)
    assert np.all(np.abs(np.sum(sparse.shapes * (M @ dense.shapes), axis=0)) > 1 - 1e-9)


def test_the_dense_solves_shapes_are_smooth_in_a_parameter_below_lapacks_rounding():
    """The shapes of the dense solve move smoothly with the model: moving a crack by 1e-11
    of the length changes a 20-element beam's shapes by a second difference below 1e-11 of
    their largest value (LAPACK's own shapes carry about eps·λ_max/gap, 5e-11 here:
    ``scripts/study_shape_rounding.py``; the inverse-iteration step takes them to 1e-13),
    and they stay an M-orthonormal set of eigenvectors to rounding."""
    base = make_model(elements=20)
    h, x0 = 1e-11 * base.length, 0.331 * base.length
    S = [model_modes(base.with_effects([Effect("crack", {"position": x0 + k * h,
                                                         "depth_ratio": 0.356})]), 4).shapes
         for k in (-1, 0, 1)]
    d2 = np.abs(S[2] - 2 * S[1] + S[0]).max(axis=0) / np.abs(S[1]).max(axis=0)
    assert np.all(d2 < 1e-11), d2
    model = base.with_effects([Effect("crack", {"position": x0, "depth_ratio": 0.356})])
    disc = discretise(model)
    K, M = disc.global_matrices()
    modes = model_modes(model, 4)
    phi, lam = modes.shapes, modes.omega ** 2
    assert np.allclose(phi.T @ (M @ phi), np.eye(4), atol=1e-12)
    free = disc.free   # (the supports' reactions are no residual)
    residual = np.linalg.norm((K @ phi - (M @ phi) * lam)[free], axis=0)
    assert np.all(residual < 1e-10 * np.linalg.norm((K @ phi)[free], axis=0)), residual


def test_a_mid_size_beams_sparse_solve_is_as_smooth_and_as_exact_as_the_dense_one():
    """Beams and bars above ``DENSE_SOLVE_DOFS`` free DOFs take the sparse route (a speed
    choice): at 100 and 150 elements its shapes move as smoothly with a crack moved by
    1e-11 of the length as the dense route's (second differences 6e-11 and 3e-10 of the
    largest value, against 5e-11 and 2e-10 dense, measured: the mesh's own conditioning,
    not the route), they are the same modes, and the frequencies of the simply supported
    beam are the closed form's to the element's own error, mode by mode."""
    from gfe_opt import modal
    from gfe_opt.assembly import DENSE_SOLVE_DOFS

    for n in (100, 150):
        base = make_model(elements=n)
        h, x0 = 1e-11 * base.length, 0.331 * base.length
        discs = [discretise(base.with_effects([Effect("crack", {"position": x0 + k * h,
                                                                "depth_ratio": 0.356})]))
                 for k in (-1, 0, 1)]
        assert not discs[1].dense_solve and discs[1].free.size > DENSE_SOLVE_DOFS
        roughness, shapes = [], []
        for dense in (True, False):
            S = []
            for disc in discs:
                K, M = disc.global_matrices()
                S.append(modal.solve_modes(K, M, 5, disc.constrained, disc.eigenvalue_scale,
                                           dense=dense, free=disc.free).shapes)
            roughness.append(np.max(np.abs(S[2] - 2 * S[1] + S[0]).max(axis=0)
                                    / np.abs(S[1]).max(axis=0)))
            shapes.append(S[1])
        assert roughness[1] < 1e-9 and roughness[1] < 10 * roughness[0], roughness
        assert np.max(np.abs(shapes[1] - shapes[0])) < 1e-8 * np.max(np.abs(shapes[0]))
    beam = make_model(elements=100)
    f = model_modes(beam, 5).frequencies_hz
    EI, rho_a = beam.E * beam.inertia, beam.rho * beam.area
    exact = (np.arange(1, 6) * np.pi / beam.length) ** 2 * np.sqrt(EI / rho_a) / (2 * np.pi)
    # the element's own error, (k h)⁴ (6.8e-10 for mode 1, 4.2e-7 for mode 5), mode by mode:
    # no rounding of the route shows above it
    error = f / exact - 1
    assert 0 < error[0] < 1e-9
    assert np.allclose(error / error[0], np.arange(1, 6) ** 4, rtol=0.02), error / error[0]


def test_inverse_iteration_leaves_a_repeated_pair_and_rigid_modes_as_they_came():
    """A pair of equal eigenvalues would be mixed by the step (either vector is one of the
    pair's): both keep LAPACK's vectors, as does a rigid mode; a lone elastic mode is
    refined to the exact eigenvector."""
    from scipy.linalg import eigh

    from gfe_opt.modal import _inverse_iteration

    rng = np.random.default_rng(3)
    Q = np.linalg.qr(rng.standard_normal((6, 6)))[0]
    A = Q @ np.diag([0.0, 1.0, 1.0, 2.5, 4.0, 9.0]) @ Q.T
    B = np.eye(6)
    lam, vec = eigh(A, B, subset_by_index=[0, 3])
    lam[0] = 0.0
    noisy = vec + 1e-9 * rng.standard_normal(vec.shape)
    out = _inverse_iteration(A, B, lam, noisy)
    assert np.array_equal(out[:, :3], noisy[:, :3])
    exact = Q[:, 3] * np.sign(Q[:, 3] @ noisy[:, 3])
    assert np.linalg.norm(out[:, 3] - exact) < 1e-13 < np.linalg.norm(noisy[:, 3] - exact)


def test_a_frames_pencil_is_refined_banded_in_a_reverse_cuthill_mckee_order(monkeypatch):
    """A frame's DOFs are numbered node by node, so its pencil is not banded in its own
    order (the portal's band spans nearly all its free DOFs); the inverse-iteration step
    solves it banded in a reverse Cuthill–McKee order, with the shapes the dense LU of
    each mode gives to rounding, each an eigenvector of the pencil to rounding."""
    from scipy.linalg import eigh

    from gfe_opt import modal
    from gfe_opt.model import load_model
    from gfe_opt.problems import problem_file

    disc = discretise(load_model(problem_file("portal-frame.toml"), frames=True))
    K, M = disc.global_matrices()
    free = disc.free
    A, B = K.toarray()[np.ix_(free, free)], M.toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(np.diag(B))
    A, B = A * np.outer(d, d), B * np.outer(d, d)
    n = free.size
    nonzero = (A != 0) | (B != 0)
    order, band = modal._banding_order(np.packbits(nonzero).tobytes(), n)
    assert 4 * modal._bandwidth(nonzero) >= n > 4 * band          # banded only reordered
    assert sorted(order) == list(range(n))
    lam, vec = eigh(A, B, subset_by_index=[0, 7])
    calls, gbsv = [], modal._GBSV()
    monkeypatch.setattr(modal, "_GBSV", lambda: lambda *a: calls.append(a[0]) or gbsv(*a))
    banded = modal._inverse_iteration(A, B, lam, vec)
    assert calls == [band] * 8            # LAPACK's banded LU, one a mode, at that band
    dense_lu = modal._inverse_iteration(A, B, lam, vec, reorder=False)
    assert len(calls) == 8
    assert np.max(np.abs(banded - dense_lu)) < 1e-11 * np.max(np.abs(dense_lu))
    rayleigh = np.einsum("ij,ij->j", banded, A @ banded)
    residual = np.linalg.norm(A @ banded - (B @ banded) * rayleigh, axis=0)
    # backward stable: a residual of rounding, eps ‖A‖ ‖x‖ times a modest factor
    bound = 100 * np.finfo(float).eps * np.linalg.norm(A) * np.linalg.norm(banded, axis=0)
    assert np.all(residual < bound), residual / bound
    # (measured 4e-13 to 8e-13 across kernels; a step solved in the wrong order is off by O(1))
    assert np.allclose(banded.T @ B @ banded, np.eye(8), atol=1e-10)


def test_a_shear_beam_the_condensation_cannot_take_is_solved_directly():
    """A Timoshenko beam (L/h = 12, κGA = 5/6 G A) of 400 elements, 10 modes: above
    CONDENSE_ABOVE, but the condensed route's check fails on every grouping it may take (160
    groups of 2 or 3 elements: the dynamic correction moves an eigenvalue by 1.7e-3; the
    groups of a shear beam carry more internal dynamics), where it raised.  Its pencil is
    conditioned 800 times better than the Euler–Bernoulli beam's at CONDENSE_ABOVE
    elements (rotary inertia: N², not N⁴), so the route chosen is the direct one (up to
    SHEAR_DIRECT_ELEMENTS: above, the direct residual grows rougher than the condensed
    one's), and the condensed route, forced, falls back to it: the simply supported closed
    form (shear and rotary inertia) within 2e-4, the error falling as h² from 200 elements
    (observed order 2.0), the two routes' frequencies the same."""
    from gfe_opt.modal import (
        SHEAR_DIRECT_ELEMENTS,
        _condensed_modes,
        _shear_beam_condensed,
        condensed,
    )

    from .reference import timoshenko_ss

    length = 0.575
    model = make_model(section={"b": 0.02, "h": length / 12})
    kga = 5 / 6 * model.E / (2 * (1 + model.nu)) * model.area
    model = model.with_effects([Effect("shear", {"shear_rigidity": kga})])
    exact = timoshenko_ss(10, model.bending_rigidity, model.mass_per_length,
                          model.rho * model.inertia, kga, length)
    errors = []
    for n in (200, 400):
        fine = model.with_elements(n)
        f = discretisation_modes(discretise(fine), 10).frequencies_hz
        errors.append(np.max(np.abs(f / exact - 1)))
    fine = discretise(model.with_elements(400))
    assert not condensed(fine) and not _shear_beam_condensed(fine, *fine.global_matrices())
    assert condensed(model.with_elements(SHEAR_DIRECT_ELEMENTS + 1))
    forced = _condensed_modes(fine, 10, None).frequencies_hz
    assert np.max(np.abs(forced / f - 1)) < 1e-12
    assert errors[1] < 2e-4
    assert 1.8 < np.log2(errors[0] / errors[1]) < 2.2
