"""Beam parameterisations: eq. 13 derived symbolically, eq. 23, and what each can represent."""

import numpy as np
import pytest
import sympy

from gfe_opt import elements as el
from gfe_opt.parameterisation import (
    beam_parameterisation,
    derive_nodal_coefficients,
    nodal_coefficients,
)

R = sympy.Rational


def test_eq13_coefficients_from_exact_integration():
    c = derive_nodal_coefficients()
    assert c == sympy.Matrix([[6, R(3, 5), 6, R(-3, 5)],
                              [R(21, 5), R(2, 5), R(9, 5), R(-1, 5)],
                              [R(16, 5), R(1, 3), R(4, 5), R(-2, 15)]])
    # the quadrature the parameterisation uses at run time gives the same numbers
    assert np.allclose(nodal_coefficients(), np.array(c, dtype=float), rtol=0, atol=1e-14)


def test_eq23_linear_is_nodal_with_equal_slopes():
    n, L = 5, 0.1
    k = np.linspace(2.0, 3.0, n + 1)
    slope = np.diff(k) / L
    lin = beam_parameterisation("linear", n, L).element_parameters(k)
    # nodal form with each element's own slope: k'_i = k'_{i+1} = (k_{i+1} - k_i) / L
    nodal = beam_parameterisation("nodal", 1, L)
    for e in range(n):
        p = nodal.element_parameters([k[e], k[e + 1], slope[e], slope[e]])
        assert np.allclose([p["k_ww"][0], p["k_wt"][0], p["k_tt"][0]],
                           [lin["k_ww"][e], lin["k_wt"][e], lin["k_tt"][e]])


@pytest.mark.parametrize("name", ["nodal", "linear", "constant", "element"])
def test_constant_rigidity_is_euler_bernoulli(name):
    n, L, EI = 4, 0.2, 7.0
    par = beam_parameterisation(name, n, L)
    q = par.fit({k: np.full(n, v) for k, v in el.euler_bernoulli_stiffness(EI).items()})
    p = par.element_parameters(q)
    assert np.allclose(p["k_ww"], 12 * EI) and np.allclose(p["k_tt"], 4 * EI)
    assert par.n_params == {"nodal": 2 * n + 2, "linear": n + 1, "constant": n,
                            "element": 3 * n}[name]


def test_nodal_holds_a_cubic_rigidity_exactly():
    # EI(x) cubic: Hermite interpolation is exact, so eq. 13 equals the integrated element
    n, L = 6, 0.05
    x = np.linspace(0, n * L, n + 1)
    coeffs = (3.0, -2.0, 5.0, 40.0)

    def rigidity(s):
        return coeffs[0] + coeffs[1] * s + coeffs[2] * s**2 + coeffs[3] * s**3

    def slope(s):
        return coeffs[1] + 2 * coeffs[2] * s + 3 * coeffs[3] * s**2

    p = beam_parameterisation("nodal", n, L).element_parameters(
        np.concatenate([rigidity(x), slope(x)]))
    for e in range(n):
        exact = el.beam_stiffness_from_rigidity(rigidity, x[e], L)
        assert np.allclose([p["k_ww"][e], p["k_wt"][e], p["k_tt"][e]], exact)


def test_unknown_parameterisation():
    with pytest.raises(ValueError, match="unknown parameterisation"):
        beam_parameterisation("quadratic", 3, 0.1)
