r"""Modal analysis: the lowest eigenpairs of :math:`K φ = ω^2 M φ` by sparse shift-invert.

Conditioning: beam DOFs mix translations and rotations and the stiffness spans many decades
on fine meshes, so the free-DOF matrices are first scaled symmetrically,
:math:`\tilde K = D K D`, :math:`\tilde M = D M D` with :math:`D = \mathrm{diag}(M)^{-1/2}`,
and the shift is placed *below* the spectrum at :math:`σ = -λ_{ref}` where
:math:`λ_{ref}` is the model's natural eigenvalue scale (EI/(ρA L⁴) for a beam, EA/(ρA L²)
for a bar).  A negative shift keeps :math:`\tilde K - σ \tilde M` positive definite, so
free–free structures (rigid-body modes at ω = 0) need no special case.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import Discretisation, discretise
from .errors import GfeSolverError
from .model import Model

#: Up to this many free DOFs a dense generalised eigensolver is faster than shift-invert.
DENSE_LIMIT = 400


@dataclass(frozen=True)
class Modes:
    """Natural frequencies [Hz] and mass-normalised shapes (n_dof, n_modes), all DOFs."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray

    @property
    def omega(self) -> np.ndarray:
        """Circular frequencies [rad/s]."""
        return 2.0 * np.pi * self.frequencies_hz

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)


def solve_modes(K, M, n_modes: int, constrained=(), eigenvalue_scale: float | None = None):
    """Lowest ``n_modes`` eigenpairs of the sparse pencil (K, M) with DOFs ``constrained`` fixed.

    Returns :class:`Modes` with shapes expanded to all DOFs (zeros at constrained ones),
    mass-normalised, sign fixed so that the largest-magnitude entry is positive.
    """
    n = K.shape[0]
    free = np.setdiff1d(np.arange(n), np.asarray(constrained, dtype=int))
    if n_modes < 1 or n_modes > len(free) - 1:
        raise ValueError(f"n_modes must lie in [1, {len(free) - 1}], got {n_modes}")
    dense = len(free) <= DENSE_LIMIT
    if dense:  # small models: numpy throughout (sparse slicing costs more than the solve)
        Kf = (K.toarray() if sp.issparse(K) else np.asarray(K))[np.ix_(free, free)]
        Mf = (M.toarray() if sp.issparse(M) else np.asarray(M))[np.ix_(free, free)]
        dm, dk = np.diag(Mf), np.diag(Kf)
    else:
        Kf = sp.csc_matrix(K)[free][:, free]
        Mf = sp.csc_matrix(M)[free][:, free]
        dm, dk = Mf.diagonal(), Kf.diagonal()
    if eigenvalue_scale is None:
        eigenvalue_scale = 1e-8 * float(np.max(dk / np.where(dm > 0, dm, np.inf)))
    d = np.where(dm > 0, 1.0 / np.sqrt(np.where(dm > 0, dm, 1.0)),
                 1.0 / np.sqrt(np.maximum(dk, 1e-300) / eigenvalue_scale))
    sigma = -eigenvalue_scale
    try:
        if dense:
            dd = np.outer(d, d)
            lam, vec = sla.eigh(Kf * dd, Mf * dd, subset_by_index=[0, n_modes - 1])
        else:
            D = sp.diags(d)
            Ks = (D @ Kf @ D).tocsc()
            Ms = (D @ Mf @ D).tocsc()
            lu = spla.splu((Ks - sigma * Ms).tocsc())
            op = spla.LinearOperator(Ks.shape, matvec=lu.solve, dtype=float)
            lam, vec = spla.eigsh(Ks, k=n_modes, M=Ms, sigma=sigma, which="LM", OPinv=op,
                                  tol=1e-12)
    except (RuntimeError, spla.ArpackError, np.linalg.LinAlgError) as exc:
        raise GfeSolverError(f"eigen solve failed: {exc}") from exc
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    # rigid-body eigenvalues come out as roundoff (either sign): clamp to zero what is tiny
    # next to the largest eigenvalue computed
    roundoff = max(1e-9 * eigenvalue_scale, 1e-8 * float(np.max(np.abs(lam))))
    lam = np.where(np.abs(lam) < roundoff, 0.0, lam)
    if np.any(lam < 0):
        raise GfeSolverError(f"eigen solve returned negative eigenvalues {lam[lam < 0]}: "
                             "stiffness is not positive semidefinite")
    shapes = np.zeros((n, n_modes))
    shapes[free] = d[:, None] * vec
    gen_mass = np.einsum("ij,ij->j", shapes, M @ shapes)
    shapes /= np.sqrt(gen_mass)
    peak = np.argmax(np.abs(shapes), axis=0)
    shapes *= np.sign(shapes[peak, np.arange(n_modes)])
    return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=shapes)


def discretisation_modes(disc: Discretisation, n_modes: int, params=None,
                         matrices=None) -> Modes:
    """Modes of a discretisation, optionally with replaced generic stiffness parameters.

    Eigenvalues are the Rayleigh quotients of the computed (mass-normalised) shapes with the
    strain energy summed element by element (:meth:`Discretisation.strain_energy`): the
    shift-invert eigenvalues lose about eps N⁴ relative accuracy on an N-element beam, the
    shapes and this quotient do not.  ``matrices`` may pass (K, M) already assembled.
    """
    K, M = disc.global_matrices(params) if matrices is None else matrices
    modes = solve_modes(K, M, n_modes, disc.constrained, disc.eigenvalue_scale)
    lam = np.maximum(disc.strain_energy(modes.shapes, params), 0.0)
    lam = np.where(modes.frequencies_hz == 0.0, 0.0, lam)
    return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=modes.shapes)


def model_modes(model: Model, n_modes: int) -> Modes:
    """The lowest ``n_modes`` modes of a model (all its effects included)."""
    return discretisation_modes(discretise(model), n_modes)
