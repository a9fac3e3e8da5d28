r"""Generic element matrices (Ahmadian, Mottershead & Friswell 2002, section 2).

Every generic element is an *affine* function of its parameters,

.. math:: \mathbf K(p) = \mathbf K_0 + \sum_b p_b \mathbf K_b ,

stored once here as a constant matrix and a basis of matrices.  numpy (vectorised over
elements) and CasADi (symbolic parameters) evaluate the same bases, so each formula lives in
one place.

Degrees of freedom follow the paper:

* bar: ``[u_i, u_{i+1}]``; :math:`K = (k/L)\,[\ldots]`, :math:`M = mL\,[\ldots]` (eq. 2);
* beam: ``[w_i, L θ_i, w_{i+1}, L θ_{i+1}]`` (rotations scaled by the element length);
  :math:`K = L^{-3}\,[\ldots]` (eq. 11), :math:`M = ρ A L\,[\ldots]` (eq. 17).

:func:`beam_dof_scaling` converts to physical DOFs ``[w, θ]``.  SI units throughout.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Mapping

import numpy as np

# --------------------------------------------------------------------------------------
# Affine bases (the one place where the element formulas live)
# --------------------------------------------------------------------------------------

#: eq. 2: bar stiffness K = (k / L) * BAR_STIFFNESS_BASIS["k"]
BAR_STIFFNESS_BASIS = {"k": np.array([[1.0, -1.0], [-1.0, 1.0]])}
#: eq. 2: bar mass M = m L * (BAR_MASS_CONSTANT + beta * BAR_MASS_BASIS["beta"])
BAR_MASS_CONSTANT = np.array([[0.5, 0.0], [0.0, 0.5]])
BAR_MASS_BASIS = {"beta": np.array([[-1.0, 1.0], [1.0, -1.0]])}

#: eq. 11: generic beam stiffness L^3 K = k_ww B_ww + k_wt B_wt + k_tt B_tt
BEAM_STIFFNESS_BASIS = {
    "k_ww": np.array(
        [[1.0, 0, -1, 1], [0, 0, 0, 0], [-1, 0, 1, -1], [1, 0, -1, 1]], dtype=float
    ),
    "k_wt": np.array(
        [[0.0, 1, 0, -1], [1, 0, -1, 1], [0, -1, 0, 1], [-1, 1, 1, -2]], dtype=float
    ),
    "k_tt": np.array(
        [[0.0, 0, 0, 0], [0, 1, 0, -1], [0, 0, 0, 0], [0, -1, 0, 1]], dtype=float
    ),
}
#: eq. 16: symmetric generic beam stiffness (k_wt = k_ww / 2)
SYMMETRIC_BEAM_STIFFNESS_BASIS = {
    "k_ww": BEAM_STIFFNESS_BASIS["k_ww"] + 0.5 * BEAM_STIFFNESS_BASIS["k_wt"],
    "k_tt": BEAM_STIFFNESS_BASIS["k_tt"],
}


def _sym(entries: Mapping[tuple[int, int], float]) -> np.ndarray:
    out = np.zeros((4, 4))
    for (i, j), v in entries.items():
        out[i, j] = out[j, i] = v
    return out


#: eq. 17: symmetric generic beam mass M / (ρ A L) = C + m11 A11 + m12 A12 + m14 A14 + m22 A22,
#: with m13 = 1/2 - m11, m23 = -m14, m34 = -m12, m24 = 1/6 - m11/2 + m12 + m14 - m22.
SYMMETRIC_BEAM_MASS_CONSTANT = _sym({(0, 2): 0.5, (1, 3): 1.0 / 6.0})
SYMMETRIC_BEAM_MASS_BASIS = {
    "m11": _sym({(0, 0): 1.0, (2, 2): 1.0, (0, 2): -1.0, (1, 3): -0.5}),
    "m12": _sym({(0, 1): 1.0, (2, 3): -1.0, (1, 3): 1.0}),
    "m14": _sym({(0, 3): 1.0, (1, 2): -1.0, (1, 3): 1.0}),
    "m22": _sym({(1, 1): 1.0, (3, 3): 1.0, (1, 3): -1.0}),
}

#: Rigid-body modes (columns) of the bar and of the beam in the paper's scaled DOFs.
BAR_RIGID_MODES = np.array([[1.0], [1.0]])
BEAM_RIGID_MODES = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.0, 1.0]])
#: eq. 15: the symmetry transform of a beam element (swap the nodes, reverse rotations).
BEAM_SYMMETRY_R = np.array(
    [[0.0, 0, 1, 0], [0, 0, 0, -1], [1, 0, 0, 0], [0, -1, 0, 0]]
)


def affine_matrix(constant, basis: Mapping[str, np.ndarray], params: Mapping[str, object]):
    """Evaluate ``constant + Σ_b params[b] * basis[b]``.

    numpy parameters may be arrays of shape (n_elements,); the result then has shape
    (n_elements, n, n).  Any other scalar type (e.g. CasADi ``SX``/``MX``) is combined term by
    term, so the same basis serves symbolic formulations.
    """
    names = list(basis)
    first = params[names[0]]
    if isinstance(first, (int, float, np.ndarray, np.generic)):
        values = [np.asarray(params[n], dtype=float) for n in names]
        shape = values[0].shape
        if any(v.shape != shape for v in values):
            shape = np.broadcast_shapes(*(v.shape for v in values))
            values = [np.broadcast_to(v, shape) for v in values]
        out = np.zeros(shape + basis[names[0]].shape)
        if constant is not None:
            out += constant
        for n, v in zip(names, values):
            out += v[..., None, None] * basis[n]
        return out
    total = 0 if constant is None else constant
    for n in names:
        total = total + params[n] * basis[n]
    return total


def generic_bar_stiffness(k, L):
    """eq. 2: bar stiffness (2, 2) or (n, 2, 2) for axial rigidity ``k = EA`` [N], length L [m]."""
    return affine_matrix(None, BAR_STIFFNESS_BASIS, {"k": np.asarray(k) / np.asarray(L)})


def generic_bar_mass(m, L, beta):
    """eq. 2: bar mass for mass per length ``m`` [kg/m], length L, mass parameter β."""
    scale = np.asarray(m * L, dtype=float)[..., None, None]
    return scale * affine_matrix(BAR_MASS_CONSTANT, BAR_MASS_BASIS, {"beta": beta})


def generic_beam_stiffness(k_ww, k_wt, k_tt):
    r"""eq. 11: :math:`L^3 K` of a generic beam element in scaled DOFs ``[w, Lθ, w, Lθ]``."""
    return affine_matrix(None, BEAM_STIFFNESS_BASIS, {"k_ww": k_ww, "k_wt": k_wt, "k_tt": k_tt})


def symmetric_beam_stiffness(k_ww, k_tt):
    """eq. 16: :math:`L^3 K` of a symmetric generic beam element (k_wt = k_ww / 2)."""
    return affine_matrix(None, SYMMETRIC_BEAM_STIFFNESS_BASIS, {"k_ww": k_ww, "k_tt": k_tt})


def symmetric_beam_mass(m11, m12, m14, m22):
    """eq. 17: :math:`M / (ρ A L)` of a symmetric generic beam element in scaled DOFs."""
    params = {"m11": m11, "m12": m12, "m14": m14, "m22": m22}
    return affine_matrix(SYMMETRIC_BEAM_MASS_CONSTANT, SYMMETRIC_BEAM_MASS_BASIS, params)


#: eq. 11 as :math:`H^T P H`: relative deformations ``d = H u`` of the scaled element DOFs
#: (deflection and rotation of node i relative to node j) and P = [[k_ww, k_wt], [k_wt, k_tt]].
BEAM_DEFORMATION_H = np.array([[1.0, 0.0, -1.0, 1.0], [0.0, 1.0, 0.0, -1.0]])


def beam_dof_scaling(L):
    """Diagonal of T with ``[w, Lθ, w, Lθ] = T [w, θ, w, θ]``; physical K = T K_scaled T
    (read-only for one length: kept, every element of a mesh asks for it)."""
    if isinstance(L, (float, int, np.floating)):
        return _scalar_dof_scaling(float(L))
    L = np.asarray(L, dtype=float)
    one = np.ones_like(L)
    return np.stack([one, L, one, L], axis=-1)


@lru_cache(maxsize=64)
def _scalar_dof_scaling(L: float) -> np.ndarray:
    out = np.array([1.0, L, 1.0, L])
    out.flags.writeable = False
    return out


# --------------------------------------------------------------------------------------
# Feasibility conditions (each must be > 0)
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Condition:
    """A named feasibility condition ``value(params) > 0`` (numpy or CasADi arithmetic)."""

    name: str
    value: Callable[[Mapping[str, object]], object]


def _mass_blocks(p):
    """Symmetric/antisymmetric 2x2 blocks of the eq. 17 mass (R-invariant subspaces)."""
    m24 = 1.0 / 6.0 - p["m11"] / 2.0 + p["m12"] + p["m14"] - p["m22"]
    sym = (0.5, p["m12"] - p["m14"], p["m22"] - m24)
    anti = (2.0 * p["m11"] - 0.5, p["m12"] + p["m14"], p["m22"] + m24)
    return sym, anti


BAR_CONDITIONS = (
    Condition("k > 0", lambda p: p["k"]),
    Condition("beta < 1/4", lambda p: 0.25 - p["beta"]),
)
BEAM_STIFFNESS_CONDITIONS = (
    Condition("k_ww > 0", lambda p: p["k_ww"]),
    Condition("k_tt > 0", lambda p: p["k_tt"]),
    Condition("k_ww*k_tt > k_wt^2", lambda p: p["k_ww"] * p["k_tt"] - p["k_wt"] ** 2),
)
SYMMETRIC_BEAM_STIFFNESS_CONDITIONS = (
    Condition("k_ww > 0", lambda p: p["k_ww"]),
    Condition("k_tt > k_ww/4", lambda p: p["k_tt"] - p["k_ww"] / 4.0),
)
SYMMETRIC_BEAM_MASS_CONDITIONS = (
    Condition("mass antisymmetric block: 2*m11 - 1/2 > 0", lambda p: _mass_blocks(p)[1][0]),
    Condition(
        "mass antisymmetric block: det > 0",
        lambda p: _mass_blocks(p)[1][0] * _mass_blocks(p)[1][2] - _mass_blocks(p)[1][1] ** 2,
    ),
    Condition("mass symmetric block: m22 - m24 > 0", lambda p: _mass_blocks(p)[0][2]),
    Condition(
        "mass symmetric block: det > 0",
        lambda p: _mass_blocks(p)[0][0] * _mass_blocks(p)[0][2] - _mass_blocks(p)[0][1] ** 2,
    ),
)


@dataclass(frozen=True)
class Violation:
    """A violated feasibility condition and the (0-based) elements that violate it."""

    condition: str
    elements: tuple[int, ...]

    def __str__(self) -> str:
        return f"{self.condition} violated by element(s) {list(self.elements)}"


def feasibility_violations(conditions, params, margin: float = 0.0) -> list[Violation]:
    """Conditions of ``conditions`` that ``params`` (scalars or per-element arrays) violate.

    A condition holds when its value exceeds ``margin`` (``margin = 0``: strict inequality).
    """
    out = []
    for cond in conditions:
        value = np.atleast_1d(np.asarray(cond.value(params), dtype=float))
        bad = np.flatnonzero(~(value > margin))
        if bad.size:
            out.append(Violation(cond.name, tuple(int(i) for i in bad)))
    return out


# --------------------------------------------------------------------------------------
# Named physical instances (parameter choices)
# --------------------------------------------------------------------------------------

#: Bar mass parameter β (eq. 2): lumped, consistent (linear), harmonic, minimum error.
BAR_MASS_BETA = {"lumped": 0.0, "consistent": 1.0 / 6.0, "harmonic": 1.0 / 8.0,
                 "minimum_error": 1.0 / 12.0}
#: Euler–Bernoulli consistent mass (cubic Hermite shape functions).  The paper prints
#: m14 = 13/420; the entry of the consistent matrix in position (1, 4) is −13/420.
CONSISTENT_BEAM_MASS = {"m11": 13 / 35, "m12": 11 / 210, "m14": -13 / 420, "m22": 1 / 105}
#: The "higher-order" mass as the paper prints it (after Stavrinidis et al.).  Measured here
#: (tests/test_modal.py): its eigenvalue error is -(kh)^4/360, 4th order, not 6th.
PAPER_HIGHER_ORDER_BEAM_MASS = {"m11": 163 / 420, "m12": 51 / 840, "m14": -19 / 840,
                                "m22": 15 / 840}
#: A 6th-order mass of the eq. 17 family: (2 x consistent + printed higher-order) / 3, the
#: combination whose (kh)^4 error terms (+1/720 and -1/360) cancel.  Used as "higher_order".
HIGHER_ORDER_BEAM_MASS = {k: (2 * CONSISTENT_BEAM_MASS[k] + PAPER_HIGHER_ORDER_BEAM_MASS[k]) / 3
                          for k in CONSISTENT_BEAM_MASS}


def euler_bernoulli_stiffness(EI):
    """Euler–Bernoulli beam: k_ww = 12 EI, k_wt = 6 EI, k_tt = 4 EI [N m²]."""
    EI = np.asarray(EI, dtype=float)
    return {"k_ww": 12.0 * EI, "k_wt": 6.0 * EI, "k_tt": 4.0 * EI}


def shear_parameter(EI, shear_rigidity, L):
    r"""Timoshenko :math:`g = 12 EI / (κ G A L^2)` (the paper's :math:`C EI / (G A L^2)`)."""
    return 12.0 * np.asarray(EI) / (np.asarray(shear_rigidity) * np.asarray(L) ** 2)


def timoshenko_parameters(EI, shear_rigidity, L):
    """eq. 18: Timoshenko stiffness and translational-mass parameters of a symmetric element.

    Returns ``(stiffness, mass)`` dicts; ``stiffness`` includes ``k_wt = k_ww / 2``.
    """
    g = shear_parameter(EI, shear_rigidity, L)
    d = (1.0 + g) ** 2
    stiffness = timoshenko_correction(euler_bernoulli_stiffness(EI), g)
    mass = {
        "m11": (13 / 35 + 7 / 10 * g + g**2 / 3) / d,
        "m12": (11 / 210 + 11 / 120 * g + g**2 / 24) / d,
        "m14": -(13 / 420 + 3 / 40 * g + g**2 / 24) / d,
        "m22": (1 / 105 + g / 60 + g**2 / 120) / d,
    }
    return stiffness, mass


def timoshenko_correction(bending, g):
    """Each element's shear compliance added to its bending flexibility: k_ww / (1 + g),
    k_wθ / (1 + g), k_θθ − g / (1 + g) · k_wθ² / k_ww, with g = k_ww / (κGA L²) (the
    element's own: 12 EI / (κGA L²) for a uniform one).

    The generic parameters P = [[k_ww, k_wθ], [k_wθ, k_θθ]] (eq. 11) are L³ times the
    stiffness of the relative deformations d = H u, a relative deflection d₁ and a relative
    rotation d₂, whose flexibility is L³ P⁻¹; a shear force, constant along the element,
    adds V L / κGA to d₁ alone, so P' = (P⁻¹ + diag(1/(κGA L²), 0))⁻¹, the closed form
    above.  For an Euler–Bernoulli element (12EI, 6EI, 4EI) it is eq. 18 (k_θθ (4 + g) /
    (4 (1 + g)), k_wθ = k_ww / 2); an element whose EI varies (beside a crack) keeps its own
    k_wθ, which eq. 18 applied as if the element were symmetric took as k_ww / 2 (25 % off
    beside a crack of a/d 0.5, for any κGA however large).
    """
    k_ww, k_wt, k_tt = (np.asarray(bending[k], dtype=float) for k in ("k_ww", "k_wt", "k_tt"))
    soft = 1.0 / (1.0 + np.asarray(g, dtype=float))
    return {"k_ww": k_ww * soft, "k_wt": k_wt * soft,
            "k_tt": k_tt - (1.0 - soft) * k_wt**2 / k_ww}


def timoshenko_rotary_inertia(rho_I, L, g=0.0):
    r"""Rotary-inertia mass of a Timoshenko element (Przemieniecki), scaled DOFs.

    ``rho_I`` is ρI [kg m]; the physical matrix is :math:`T R T` with :func:`beam_dof_scaling`.
    """
    g = np.asarray(g, dtype=float)
    d = (1.0 + g) ** 2
    r11 = np.full_like(g, 6.0 / 5.0)
    r12 = 1.0 / 10.0 - g / 2.0
    r22 = 2.0 / 15.0 + g / 6.0 + g**2 / 3.0
    r24 = -1.0 / 30.0 - g / 6.0 + g**2 / 6.0
    out = np.stack(
        [
            np.stack([r11, r12, -r11, r12], -1),
            np.stack([r12, r22, -r12, r24], -1),
            np.stack([-r11, -r12, r11, -r12], -1),
            np.stack([r12, r24, -r12, r22], -1),
        ],
        -2,
    )
    return (np.asarray(rho_I) / np.asarray(L) / d)[..., None, None] * out


# --------------------------------------------------------------------------------------
# Cracked element (eqs. 19-22) and the Christides–Barr disturbance function (eq. 25)
# --------------------------------------------------------------------------------------


def crack_function_f1(depth_ratio: float) -> float:
    r"""eq. 20 with the Tada bending geometry function (exponent 4 restored):

    .. math:: F_1 = \int_0^{a/h} \frac{2\tan(πs/2)\,[0.923 + 0.199(1-\sin(πs/2))^4]^2}
              {\cos^2(πs/2)}\,ds
    """
    _check_depth_ratio(depth_ratio)

    def integrand(s):
        t = 0.5 * np.pi * s
        return 2.0 * np.tan(t) * (0.923 + 0.199 * (1.0 - np.sin(t)) ** 4) ** 2 / np.cos(t) ** 2

    from scipy import integrate  # (here, not at import: 0.2 s of every start)

    return integrate.quad(integrand, 0.0, depth_ratio, limit=200)[0]


def crack_function_f2(depth_ratio: float) -> float:
    r"""eq. 21: :math:`F_2 = \int_0^{a/h} \frac{πs^2}{1-s}(3-2s)^2
    (1.122 - 0.561s + 0.085s^2 + 0.18s^3)^2\,ds`."""
    _check_depth_ratio(depth_ratio)

    def integrand(s):
        poly = 1.122 - 0.561 * s + 0.085 * s**2 + 0.18 * s**3
        return np.pi * s**2 / (1.0 - s) * (3.0 - 2.0 * s) ** 2 * poly**2

    from scipy import integrate

    return integrate.quad(integrand, 0.0, depth_ratio, limit=200)[0]


def _check_depth_ratio(depth_ratio):
    if not 0.0 <= depth_ratio < 1.0:
        raise ValueError(f"crack depth ratio must lie in [0, 1), got {depth_ratio}")


def cracked_element_stiffness(EI, nu, thickness, L, depth_ratio, first_order=False):
    """eqs. 19 (or 22 with ``first_order``): symmetric element with a crack at mid-length.

    Returns ``{"k_ww", "k_wt", "k_tt"}`` with ``k_wt = k_ww / 2``; α = thickness / L.
    """
    alpha = thickness / L
    c = 1.0 - nu**2
    f1 = crack_function_f1(depth_ratio)
    if first_order:
        k_ww = 12.0 * EI
        k_tt = EI * (4.0 - 6.0 * c * alpha * f1)
    else:
        f2 = crack_function_f2(depth_ratio)
        k_ww = 12.0 * EI / (1.0 + c * alpha**3 * f2)
        k_tt = EI * (4.0 + c * (18.0 * alpha * f1 + 2.0 * alpha**3 * f2)) / (
            (1.0 + 6.0 * c * alpha * f1) * (1.0 + 2.0 * c * alpha**3 * f2)
        )
    return {"k_ww": k_ww, "k_wt": k_ww / 2.0, "k_tt": k_tt}


#: Shen & Pierre's decay constant for symmetric cracks.
SHEN_PIERRE_GAMMA = 1.936


def christides_barr_q(x, position, depth_ratio, half_depth, gamma=SHEN_PIERRE_GAMMA):
    r"""eq. 25: crack disturbance :math:`Q(x) = 1/(1 + ((d/(d-a))^3 - 1) e^{-2γ|x-x_c|/d})`.

    ``half_depth`` is d (half the beam depth; the beam is cut symmetrically from both faces,
    each cut of depth a) and ``depth_ratio`` is a/d.
    """
    _check_depth_ratio(depth_ratio)
    strength = (1.0 / (1.0 - depth_ratio)) ** 3 - 1.0
    decay = np.exp(-2.0 * gamma * np.abs(np.asarray(x, dtype=float) - position) / half_depth)
    return 1.0 / (1.0 + strength * decay)


# --------------------------------------------------------------------------------------
# Shape functions and elements integrated from a distribution EI(x)
# --------------------------------------------------------------------------------------


def hermite(xi):
    """Cubic Hermite functions (n, 4) for scaled DOFs ``[w_i, Lθ_i, w_j, Lθ_j]``, ξ in [0, 1]."""
    xi = np.asarray(xi, dtype=float)
    out = np.empty(xi.shape + (4,))
    xi2, xi3 = xi**2, xi**3
    out[..., 0] = 1 - 3 * xi2 + 2 * xi3
    out[..., 1] = xi - 2 * xi2 + xi3
    out[..., 2] = 3 * xi2 - 2 * xi3
    out[..., 3] = -xi2 + xi3
    return out


def hermite_d2(xi):
    """Second ξ-derivatives of :func:`hermite` (curvature is ``hermite_d2 / L²``)."""
    xi = np.asarray(xi, dtype=float)
    return np.stack([-6 + 12 * xi, -4 + 6 * xi, 6 - 12 * xi, -2 + 6 * xi], axis=-1)


def hermite_d1(xi):
    """First ξ-derivatives of :func:`hermite` (slope is ``hermite_d1 / L``)."""
    xi = np.asarray(xi, dtype=float)
    return np.stack([-6 * xi + 6 * xi**2, 1 - 4 * xi + 3 * xi**2, 6 * xi - 6 * xi**2,
                     -2 * xi + 3 * xi**2], axis=-1)


def linear(xi):
    """Linear bar shape functions (n, 2)."""
    xi = np.asarray(xi, dtype=float)
    return np.stack([1 - xi, xi], axis=-1)


@lru_cache(maxsize=8)
def _gauss_legendre(order: int):
    return np.polynomial.legendre.leggauss(order)


def element_quadrature(x0, x1, breakpoints=(), refine_scale=None, order=6):
    """Composite Gauss–Legendre points and weights on [x0, x1] (physical coordinates).

    The interval is split at every breakpoint inside it; with ``refine_scale`` the pieces
    next to a breakpoint are graded geometrically (ℓ/4 … 32ℓ) so that a kink such as
    ``exp(-|x - x_c|/ℓ)`` is integrated to near machine precision.
    """
    cuts = {x0, x1}
    for b in breakpoints:
        offsets = [0.0]
        if refine_scale is not None:
            offsets += [s * refine_scale for s in (0.25, 0.5, 1, 2, 4, 8, 16, 32)]
        for o in offsets:
            for c in (b - o, b + o):
                if x0 < c < x1:
                    cuts.add(c)
    cuts = np.array(sorted(cuts))
    x, w = element_quadratures(cuts[:-1], cuts[1:], order)
    return x.ravel(), w.ravel()


def element_quadratures(x0, x1, order=6):
    """Gauss–Legendre points and weights on each interval [x0, x1] (arrays), one row an
    interval (len(x0), order): :func:`element_quadrature`'s pieces, and the elements with
    no breakpoint inside at once (each row the numbers the element's own call gives)."""
    g, w = _gauss_legendre(order)
    a = np.asarray(x0, dtype=float)[:, None]
    b = np.asarray(x1, dtype=float)[:, None]
    return 0.5 * (b - a) * g + 0.5 * (a + b), 0.5 * (b - a) * w


def beam_stiffness_from_rigidity(rigidity, x0, L, breakpoints=(), refine_scale=None):
    r"""Generic parameters of :math:`K_e = \int EI(x) B B^T dx` (Hermite curvatures).

    ``rigidity`` maps positions [m] to EI [N m²]; returns ``(k_ww, k_wt, k_tt)`` such that
    :func:`generic_beam_stiffness` gives :math:`L^3 K_e`.
    """
    x, w = element_quadrature(x0, x0 + L, breakpoints, refine_scale)
    b = hermite_d2((x - x0) / L)
    k = np.einsum("q,qi,qj->ij", w * rigidity(x), b, b) / L
    return k[0, 0], k[0, 1], k[1, 1]


def beam_stiffness_from_flexibility(rigidity, x0, L, breakpoints=(), refine_scale=None):
    r"""Generic parameters of the *exact static* element of a beam with rigidity EI(x).

    The flexibility of the element clamped at its right node and loaded at its left node,

    .. math:: F = \int_0^L \frac{1}{EI(x_0 + s)} \begin{bmatrix} s^2 & -s \\ -s & 1
              \end{bmatrix} ds ,

    is inverted and spread over the four DOFs with the rigid-body map
    :math:`H = [[1, 0, -1, L], [0, 1, 0, -1]]`: :math:`K_e = H^T F^{-1} H`.  Unlike
    :func:`beam_stiffness_from_rigidity` it holds a short stiffness loss (a crack zone) exactly
    for nodal loads, whatever the element size.  Returns ``(k_ww, k_wt, k_tt)`` of eq. 11.
    """
    x, w = element_quadrature(x0, x0 + L, breakpoints, refine_scale)
    return flexibility_parameters(x - x0, w / rigidity(x), L)


def flexibility_parameters(s, c, L):
    r"""``(k_ww, k_wt, k_tt)`` of the exact static element from quadrature: ``s`` local
    coordinates and ``c`` = weights / EI at the points (last axis; leading axes are
    elements).  With :math:`f_n = \sum c\, s^n`, :math:`F = [[f_2, -f_1], [-f_1, f_0]]` and
    in scaled DOFs :math:`k_{ww} = L^3 f_0/Δ`, :math:`k_{wθ} = L^2 f_1/Δ`,
    :math:`k_{θθ} = L f_2/Δ`, :math:`Δ = f_2 f_0 - f_1^2`."""
    f0 = np.sum(c, axis=-1)
    f1 = np.sum(c * s, axis=-1)
    f2 = np.sum(c * s * s, axis=-1)
    det = f2 * f0 - f1 * f1
    return L**3 * f0 / det, L**2 * f1 / det, L * f2 / det


#: ∫ N Nᵀ dx / L of the cubic Hermite element in scaled DOFs [w₁, Lθ₁, w₂, Lθ₂]: the
#: consistent mass per ρAL, and a Winkler foundation's stiffness per k_f L (beam and frame)
HERMITE_GRAM = symmetric_beam_mass(**CONSISTENT_BEAM_MASS)
HERMITE_GRAM.flags.writeable = False
