r"""Derivatives of eigenpairs with respect to parameters (the fits' analytic Jacobian).

For a simple eigenpair of the pencil (K, M), mass-normalised (:math:`φ^T M φ = 1`), and a
parameter p with :math:`K' = ∂K/∂p`, :math:`M' = ∂M/∂p`:

.. math:: λ' = φ^T (K' - λ M') φ

and the shape derivative solves the bordered system (Nelson's condition written as one
nonsingular equation; Lee & Jung 1997)

.. math::
    \begin{bmatrix} K - λM & Mφ \\ (Mφ)^T & 0 \end{bmatrix}
    \begin{bmatrix} φ' \\ μ \end{bmatrix} =
    \begin{bmatrix} -(K' - λ M')φ + λ' Mφ \\ -\tfrac12 φ^T M' φ \end{bmatrix}

(μ = 0 at the solution), exact for any number of parameters with one factorisation per
mode: dense (LAPACK) up to :data:`DENSE_DOFS` free DOFs; above, Nelson's own form (the
row and column of the shape's largest entry removed, a sparse LU that keeps the band) with
the same result.  The system is nonsingular exactly when λ is simple: a mode within
:data:`REPEATED_GAP` (relative) of another has no derivative of its shape (any combination of
the pair is an eigenvector) and :func:`eigen_derivatives` raises :class:`RepeatedEigenvalue`.

The system is solved in the coordinates scaled by :math:`1/\sqrt{K_{ii}}` with the border
scaled to unit length: K of a fine beam mesh spans ~N⁴ between its translations and
rotations, and M φ is ~λ⁻¹ smaller than K φ'.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: eigenvalues closer than this (relative) are repeated: their shapes have no derivative
REPEATED_GAP = 1e-7
#: up to this many free DOFs the bordered systems are solved dense (LAPACK): a sparse
#: factorisation's set-up costs more than a dense one of a small model.  The default only:
#: the fits pass their discretisation's own choice (a beam's or bar's
#: :data:`~gfe_opt.assembly.DENSE_DERIVATIVE_DOFS`, measured; a frame's: sparse)
DENSE_DOFS = 400


class RepeatedEigenvalue(ValueError):
    """A mode's eigenvalue is (numerically) repeated: its shape is not differentiable."""


def eigen_derivatives(K, M, free, lam, phi, dK, dM, all_lam=None, dense=None,
                      shapes: bool = True):
    """Derivatives of the eigenpairs (λ_j, φ_j) (columns of ``phi``, all DOFs, zero at the
    constrained ones, mass-normalised) with respect to p parameters.

    ``dK``, ``dM``: lists of p sparse (or dense) matrices over all DOFs; ``free``: the free
    DOFs; ``all_lam``: every computed eigenvalue (to refuse repeated ones).  Returns
    ``(dlam, dphi)`` of shapes (m, p) and (n_dof, m, p).  ``dense``: LAPACK on the
    bordered system or Nelson's sparse form (None: dense up to :data:`DENSE_DOFS`).
    Without ``shapes`` (frequencies alone are fitted) ``dphi`` stays zero: no system is
    solved, and ``dlam`` is the same to the last bit."""
    free = np.asarray(free, dtype=int)
    dense = free.size <= DENSE_DOFS if dense is None else dense
    K, M = _as(K, dense), _as(M, dense)
    lam = np.asarray(lam, dtype=float)
    phi = np.asarray(phi, dtype=float)
    m, p = lam.size, len(dK)
    n_dof = K.shape[0]
    dlam = np.zeros((m, p))
    dphi = np.zeros((n_dof, m, p))
    if m == 0 or p == 0:
        return dlam, dphi
    if all_lam is not None:
        others = np.asarray(all_lam, dtype=float)
        for j in range(m):
            gap = np.abs(others - lam[j])
            close = gap < REPEATED_GAP * max(abs(lam[j]), 1e-300)
            if np.count_nonzero(close) > 1:
                raise RepeatedEigenvalue(f"eigenvalue {lam[j]:.6g} is repeated")
    Kf, Mf = _sub(K, free), _sub(M, free)
    if dense:
        dKf = [_sub(_as(d, dense), free) for d in dK]
        dMf = [_sub(_as(d, dense), free) for d in dM]
    else:   # products over all DOFs with the shape zero off the free ones, then the free
        # rows: the same sums term by term as the free block's (slicing cost more than them)
        dKf = [_FreeRows(sp.csr_matrix(d), free) for d in dK]
        dMf = [_FreeRows(sp.csr_matrix(d), free) for d in dM]
    kd = np.abs(Kf.diagonal())
    d = 1.0 / np.sqrt(np.where(kd > 0, kd, 1.0))
    if dense and shapes:
        Ks, Ms = Kf * np.outer(d, d), Mf * np.outer(d, d)
    elif shapes:
        D = sp.diags(d)
        pencil = _Pencil((D @ Kf @ D).tocsc(), (D @ Mf @ D).tocsc())
    for j in range(m):
        x = phi[free, j]
        Mx = Mf @ x
        # derivatives of λ: φᵀ(K' − λM')φ
        if dense:
            xk = x
        else:
            xk = np.zeros(n_dof)
            xk[free] = x
        Mxk = [dMf[k] @ xk for k in range(p)]
        g = np.column_stack([dKf[k] @ xk - lam[j] * Mxk[k] for k in range(p)])
        dlam[j] = x @ g
        if not shapes:
            continue
        half = np.array([-0.5 * float(x @ Mxk[k]) for k in range(p)])
        rhs_top = -g + np.outer(Mx, dlam[j])
        border = d * Mx
        beta = 1.0 / np.linalg.norm(border)
        try:
            if dense:
                rhs = np.vstack([d[:, None] * rhs_top, beta * half[None, :]])
                A = np.zeros((free.size + 1, free.size + 1))
                A[:-1, :-1] = Ks - lam[j] * Ms
                A[:-1, -1] = A[-1, :-1] = beta * border
                sol = np.linalg.solve(A, rhs)
                dphi[free, j, :] = d[:, None] * sol[:-1]
            else:
                dphi[free, j, :] = _nelson(pencil, lam[j], x / d, d, rhs_top, Mx, half)
        except (RuntimeError, np.linalg.LinAlgError) as exc:  # singular: a repeated one
            raise RepeatedEigenvalue(str(exc)) from exc
    return dlam, dphi


def _nelson(pencil, lam, xs, d, rhs_top, Mx, half):
    """Nelson's method on a sparse model: the scaled (K − λM) with the row and column of
    the shape's largest (scaled) entry removed is nonsingular and keeps its sparsity (a
    bordered matrix's dense row and column made the factorisation 50 times slower on 4 000
    DOFs); v solves it with v_k = 0, and φ′ = v + cφ with c from the normalisation."""
    k = int(np.argmax(np.abs(xs)))
    keep = np.flatnonzero(np.arange(xs.size) != k)
    v = np.zeros((xs.size, rhs_top.shape[1]))
    v[keep] = spla.splu(pencil.without(lam, k)).solve(d[keep, None] * rhs_top[keep])
    v = d[:, None] * v                                  # back to physical coordinates
    c = half - Mx @ v
    return v + np.outer(d * xs, c)


class _FreeRows:
    """``A @ v`` restricted to the rows ``free``, for ``v`` over all DOFs."""

    def __init__(self, A, free):
        self.A, self.free = A, free

    def __matmul__(self, v):
        return (self.A @ v)[self.free]


class _Pencil:
    """The scaled pencil (Ks, Ms) (CSC) on the union of their entries, so that Ks − λMs
    without one row and column is built from arrays once a mode: the numbers and the
    entries sparse arithmetic and slicing give (``Ks - lam * Ms``, whose exact zeros it
    drops, then ``[keep][:, keep]``), at a fraction of their cost (three sparse operations
    a mode were a third of a frame's eigen-derivatives)."""

    def __init__(self, Ks, Ms):
        n = Ks.shape[0]
        self.n = n
        keys = [np.repeat(np.arange(n), np.diff(A.indptr)) * n + A.indices for A in (Ks, Ms)]
        self.keys = np.union1d(*keys)                     # column-major: col * n + row
        self.k_data, self.m_data = np.zeros(self.keys.size), np.zeros(self.keys.size)
        self.k_data[np.searchsorted(self.keys, keys[0])] = Ks.data
        self.m_data[np.searchsorted(self.keys, keys[1])] = Ms.data
        self.cols, self.rows = self.keys // n, self.keys % n

    def without(self, lam: float, k: int) -> sp.csc_matrix:
        """Ks − λMs with row and column k removed, (n − 1) × (n − 1), CSC."""
        data = self.k_data - lam * self.m_data
        keep = (data != 0) & (self.rows != k) & (self.cols != k)
        rows, cols = self.rows[keep], self.cols[keep]
        rows = rows - (rows > k)
        cols = cols - (cols > k)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=self.n - 1))])
        return sp.csc_matrix((data[keep], rows, indptr), shape=(self.n - 1, self.n - 1))


def _as(A, dense: bool):
    if dense:
        return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)
    return sp.csc_matrix(A)


def _sub(A, free):
    return A[np.ix_(free, free)] if isinstance(A, np.ndarray) else A[free][:, free]
