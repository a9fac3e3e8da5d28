r"""The paper's rows expanded symbolically (sympy; paper section 3): :func:`taylor_expand_row`
for any stencil of bar or beam DOFs, :func:`bar_row` / :func:`beam_row` for the paper's rows
(eqs. 3, 5; eq. 12 with eq. 13).  Kept apart from :mod:`gfe_opt.realisation`'s numeric
reading so that a diagnosis does not load sympy (half a second of every ``gfe-opt
diagnose``); :mod:`gfe_opt.realisation` still gives these names."""

from __future__ import annotations

import numpy as np
import sympy

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
    from .elements import HERMITE_GRAM
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
    mass = np.array(HERMITE_GRAM)
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
