r"""Parameterisations of a beam's generic stiffness: small vectors q -> (k_ww, k_wt, k_tt).

Each parameterisation is linear, :math:`p = A q` with ``p`` the stacked element parameters
``[k_ww (N), k_wt (N), k_tt (N)]`` and ``A`` sparse, so an equation error stays affine in q.

* ``element``: every element's own (k_ww, k_wt, k_tt), 3N parameters (eq. 11);
* ``nodal``: nodal bending stiffness k_i and slope ∂k_i/∂x, 2N+2 parameters (eq. 13);
* ``linear``: k_i only, k varying linearly in each element (eq. 23), N+1 parameters;
* ``constant``: one k per element, k_ww = 12k, k_wt = 6k, k_tt = 4k, N parameters;
* bars: ``element`` (k = EA per element) and ``nodal`` (eq. 7 with c1 = c2 = 1/2).

Eq. 13 is derived here (:func:`derive_nodal_coefficients`) as the exact integral
:math:`\int_0^1 EI(ξ) N''N''^T dξ` of a cubic-Hermite interpolated EI(x) with nodal values
k_i, k_{i+1} and slopes k'_i L, k'_{i+1} L.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

if TYPE_CHECKING:   # loaded where it is used: a diagnosis does not need sympy
    import sympy

PARAMETERISATIONS = ("element", "nodal", "linear", "constant")


@lru_cache(maxsize=1)
def derive_nodal_coefficients() -> sympy.Matrix:
    """Eq. 13 by exact integration: rows k_ww, k_wt, k_tt; columns k_i, k'_i L, k_{i+1},
    k'_{i+1} L (sympy Rationals; sympy is loaded here, not with the module: the fits and a
    diagnosis use :func:`nodal_coefficients`)."""
    import sympy

    xi = sympy.Symbol("xi")
    hermite = [1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3, 3 * xi**2 - 2 * xi**3,
               -(xi**2) + xi**3]
    curv = [sympy.diff(h, xi, 2) for h in hermite]
    rows = []
    for a, b in ((0, 0), (0, 1), (1, 1)):  # K[0,0] = k_ww, K[0,1] = k_wt, K[1,1] = k_tt
        rows.append([sympy.integrate(h * curv[a] * curv[b], (xi, 0, 1)) for h in hermite])
    return sympy.Matrix(rows)


@lru_cache(maxsize=1)
def nodal_coefficients() -> np.ndarray:
    """Eq. 13 as floats (3, 4): the same integral as :func:`derive_nodal_coefficients`,
    evaluated by Gauss quadrature (exact: the integrand has degree 5), without sympy at
    run time."""
    from .elements import _gauss_legendre, hermite, hermite_d2

    g, w = _gauss_legendre(4)
    xi, w = 0.5 * (g + 1.0), 0.5 * w
    h, b = hermite(xi), hermite_d2(xi)
    return np.array([[np.sum(w * h[:, k] * b[:, i] * b[:, j]) for k in range(4)]
                     for i, j in ((0, 0), (0, 1), (1, 1))])


BEAM_KEYS = ("k_ww", "k_wt", "k_tt")
BAR_KEYS = ("k",)


@dataclass(frozen=True)
class Parameterisation:
    """A linear map q -> stacked element parameters, ``[k_ww, k_wt, k_tt]`` (3N,) for a
    beam or ``[k]`` (N,) for a bar."""

    name: str
    matrix: sp.csr_matrix  # (len(keys) N, n_q)
    labels: tuple[str, ...]
    keys: tuple[str, ...] = BEAM_KEYS

    @property
    def n_params(self) -> int:
        return self.matrix.shape[1]

    @property
    def n_elements(self) -> int:
        return self.matrix.shape[0] // len(self.keys)

    def element_parameters(self, q) -> dict:
        p = self.matrix @ np.asarray(q, float)
        n = self.n_elements
        return {k: p[i * n:(i + 1) * n] for i, k in enumerate(self.keys)}

    def fit(self, params: dict) -> np.ndarray:
        """The q whose element parameters are closest (least squares) to ``params``."""
        target = np.concatenate([params[k] for k in self.keys])
        A = self.matrix
        try:
            return spla.splu((A.T @ A).tocsc()).solve(A.T @ target)
        except RuntimeError:  # rank-deficient (e.g. a bar's nodal k): minimum-norm solution
            return spla.lsqr(A, target, atol=1e-15, btol=1e-15, iter_lim=10 * A.shape[1])[0]


def beam_parameterisation(name: str, n_elements: int, element_length: float) -> Parameterisation:
    """Build one of :data:`PARAMETERISATIONS` for N equal elements of length L."""
    n, L = n_elements, element_length
    e = np.arange(n)
    if name == "element":
        return Parameterisation(name, sp.identity(3 * n, format="csr"),
                                tuple(f"{k}[{i}]" for k in ("k_ww", "k_wt", "k_tt")
                                      for i in range(n)))
    if name == "nodal":
        c = nodal_coefficients()  # (3, 4)
        # q = [k_0..k_N, k'_0..k'_N]; element columns k_i, k'_i L, k_{i+1}, k'_{i+1} L
        cols = np.stack([e, n + 1 + e, e + 1, n + 1 + e + 1], axis=1)
        scale = np.array([1.0, L, 1.0, L])
        rows, cs, vals = [], [], []
        for r in range(3):
            rows.append(np.repeat(r * n + e, 4))
            cs.append(cols.ravel())
            vals.append(np.tile(c[r] * scale, n))
        A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cs))),
                          shape=(3 * n, 2 * (n + 1)))
        labels = tuple(f"k[{i}]" for i in range(n + 1)) + tuple(
            f"dk/dx[{i}]" for i in range(n + 1))
        return Parameterisation(name, A, labels)
    if name == "linear":  # eq. 23: k_ww = 6k_i + 6k_j, k_wt = 4k_i + 2k_j, k_tt = 3k_i + k_j
        coef = np.array([[6.0, 6.0], [4.0, 2.0], [3.0, 1.0]])
        rows = np.concatenate([np.repeat(r * n + e, 2) for r in range(3)])
        cols = np.tile(np.stack([e, e + 1], 1).ravel(), 3)
        vals = np.concatenate([np.tile(coef[r], n) for r in range(3)])
        return Parameterisation(name, sp.csr_matrix((vals, (rows, cols)), shape=(3 * n, n + 1)),
                                tuple(f"k[{i}]" for i in range(n + 1)))
    if name == "constant":
        rows = np.concatenate([r * n + e for r in range(3)])
        vals = np.repeat([12.0, 6.0, 4.0], n)
        return Parameterisation(name, sp.csr_matrix((vals, (rows, np.tile(e, 3))),
                                                    shape=(3 * n, n)),
                                tuple(f"k[{i}]" for i in range(n)))
    raise ValueError(f"unknown parameterisation {name!r} (one of {', '.join(PARAMETERISATIONS)})")


BAR_PARAMETERISATIONS = ("element", "nodal")


def bar_parameterisation(name: str, n_elements: int) -> Parameterisation:
    """Bar axial stiffness k = EA per element (``element``, N) or from nodal values with
    eq. 7, :math:`k^{j} = (k_{i-1} + k_i)/2` (c1 = c2 = 1/2, ``nodal``, N+1)."""
    n = n_elements
    e = np.arange(n)
    if name == "element":
        return Parameterisation(name, sp.identity(n, format="csr"),
                                tuple(f"k[{i}]" for i in range(n)), BAR_KEYS)
    if name == "nodal":
        A = sp.csr_matrix((np.full(2 * n, 0.5), (np.repeat(e, 2), np.stack([e, e + 1], 1).ravel())),
                          shape=(n, n + 1))
        return Parameterisation(name, A, tuple(f"k[{i}]" for i in range(n + 1)), BAR_KEYS)
    raise ValueError(f"unknown bar parameterisation {name!r} "
                     f"(one of {', '.join(BAR_PARAMETERISATIONS)})")


def parameterisation_for(kind: str, name: str, n_elements: int,
                         element_length: float) -> Parameterisation:
    """The named parameterisation of a beam or a bar."""
    if kind == "bar":
        return bar_parameterisation(name, n_elements)
    return beam_parameterisation(name, n_elements, element_length)
