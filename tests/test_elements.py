"""Generic element matrices: null spaces, positivity, named instances, crack functions."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gfe_opt import elements as el

positive = st.floats(min_value=1e-3, max_value=1e3)


@settings(max_examples=60, deadline=None)
@given(k_ww=positive, k_tt=positive, frac=st.floats(min_value=-0.999, max_value=0.999))
def test_generic_beam_stiffness_null_space_and_positivity(k_ww, k_tt, frac):
    k_wt = frac * np.sqrt(k_ww * k_tt)  # feasible: k_ww k_tt > k_wt^2
    K = el.generic_beam_stiffness(k_ww, k_wt, k_tt)
    assert np.allclose(K, K.T)
    assert np.allclose(K @ el.BEAM_RIGID_MODES, 0.0, atol=1e-9 * k_ww)
    lam = np.linalg.eigvalsh(K)
    assert np.sum(np.abs(lam) < 1e-9 * lam.max()) == 2  # exactly the rigid-body null space
    assert lam.min() > -1e-9 * lam.max()
    assert not el.feasibility_violations(el.BEAM_STIFFNESS_CONDITIONS,
                                         {"k_ww": k_ww, "k_wt": k_wt, "k_tt": k_tt})


@settings(max_examples=60, deadline=None)
@given(k_ww=positive, k_tt=positive, excess=st.floats(min_value=1.001, max_value=10.0))
def test_infeasible_beam_stiffness_is_indefinite_and_named(k_ww, k_tt, excess):
    k_wt = excess * np.sqrt(k_ww * k_tt)
    lam = np.linalg.eigvalsh(el.generic_beam_stiffness(k_ww, k_wt, k_tt))
    assert lam.min() < 0
    names = [v.condition for v in el.feasibility_violations(
        el.BEAM_STIFFNESS_CONDITIONS, {"k_ww": k_ww, "k_wt": k_wt, "k_tt": k_tt})]
    assert names == ["k_ww*k_tt > k_wt^2"]


def test_violations_name_elements():
    params = {"k_ww": np.array([12.0, -1.0, 12.0]), "k_wt": np.array([6.0, 0.0, 6.0]),
              "k_tt": np.array([4.0, 4.0, 1.0])}
    found = {v.condition: v.elements for v in el.feasibility_violations(
        el.BEAM_STIFFNESS_CONDITIONS, params)}
    assert found == {"k_ww > 0": (1,), "k_ww*k_tt > k_wt^2": (1, 2)}


@settings(max_examples=60, deadline=None)
@given(k=positive, beta=st.floats(min_value=-2.0, max_value=0.2499))
def test_generic_bar(k, beta):
    K = el.generic_bar_stiffness(k, 0.5)
    assert np.allclose(K @ el.BAR_RIGID_MODES, 0.0)
    M = el.generic_bar_mass(3.0, 0.5, beta)
    assert np.isclose(M.sum(), 1.5)  # total mass m L
    assert np.linalg.eigvalsh(M).min() > 0


def test_bar_mass_beta_boundary_is_named():
    bad = el.feasibility_violations(el.BAR_CONDITIONS, {"k": 1.0, "beta": 0.3})
    assert [v.condition for v in bad] == ["beta < 1/4"]
    assert np.linalg.eigvalsh(el.generic_bar_mass(1.0, 1.0, 0.3)).min() < 0


def test_bar_consistent_mass_is_linear_shape_function_mass():
    assert np.allclose(el.generic_bar_mass(1.0, 1.0, el.BAR_MASS_BETA["consistent"]),
                       np.array([[2, 1], [1, 2]]) / 6)


def _hermite_mass():
    g, w = np.polynomial.legendre.leggauss(8)
    xi = 0.5 * (g + 1)
    n = el.hermite(xi)
    return np.einsum("q,qi,qj->ij", 0.5 * w, n, n)


def test_consistent_mass_equals_hermite_integral():
    assert np.allclose(el.symmetric_beam_mass(**el.CONSISTENT_BEAM_MASS), _hermite_mass())


@pytest.mark.parametrize("params", [el.CONSISTENT_BEAM_MASS, el.HIGHER_ORDER_BEAM_MASS])
def test_symmetric_mass_total_mass_inertia_and_positivity(params):
    M = el.symmetric_beam_mass(**params)
    t = np.array([1.0, 0, 1, 0])
    rc = np.array([-0.5, 1, 0.5, 1])  # rigid rotation about the centre
    assert np.isclose(t @ M @ t, 1.0)
    assert np.isclose(t @ M @ rc, 0.0)
    assert np.isclose(rc @ M @ rc, 1.0 / 12.0)  # J = m L^2 / 12 of a uniform segment
    assert np.allclose(el.BEAM_SYMMETRY_R.T @ M @ el.BEAM_SYMMETRY_R, M)
    assert np.linalg.eigvalsh(M).min() > 0
    assert not el.feasibility_violations(el.SYMMETRIC_BEAM_MASS_CONDITIONS, params)


@settings(max_examples=80, deadline=None)
@given(st.tuples(*[st.floats(min_value=-0.5, max_value=0.7)] * 4))
def test_mass_conditions_match_eigenvalues(p):
    params = dict(zip(("m11", "m12", "m14", "m22"), p))
    lam_min = np.linalg.eigvalsh(el.symmetric_beam_mass(**params)).min()
    violated = el.feasibility_violations(el.SYMMETRIC_BEAM_MASS_CONDITIONS, params)
    if lam_min > 1e-9:
        assert not violated
    elif lam_min < -1e-9:
        assert violated


def test_symmetric_stiffness_condition():
    ok = {"k_ww": 12.0, "k_tt": 4.0}
    assert not el.feasibility_violations(el.SYMMETRIC_BEAM_STIFFNESS_CONDITIONS, ok)
    bad = {"k_ww": 12.0, "k_tt": 2.9}
    assert [v.condition for v in el.feasibility_violations(
        el.SYMMETRIC_BEAM_STIFFNESS_CONDITIONS, bad)] == ["k_tt > k_ww/4"]
    assert np.linalg.eigvalsh(el.symmetric_beam_stiffness(12.0, 2.9)).min() < 0


def test_euler_bernoulli_is_hermite_integral_of_constant_rigidity():
    eb = el.euler_bernoulli_stiffness(3.0)
    for build in (el.beam_stiffness_from_rigidity, el.beam_stiffness_from_flexibility):
        k = build(lambda x: np.full_like(x, 3.0), 0.2, 0.05)
        assert np.allclose(k, (eb["k_ww"], eb["k_wt"], eb["k_tt"]))


def test_timoshenko_reduces_to_euler_bernoulli_without_shear_deformation():
    stiff, mass = el.timoshenko_parameters(2.0, 1e30, 0.1)
    eb = el.euler_bernoulli_stiffness(2.0)
    assert all(np.isclose(stiff[k], eb[k]) for k in eb)
    assert all(np.isclose(mass[k], el.CONSISTENT_BEAM_MASS[k]) for k in mass)


def test_timoshenko_stiffness_flexibility_adds_shear_compliance():
    # cantilever tip deflection of one element: L^3/(3EI) + L/(kGA)
    EI, kGA, L = 2.0, 50.0, 0.3
    stiff, _ = el.timoshenko_parameters(EI, kGA, L)
    K = el.symmetric_beam_stiffness(stiff["k_ww"], stiff["k_tt"]) / L**3
    T = np.diag([1, L, 1, L])
    Kp = T @ K @ T
    tip = np.linalg.solve(Kp[2:, 2:], [1.0, 0.0])[0]  # clamp node 1, load node 2
    assert np.isclose(tip, L**3 / (3 * EI) + L / kGA)


def test_shear_softens_a_cracked_element_as_a_chain_of_timoshenko_slices_does():
    """One element of a deep beam (L/h = 4) with a crack 0.3 L along it, κGA = 5/6 G A: its
    generic parameters softened by :func:`timoshenko_correction` against the element's end
    stiffness built another way: 1600 uniform Timoshenko slices (eq. 18, each with the
    Christides–Barr EI at its middle), statically condensed to the element's ends (the
    midpoint rule's error falls as the slices' h²: 1.7e-5, 4.2e-6, 1.05e-6 of the largest
    entry at 400, 800, 1600 slices).  Agree to 3e-6; eq. 18 applied as if the element were
    symmetric (k_wθ = k_ww / 2, before) is 1.2 % off, the element without shear 5 % and
    more."""
    from gfe_opt.assembly import discretise
    from gfe_opt.model import Effect

    from .conftest import make_model

    L = 0.2
    base = make_model(length=L, elements=1, section={"b": 0.02, "h": L / 4})
    kga = 5 / 6 * base.E / (2 * (1 + base.nu)) * base.area
    crack = Effect("crack", {"position": 0.3 * L, "depth_ratio": 0.5})
    element = discretise(base.with_effects([crack, Effect("shear", {"shear_rigidity": kga})]))
    K = element.stiffness_elements()[0]
    ei = base.bending_rigidity
    n = 1600
    h = L / n
    mid = (np.arange(n) + 0.5) * h
    q = el.christides_barr_q(mid, 0.3 * L, 0.5, base.depth / 2)
    chain = np.zeros((2 * n + 2, 2 * n + 2))
    for i, EI in enumerate(ei * q):
        stiff, _ = el.timoshenko_parameters(EI, kga, h)
        T = np.diag([1.0, h, 1.0, h])
        k = T @ (el.symmetric_beam_stiffness(stiff["k_ww"], stiff["k_tt"]) / h**3) @ T
        chain[2 * i:2 * i + 4, 2 * i:2 * i + 4] += k
    ends = [0, 1, 2 * n, 2 * n + 1]
    inner = np.arange(2, 2 * n)
    condensed = chain[np.ix_(ends, ends)] - chain[np.ix_(ends, inner)] @ np.linalg.solve(
        chain[np.ix_(inner, inner)], chain[np.ix_(inner, ends)])
    scale = np.max(np.abs(condensed))
    assert np.max(np.abs(K - condensed)) < 3e-6 * scale
    euler = discretise(base.with_effects([crack])).stiffness_elements()[0]
    assert np.max(np.abs(euler - condensed)) > 0.05 * scale


def test_crack_functions():
    # F1 is the integral of pi s F(s)^2 >= 0, growing with depth; F1 ~ pi*1.122^2 s^2/2 near 0
    s = 1e-3
    assert np.isclose(el.crack_function_f1(s), np.pi * 1.1216**2 * s**2 / 2, rtol=2e-2)
    values = [el.crack_function_f1(a) for a in (0.1, 0.3, 0.5)]
    assert values[0] < values[1] < values[2]
    assert el.crack_function_f2(0.3) > el.crack_function_f2(0.1) > 0
    with pytest.raises(ValueError):
        el.crack_function_f1(1.2)


def test_cracked_element_is_softer_and_first_order_agrees_for_thin_elements():
    EI, nu, h, L = 100.0, 0.3, 0.01, 0.5
    full = el.cracked_element_stiffness(EI, nu, h, L, 0.3)
    first = el.cracked_element_stiffness(EI, nu, h, L, 0.3, first_order=True)
    assert full["k_tt"] < 4 * EI and full["k_ww"] <= 12 * EI
    assert np.isclose(full["k_tt"], first["k_tt"], rtol=1e-3)
    assert not el.feasibility_violations(el.SYMMETRIC_BEAM_STIFFNESS_CONDITIONS, full)


def test_christides_barr_q():
    d = 0.015875
    assert np.isclose(el.christides_barr_q(0.3, 0.3, 2 / 3, d), 1 / 27)  # ((d-a)/d)^3 at x_c
    # decay length d / (2 gamma): Q recovers as 1 / (1 + 26 exp(-2 gamma |x - x_c| / d))
    near = el.christides_barr_q(0.3 - 2 * d, 0.3, 2 / 3, d)
    assert np.isclose(near, 1 / (1 + 26 * np.exp(-4 * el.SHEN_PIERRE_GAMMA)))


def test_flexibility_element_holds_a_short_soft_zone_exactly():
    # EI piecewise: a short soft zone in the middle; compare with the exact compliance
    EI, L = 5.0, 0.1

    def rigidity(x):
        return np.where(np.abs(x - 0.05) < 0.005, EI / 10, EI)

    k_ww, k_wt, k_tt = el.beam_stiffness_from_flexibility(rigidity, 0.0, L, (0.045, 0.055))
    Kp = np.diag([1, L, 1, L]) @ el.generic_beam_stiffness(k_ww, k_wt, k_tt) @ np.diag(
        [1, L, 1, L]) / L**3
    # tip rotation of a cantilever (clamped at x = L) under a unit end moment: int 1/EI
    rot = np.linalg.solve(Kp[:2, :2], [0.0, 1.0])[1]
    assert np.isclose(rot, (L - 0.01) / EI + 0.01 / (EI / 10))


def test_casadi_evaluates_the_same_bases_as_numpy():
    # one place for each formula: symbolic parameters go through the same affine bases
    import casadi as ca

    k = ca.SX.sym("k", 3)
    symbolic = ca.Function("K", [k], [el.generic_beam_stiffness(k[0], k[1], k[2])])
    values = np.array([12.0, 5.0, 3.0])
    assert np.allclose(np.array(symbolic(values)), el.generic_beam_stiffness(*values))
    m = ca.SX.sym("m", 4)
    mass = ca.Function("M", [m], [el.symmetric_beam_mass(m[0], m[1], m[2], m[3])])
    params = np.array(list(el.CONSISTENT_BEAM_MASS.values()))
    assert np.allclose(np.array(mass(params)), el.symmetric_beam_mass(*params))
    value = el.SYMMETRIC_BEAM_MASS_CONDITIONS[1].value(dict(zip(("m11", "m12", "m14", "m22"),
                                                                 (m[i] for i in range(4)))))
    det = ca.Function("det", [m], [value])
    assert float(det(params)) > 0
