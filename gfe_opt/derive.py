r"""Generic element families derived from their constraints (paper eqs. 1, 14, 15).

An element matrix :math:`X` (symmetric, n x n) is generic when it satisfies the linear
constraints that hold for *every* physically admissible element:

* stiffness: :math:`K Φ_R = 0` (the rigid-body modes span the null space, eq. 1);
* mass: :math:`Φ_R^T M Φ_R = \mathrm{diag}(m, J)` (total mass and inertia, eq. 1);
* geometric symmetry: :math:`X = R^T X R` (eqs. 14-15).

The solutions form an affine family :math:`X(p) = X_0 + \sum_b p_b X_b`, found here from the
null space of the constraint system, numerically (SVD) or symbolically (sympy).  Positivity
(K ⪰ 0, M ≻ 0) is an inequality on p; see :mod:`gfe_opt.elements` for the named conditions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import sympy


@dataclass(frozen=True)
class GenericFamily:
    """An affine family of symmetric matrices: ``constant + Σ_b p_b basis[b]``."""

    constant: np.ndarray
    basis: np.ndarray  # (n_params, n, n)

    @property
    def n_params(self) -> int:
        return self.basis.shape[0]

    def __call__(self, p) -> np.ndarray:
        return self.constant + np.tensordot(np.asarray(p, float), self.basis, axes=1)

    def contains(self, matrix, tol: float = 1e-9) -> bool:
        """True when ``matrix`` belongs to the family (least-squares residual below tol)."""
        a = self.basis.reshape(self.n_params, -1).T
        target = (np.asarray(matrix, float) - self.constant).ravel()
        if a.size == 0:
            return bool(np.linalg.norm(target) <= tol * max(1.0, np.linalg.norm(matrix)))
        p, *_ = np.linalg.lstsq(a, target, rcond=None)
        scale = max(1.0, np.linalg.norm(matrix))
        return bool(np.linalg.norm(a @ p - target) <= tol * scale)


def _constraint_system(n, null_space, rigid_modes, rigid_mass, symmetry):
    """Linear equations (rows of A, b) on the upper-triangular entries of X."""
    rows, rhs = [], []

    def add(expr_coeffs, value):
        rows.append(expr_coeffs)
        rhs.append(value)

    idx = [(i, j) for i in range(n) for j in range(i, n)]

    def coeffs_of(linear_map):
        """Coefficient vector of a linear function of X over the upper-triangular entries."""
        out = []
        for i, j in idx:
            e = np.zeros((n, n))
            e[i, j] = e[j, i] = 1.0
            out.append(linear_map(e))
        return np.array(out)

    if null_space is not None:
        phi = np.asarray(null_space, float)
        for a in range(n):
            for r in range(phi.shape[1]):
                add(coeffs_of(lambda e, a=a, r=r: (e @ phi)[a, r]), 0.0)
    if rigid_modes is not None:
        phi = np.asarray(rigid_modes, float)
        target = np.asarray(rigid_mass, float)
        for a in range(phi.shape[1]):
            for b in range(a, phi.shape[1]):
                add(coeffs_of(lambda e, a=a, b=b: (phi.T @ e @ phi)[a, b]), target[a, b])
    if symmetry is not None:
        R = np.asarray(symmetry, float)
        for i, j in idx:
            add(coeffs_of(lambda e, i=i, j=j: (R.T @ e @ R - e)[i, j]), 0.0)
    return idx, np.array(rows), np.array(rhs)


def generic_family(n, *, null_space=None, rigid_modes=None, rigid_mass=None,
                   symmetry=None) -> GenericFamily:
    """The affine family of symmetric n x n matrices meeting the given constraints.

    Parameters
    ----------
    null_space : (n, r) array, optional
        Vectors the matrix must annihilate (stiffness: rigid-body modes).
    rigid_modes, rigid_mass : (n, r) and (r, r) arrays, optional
        Required projection :math:`Φ^T X Φ` (mass: total mass and inertia).
    symmetry : (n, n) array, optional
        Transform R with :math:`X = R^T X R`.
    """
    idx, A, b = _constraint_system(n, null_space, rigid_modes, rigid_mass, symmetry)
    x0, *_ = np.linalg.lstsq(A, b, rcond=None)
    if np.linalg.norm(A @ x0 - b) > 1e-9 * max(1.0, np.linalg.norm(b)):
        raise ValueError("the constraints are inconsistent: no matrix satisfies them")
    null = sla.null_space(A).T  # orthonormal basis of the homogeneous solutions
    if null.size:
        x0 = x0 - null.T @ (null @ x0)  # the particular solution orthogonal to them

    def to_matrix(v):
        m = np.zeros((n, n))
        for (i, j), val in zip(idx, v):
            m[i, j] = m[j, i] = val
        return m

    basis = np.array([to_matrix(v) for v in null]) if null.size else np.zeros((0, n, n))
    return GenericFamily(constant=to_matrix(x0), basis=basis)


def generic_family_symbolic(n, *, null_space=None, rigid_modes=None, rigid_mass=None,
                            symmetry=None) -> tuple[sympy.Matrix, tuple]:
    """Exact (sympy) version of :func:`generic_family`.

    Returns the symmetric matrix in terms of its free entries ``x_ij`` (upper-triangular
    names) and the tuple of those free symbols.  Inputs may be sympy Rationals.
    """
    syms = {(i, j): sympy.Symbol(f"x{i + 1}{j + 1}") for i in range(n) for j in range(i, n)}
    X = sympy.Matrix(n, n, lambda i, j: syms[(min(i, j), max(i, j))])
    eqs = []
    if null_space is not None:
        eqs += list(X * sympy.Matrix(null_space))
    if rigid_modes is not None:
        phi = sympy.Matrix(rigid_modes)
        eqs += list(phi.T * X * phi - sympy.Matrix(rigid_mass))
    if symmetry is not None:
        R = sympy.Matrix(symmetry)
        eqs += list(R.T * X * R - X)
    solution = sympy.linsolve(eqs, list(syms.values()))
    if solution == sympy.EmptySet:
        raise ValueError("the constraints are inconsistent: no matrix satisfies them")
    (values,) = tuple(solution)
    subs = dict(zip(syms.values(), values))
    Xs = X.subs(subs)
    free = tuple(sorted(Xs.free_symbols, key=lambda s: s.name))
    return Xs, free
