r"""Physical realisation (paper section 3): discrete equations turned into continuous ones.

A row of :math:`K u + M \ddot u = 0` at node i couples the DOFs of the neighbouring nodes.
Expanding every neighbour's displacement about node i,
:math:`u_{i+s} = \sum_n (sL)^n/n!\; u_i^{(n)}` (a rotation DOF is the slope, so it expands
:math:`u'`), turns the row into a series of differential operators sorted by powers of the
element length L.  Comparing the series with known governing equations tells what physics the
updated matrices hold.

* :func:`taylor_expand_row` — symbolic (sympy), any stencil of bar or beam DOFs;
* :func:`bar_row` / :func:`beam_row` — the paper's rows (eqs. 3, 5; eq. 12 with eq. 13);
* :func:`nodal_equations` — numeric: at every node of a model, the coefficients of
  w, w', w'', w''', w'''' (stiffness side) and ẅ, ẅ'' (mass side) per unit length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy

from .assembly import Discretisation

x, L = sympy.symbols("x L", positive=True)
u = sympy.Function("u")
k = sympy.Function("k")
m = sympy.Function("m")
t = sympy.Symbol("t")


def shift(expr_of_x, offset, order: int):
    """Taylor series of ``expr_of_x`` at x + offset·L about x, up to ``order`` (inclusive)."""
    return sum((offset * L) ** n / sympy.factorial(n) * sympy.diff(expr_of_x, x, n)
               for n in range(order + 1))


def taylor_expand_row(stencil, order: int = 6) -> dict:
    """Sort a discrete row by powers of L.

    ``stencil`` is a list of ``(coefficient, offset, derivative)``: the row holds
    ``coefficient * field^(derivative)(x + offset L)`` (derivative 0 for a displacement,
    1 for a rotation = slope; time derivatives are part of ``field``).  Returns
    ``{power: expression}`` with every power of L up to ``order``.
    """
    total = 0
    for coefficient, offset, field in stencil:
        total += coefficient * shift(field, offset, order)
    total = sympy.expand(total)
    return {p: sympy.simplify(total.coeff(L, p)) for p in range(order + 1)}


def bar_row(c=None, beta=None, order: int = 4):
    r"""Eq. 3 times L, with eq. 7 (k^{j+1} = c1 k_i + c2 k_{i+1}, ...) and k, m expanded
    about node i (``c`` defaults to 1/2 each, ``beta`` to the symbol β).  Returns the L-power
    series of eqs. 5/8/9."""
    c1, c2, c3, c4 = c if c is not None else (sympy.Rational(1, 2),) * 4
    beta = sympy.Symbol("beta") if beta is None else beta
    ui = u(x, t)
    acc = sympy.diff(ui, t, 2)
    k_right = c1 * k(x) + c2 * shift(k(x), 1, order)
    k_left = c1 * shift(k(x), -1, order) + c2 * k(x)
    m_right = c3 * m(x) + c4 * shift(m(x), 1, order)
    m_left = c3 * shift(m(x), -1, order) + c4 * m(x)
    stencil = [(-k_left, -1, ui), (k_left + k_right, 0, ui), (-k_right, 1, ui),
               (L**2 * m_left * beta, -1, acc),
               (L**2 * (m_left + m_right) * (sympy.Rational(1, 2) - beta), 0, acc),
               (L**2 * m_right * beta, 1, acc)]
    return taylor_expand_row(stencil, order)


def beam_row(order: int = 6):
    r"""The translational row at node i of two generic beam elements with eq. 13 stiffness
    from a smooth k(x) and the consistent mass of a smooth m(x) (uniform within each element,
    taken at the element centre), times L³.  The paper's eq. 12 is its L⁴ term."""
    from .elements import CONSISTENT_BEAM_MASS, symmetric_beam_mass
    from .parameterisation import derive_nodal_coefficients

    c = derive_nodal_coefficients()
    wi = u(x, t)
    acc = sympy.diff(wi, t, 2)

    def element_params(offset):
        """Eq. 13 for the element whose left node lies at x + offset L."""
        nodal = [shift(k(x), offset, order), L * shift(sympy.diff(k(x), x), offset, order),
                 shift(k(x), offset + 1, order),
                 L * shift(sympy.diff(k(x), x), offset + 1, order)]
        return [sum(c[r, i] * nodal[i] for i in range(4)) for r in range(3)]

    kl_ww, kl_wt, _ = element_params(-1)   # left element, node i is its node 2
    kr_ww, kr_wt, _ = element_params(0)    # right element, node i is its node 1
    mass = np.array(symmetric_beam_mass(**CONSISTENT_BEAM_MASS))
    mass = sympy.Matrix(4, 4, [sympy.nsimplify(v) for v in mass.ravel()])
    m_left = shift(m(x), sympy.Rational(-1, 2), order)
    m_right = shift(m(x), sympy.Rational(1, 2), order)
    # scaled DOFs [w, L w'] of the nodes at offsets -1, 0, +1
    stencil = [
        # left element, row 3 of eq. 11: [-k_ww, -k_wt, k_ww, -k_ww + k_wt]
        (-kl_ww, -1, wi), (-kl_wt * L, -1, sympy.diff(wi, x)), (kl_ww, 0, wi),
        ((-kl_ww + kl_wt) * L, 0, sympy.diff(wi, x)),
        # right element, row 1: [k_ww, k_wt, -k_ww, k_ww - k_wt]
        (kr_ww, 0, wi), (kr_wt * L, 0, sympy.diff(wi, x)), (-kr_ww, 1, wi),
        ((kr_ww - kr_wt) * L, 1, sympy.diff(wi, x)),
    ]
    for (mm, row, first) in ((m_left, 2, -1), (m_right, 0, 0)):
        for col in range(4):
            node = first + col // 2
            field = acc if col % 2 == 0 else sympy.diff(acc, x)
            scale = 1 if col % 2 == 0 else L
            stencil.append((mm * L**4 * mass[row, col] * scale, node, field))
    return taylor_expand_row(stencil, order)


# -------------------------------------------------------------------------------------------
# Numeric realisation of a discretised model
# -------------------------------------------------------------------------------------------

STIFFNESS_TERMS = ("w", "w'", "w''", "w'''", "w''''")
MASS_TERMS = ("ẅ", "ẅ'", "ẅ''")


@dataclass(frozen=True)
class NodalEquation:
    """Continuous equation represented by node i's translational row, per unit length:
    sum_n stiffness[n] w^(n) + sum_n mass[n] w_tt^(n) = 0."""

    x: float
    stiffness: np.ndarray  # coefficients of w, w', w'', w''', w'''' per unit length
    mass: np.ndarray       # coefficients of ẅ, ẅ', ẅ''


@dataclass(frozen=True)
class Realisation:
    """What node i's updated equation says next to the initial model's, in physical terms:
    (k(x) w'')'' - T w'' + k_f w + m ẅ = 0, with k'' taken from neighbouring nodes."""

    x: float
    k_ratio: float       # k / k0, from the coefficient of the fourth derivative
    tension: float       # T [N] in -T w'' beyond what (k w'')'' explains
    foundation: float    # k_f [N/m^2], coefficient of w beyond the initial model's
    mass_ratio: float    # m / m0, from the coefficient of the acceleration

    def describe(self) -> str:
        """The local reading; uniform terms (tension, foundation) are read along the whole
        beam by :func:`summarise`, since one node's w'' and w terms also carry k''."""
        text = f"near x = {self.x:.3f} m: (k(x) w'')'' + m ẅ = 0 with k = {self.k_ratio:.2f} k0"
        if abs(self.mass_ratio - 1) > 1e-3:
            text += f", m = {self.mass_ratio:.2f} m0"
        return text


def realise(disc: Discretisation, initial: Discretisation, significance: float = 1e-3
            ) -> list[Realisation]:
    """Compare the nodal equations of an updated (or fitted) model with the initial model's.

    Terms below ``significance`` of their natural scale (k0 (π/ℓ)², k0 (π/ℓ)⁴ with ℓ the
    length of the structure) are reported as zero.
    """
    new, old = nodal_equations(disc), nodal_equations(initial)
    x = np.array([e.x for e in new])
    c4 = np.array([e.stiffness[4] for e in new])
    k0 = float(np.mean([e.stiffness[4] for e in old]))
    m0 = float(np.mean([e.mass[0] for e in old]))
    length = disc.nodes[-1] - disc.nodes[0]
    kpp = np.gradient(np.gradient(c4, x), x)
    out = []
    for i, (a, b) in enumerate(zip(new, old)):
        tension = -((a.stiffness[2] - kpp[i]) - b.stiffness[2])
        foundation = a.stiffness[0] - b.stiffness[0]
        if abs(tension) < significance * k0 * (np.pi / length) ** 2:
            tension = 0.0
        if abs(foundation) < significance * k0 * (np.pi / length) ** 4:
            foundation = 0.0
        out.append(Realisation(float(a.x), float(a.stiffness[4] / k0), float(tension),
                               float(foundation), float(a.mass[0] / m0)))
    return out


def nodal_equations(disc: Discretisation, K=None, M=None) -> list[NodalEquation]:
    """Numeric Taylor expansion of every interior node's translational row (beam) or row
    (bar) of the assembled K and M; coefficients per unit length (divided by the element
    length, as the row integrates over two half elements)."""
    if K is None or M is None:
        K, M = disc.global_matrices()
    K, M = K.tocsr(), M.tocsr()
    nodes = disc.nodes
    L = disc.element_length
    per = disc.dofs_per_node
    out = []
    for i in range(1, len(nodes) - 1):
        row = per * i
        stiff = np.zeros(5)
        mass = np.zeros(3)
        for j in (i - 1, i, i + 1):
            h = nodes[j] - nodes[i]
            for d in range(per):
                col = per * j + d
                kv, mv = K[row, col], M[row, col]
                # a displacement DOF expands w^(n) h^n/n!; a rotation DOF (slope) w^(n+1) h^n/n!
                for n in range(5):
                    p = n - d
                    if p >= 0:
                        stiff[n] += kv * h**p / math.factorial(p)
                for n in range(3):
                    p = n - d
                    if p >= 0:
                        mass[n] += mv * h**p / math.factorial(p)
        out.append(NodalEquation(float(nodes[i]), stiff / L, mass / L))
    return out


def summarise(realisations: list[Realisation]) -> list[str]:
    """The physics the nodal equations point to, in words (uniform terms by their median,
    local ones by their extreme node)."""
    k = np.array([r.k_ratio for r in realisations])
    m = np.array([r.mass_ratio for r in realisations])
    tension = _uniform([r.tension for r in realisations])
    foundation = _uniform([r.foundation for r in realisations])
    lines = []
    if abs(np.median(k) - 1) > 5e-3:
        lines.append(f"uniform bending stiffness {np.median(k):.3f} k0 (a material change)")
    i = int(np.argmin(k))
    if k[i] < 0.95 * np.median(k):
        lines.append(f"local stiffness loss: {realisations[i].describe()}")
    if tension:
        lines.append(f"a -T w'' term along the beam with T = {tension:.4g} N (axial load)")
    if foundation:
        lines.append(f"a k_f w term along the beam with k_f = {foundation:.4g} N/m² "
                     "(elastic foundation)")
    j = int(np.argmax(m))
    if m[j] > 1.05:
        lines.append(f"local mass {m[j]:.2f} m0 near x = {realisations[j].x:.3f} m "
                     "(attached mass)")
    return lines


def _uniform(values) -> float:
    """The median of a term that is present along the whole beam with one sign and a small
    spread (80 % of the nodes, interquartile range below half the median), else 0."""
    v = np.asarray(values, float)
    med = float(np.median(v))
    if med == 0.0 or np.mean(np.sign(v) == np.sign(med)) < 0.8:
        return 0.0
    q1, q3 = np.percentile(v, [25, 75])
    return med if (q3 - q1) < 0.5 * abs(med) else 0.0
