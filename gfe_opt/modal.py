r"""Modal analysis: the lowest eigenpairs of :math:`K φ = ω^2 M φ`, each solve checked.

Conditioning: the stiffness of an N-element beam has a condition number growing as N⁴, past
what double precision holds near N = 10⁵ (and shift-invert eigenvalues lose eps N⁴ already
at 10⁴).  Two routes, both ending in Rayleigh quotients whose strain energy is summed
element by element from relative deformations (no cancellation):

* **direct** (bars, beams up to :data:`CONDENSE_ABOVE` elements, and shear beams up to
  :data:`SHEAR_DIRECT_ELEMENTS` whose pencil is conditioned no worse than the
  Euler–Bernoulli beam's at CONDENSE_ABOVE, :data:`DIRECT_CONDITIONING`: with rotary
  inertia the conditioning grows as N²): the free-DOF matrices scaled by
  :math:`D = \mathrm{diag}(M)^{-1/2}`, a dense generalised solver up to
  :data:`DENSE_LIMIT` DOFs, else shift-invert below the spectrum
  (:math:`σ = -λ_{ref}`, :math:`λ_{ref}` = EI/(ρA L⁴) or EA/(ρA L²): positive definite,
  free–free structures need no special case) from a fixed start vector.  Check: the
  residual :math:`\|(K - λM)φ\| / \|λ M φ\|` of every elastic mode below
  :data:`RESIDUAL_TOLERANCE` (the eigenvalue error is of its square).
* **condensed** (longer beams): the elements are grouped into about √N super-elements whose
  interior DOFs are condensed statically (Guyan: :math:`T = [I; -K_{II}^{-1}K_{IB}]`, one
  banded Cholesky factorisation of the block-diagonal :math:`K_{II}`); the reduced pencil
  :math:`(T^TKT, T^TMT)` is solved densely, the fine shapes :math:`Tφ_c` get one dynamic
  correction :math:`φ_I \mathrel{+}= K_{II}^{-1} λ_c (Mφ)_I`, and their Rayleigh quotients
  are the eigenvalues.  The reduced stiffness is summed from the element deformations of the
  reduced basis (no cancellation of fine stiffness entries).  Check: the dynamic correction
  changes no quotient by more than :data:`CONDENSATION_TOLERANCE` (the error left is of its
  square); otherwise the groups are halved and the solve repeated, and where no finer
  grouping is left (two elements a group) the direct route solves it, checked as above.
  Rounding still grows as N³, so meshes finer than :data:`MAX_BEAM_ELEMENTS` are refused.
  Measured
  (``tests/test_modal.py``, ``scripts/bench_eigen_accuracy.py``): closed forms within 1e-10
  up to 30 000 elements (6e-9 with the sparse LU used before).

Results are deterministic (dense solvers; a fixed start vector for shift-invert).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import Discretisation, discretise
from .errors import GfeInputError, GfeSolverError
from .inputs import MAX_ELEMENTS
from .model import Model
from .threads import one_blas_thread

#: Up to this many free DOFs a dense generalised eigensolver is used, where the caller does
#: not choose (a beam's or bar's discretisation does: :data:`~gfe_opt.assembly.DENSE_SOLVE_DOFS`,
#: measured; a frame's: :data:`~gfe_opt.frame.DENSE_SOLVE_DOFS`; a condensed beam's reduced
#: pencil takes this default)
DENSE_LIMIT = 1500
#: Beams with more elements are solved through condensed super-elements.
CONDENSE_ABOVE = 200
#: The direct route's conditioning limit, max K_ii/M_ii over the eigenvalue scale EI/(ρA L⁴):
#: the consistent-mass Euler–Bernoulli beam's at CONDENSE_ABOVE elements (the rotation's
#: 8EI/h over 8ρAh³/420: 420 N⁴).  A shear beam below it is solved directly
#: (:func:`condensed`).
DIRECT_CONDITIONING = 420.0 * CONDENSE_ABOVE**4
#: The most elements a shear beam is solved directly with (:func:`condensed`): the direct
#: route's residual grows rougher with N (Lanczos on more DOFs), the condensed one's does
#: not, and a fit's finish feels it along a flat direction.  Measured (stop 81, χ² of the
#: 5-mode ``ss-steel-beam`` data along κGA, the spread of its second differences over ±1e-3):
#: direct 0.8, 1.2, 2.0, 2.4, 4.5 % at 300, 400, 600, 800, 1 000 elements, condensed
#: 0.9–1.0 %, ``python scripts/study_deep_beam.py --parts smooth``; at 2 000 elements the
#: direct route's shear fit took 64 evaluations where the condensed one's took 26.  (The
#: continuum notch case of ``--parts loop`` at 300–1 000: 3.1–3.3 % either way.)
SHEAR_DIRECT_ELEMENTS = 400
#: Largest relative residual ‖(K − λM)φ‖ / ‖λMφ‖ a direct solve may leave.
RESIDUAL_TOLERANCE = 1e-3
#: Largest change of a Rayleigh quotient by the dynamic correction of the condensed shapes.
CONDENSATION_TOLERANCE = 1e-3
#: The finest beam mesh whose modal solve is verified: simply supported, clamped and
#: cantilever closed forms within 6e-9 at 30 000 elements (tests/test_modal.py) when it was
#: set, with a sparse LU of K_II (40 000: 2e-6 off; rounding grows as N³); 1e-11 with the
#: banded Cholesky since (40 000: 3.5e-10).  Kept: it is a model file's limit.
MAX_BEAM_ELEMENTS = MAX_ELEMENTS["beam"]


@dataclass(frozen=True)
class Modes:
    """Natural frequencies [Hz] and mass-normalised shapes (n_dof, n_modes), all DOFs."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    #: from the condensed route (:func:`_condensed_modes`): approximate shapes, whose
    #: residual the eigen-derivatives do not differentiate
    condensed: bool = False

    @property
    def omega(self) -> np.ndarray:
        """Circular frequencies [rad/s]."""
        return 2.0 * np.pi * self.frequencies_hz

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)


def solve_modes(K, M, n_modes: int, constrained=(), eigenvalue_scale: float | None = None,
                roundoff_fraction: float = 1e-8, dense: bool | None = None, free=None):
    """Lowest ``n_modes`` eigenpairs of the sparse pencil (K, M) with DOFs ``constrained`` fixed.

    Returns :class:`Modes` with shapes expanded to all DOFs (zeros at constrained ones),
    mass-normalised, sign fixed so that the largest-magnitude entry is positive (the first of
    equal ones, :func:`peak_rows`).  Eigenvalues
    smaller in magnitude than ``roundoff_fraction`` of the largest one computed are rigid-body
    roundoff (zero); other negative ones are an error.  ``dense``: LAPACK on the dense
    pencil or shift-invert Lanczos on the sparse one (None: dense up to
    :data:`DENSE_LIMIT` free DOFs).
    """
    n = K.shape[0]
    if free is None:   # (given: the DOFs not in ``constrained``, as a discretisation keeps)
        free = np.setdiff1d(np.arange(n), np.asarray(constrained, dtype=int))
    if n_modes < 1 or n_modes > len(free) - 1:
        raise ValueError(f"n_modes must lie in [1, {len(free) - 1}], got {n_modes}")
    dense = len(free) <= DENSE_LIMIT if dense is None else dense
    if dense:  # small models: numpy throughout (sparse slicing costs more than the solve)
        Kf = (K.toarray() if sp.issparse(K) else np.asarray(K))[np.ix_(free, free)]
        Mf = (M.toarray() if sp.issparse(M) else np.asarray(M))[np.ix_(free, free)]
        dm, dk = np.diag(Mf), np.diag(Kf)
    else:
        Kf, Mf = sp.csr_matrix(K), sp.csr_matrix(M)
        dm, dk = Mf.diagonal()[free], Kf.diagonal()[free]
    if eigenvalue_scale is None:
        eigenvalue_scale = 1e-8 * float(np.max(dk / np.where(dm > 0, dm, np.inf)))
    d = np.where(dm > 0, 1.0 / np.sqrt(np.where(dm > 0, dm, 1.0)),
                 1.0 / np.sqrt(np.maximum(dk, 1e-300) / eigenvalue_scale))
    sigma = -eigenvalue_scale
    try:
        if dense:
            dd = np.outer(d, d)
            A, B = Kf * dd, Mf * dd
            lam, vec = sla.eigh(A, B, subset_by_index=[0, n_modes - 1])
        else:
            Ks, Ms = _restricted(Kf, free, d), _restricted(Mf, free, d)
            lu = spla.splu((Ks - sigma * Ms).tocsc())
            start = np.random.default_rng(0).standard_normal(Ks.shape[0])  # deterministic
            size = Ks.shape[0]
            lam, vec = spla.eigsh(Ks, k=n_modes, M=_Direct(_product(Ms), size), sigma=sigma,
                                  which="LM", OPinv=_Direct(lu.solve, size), tol=1e-12,
                                  v0=start)
    except (RuntimeError, spla.ArpackError, np.linalg.LinAlgError) as exc:
        raise GfeSolverError(f"eigen solve failed: {exc}") from exc
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    lam = rigid_as_zero(lam, eigenvalue_scale, roundoff_fraction)
    if dense:
        vec = _inverse_iteration(A, B, lam, vec)
    if np.any(lam < 0):
        raise GfeSolverError(f"eigen solve returned negative eigenvalues {lam[lam < 0]}: "
                             "the stiffness is not positive semidefinite (a compression above "
                             "the buckling load, or a negative spring?)")
    shapes = np.zeros((n, n_modes))
    shapes[free] = d[:, None] * vec
    gen_mass = np.einsum("ij,ij->j", shapes, M @ shapes)
    shapes /= np.sqrt(gen_mass)
    return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=signed(shapes))


@lru_cache(maxsize=1)
def _GBSV():
    """LAPACK's dgbsv (banded LU and solve), looked up once."""
    return sla.get_lapack_funcs("gbsv", (np.zeros(1),))


def _inverse_iteration(A, B, lam, vec, reorder: bool = True) -> np.ndarray:
    """One step of inverse iteration for each elastic mode of the pencil (A, B) at its own
    eigenvalue: x = (A − λB)⁻¹ B v.  LAPACK's shapes carry rounding of about eps·λ_max/gap
    (5·10⁻¹¹ of a 20-element beam's first mode, whatever the step that moved the model:
    ``scripts/study_shape_rounding.py``), and χ² near an optimum was rough at 10⁻⁷ noise
    floors, above the finish's rule; after one step 10⁻¹³, χ² smooth to 2·10⁻¹⁰ floors.  A
    rigid mode (λ = 0) and a mode whose eigenvalue lies within 10⁻⁶ (relative) of another
    computed one (a pair the step would mix) keep LAPACK's shape.  A pencil not banded in
    its own order is solved banded in a reverse Cuthill–McKee order (``reorder``; else one
    dense LU a mode, as before stop 73: ``scripts/bench.py --parts shapes`` compares)."""
    n = A.shape[0]
    gaps = np.abs(lam[:, None] - lam[None, :])
    np.fill_diagonal(gaps, np.inf)
    take = np.flatnonzero((lam > 0.0) & (gaps.min(axis=1) > 1e-6 * lam))
    if take.size == 0:
        return vec
    Bv = B @ vec[:, take]
    shifts = lam[take]
    band, order = n, None
    if n > 24:   # (a beam's DOFs in order: LAPACK's banded LU, O(n band²) a mode)
        nonzero = (A != 0) | (B != 0)
        band = _bandwidth(nonzero)
        if 4 * band >= n and reorder:   # (a frame's: banded in a reverse Cuthill–McKee order)
            order, band = _banding_order(np.packbits(nonzero).tobytes(), n)
            if 4 * band < n:
                A, B, Bv = A[np.ix_(order, order)], B[np.ix_(order, order)], Bv[order]
            else:
                order = None
    try:
        if 4 * band < n:
            # LAPACK's band storage with room for the LU's fill: row 2·band + i − j, column j
            a_band, b_band = np.zeros((3 * band + 1, n)), np.zeros((3 * band + 1, n))
            for k in range(-band, band + 1):   # the diagonal A[i, i + k]
                a_band[2 * band - k, max(k, 0):n + min(k, 0)] = np.diagonal(A, k)
                b_band[2 * band - k, max(k, 0):n + min(k, 0)] = np.diagonal(B, k)
            gbsv = _GBSV()
            x = np.empty_like(Bv)
            for j, value in enumerate(shifts):
                _, _, x[:, j], info = gbsv(band, band, a_band - value * b_band, Bv[:, j])
                if info != 0:
                    return vec
        else:
            x = np.linalg.solve(A[None] - shifts[:, None, None] * B[None],
                                Bv.T[:, :, None])[:, :, 0].T
    except (np.linalg.LinAlgError, ValueError):
        return vec
    norm = np.einsum("ij,ij->j", x, B @ x)
    if not np.all(np.isfinite(norm) & (norm > 0.0)):
        return vec
    x = x / np.sqrt(norm)
    if order is not None:   # back to the pencil's own order
        back = np.argsort(order)
        x, Bv = x[back], Bv[back]
    out = vec.copy()
    out[:, take] = x * np.where(np.einsum("ij,ij->j", x, Bv) >= 0.0, 1.0, -1.0)
    return out


def _bandwidth(nonzero) -> int:
    """The largest |i − j| of a nonzero entry of a symmetric pattern."""
    n = nonzero.shape[0]
    last = n - 1 - np.argmax(nonzero[:, ::-1], axis=1)
    return int(np.max(last - np.arange(n)))


@lru_cache(maxsize=32)
def _banding_order(pattern: bytes, n: int):
    """(order, band): a reverse Cuthill–McKee ordering of the n × n symmetric pattern
    (``np.packbits`` of it) and the bandwidth in that order.  A frame's DOFs are numbered
    node by node, members joining nodes far apart in the numbering (the portal's pencil has
    a band of 173 of its 177 free DOFs in its own order, 7 in this one): the solves cost
    O(n band²) a mode instead of a dense LU, O(n³) (kept per pattern: every solve of a mesh
    has the same)."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    nonzero = np.unpackbits(np.frombuffer(pattern, dtype=np.uint8))[:n * n].reshape(n, n)
    order = np.asarray(reverse_cuthill_mckee(sp.csr_matrix(nonzero), symmetric_mode=True),
                       dtype=np.intp)
    band = _bandwidth(nonzero[np.ix_(order, order)].astype(bool))
    order.flags.writeable = False
    return order, band


class _Direct(spla.LinearOperator):
    """A square operator whose ``matvec`` is ``fn`` itself: ARPACK's reverse communication
    calls it ~124 times a solve, and LinearOperator's checks and reshapes around each call
    cost more than the mass product itself (measured on the three-storey frame's 351 free
    DOFs: about 8 µs a call, against 5 µs for the product and 49 µs for the LU solve; a
    solve 5.1 → 4.3 ms).  The same kernels as before are called on the same vectors: the
    same numbers."""

    def __init__(self, fn, n: int):
        super().__init__(float, (n, n))
        self._fn = fn

    def matvec(self, x):
        return self._fn(x)

    def _matvec(self, x):
        return self._fn(x)


def _product(A):
    """x ↦ A x for a square CSC matrix ``A``: the kernel ``A @ x`` reaches (``csc_matvec``),
    called directly; ``A @ x`` itself where scipy has no such kernel."""
    n = A.shape[0]

    def plain(x):
        return A @ x
    try:
        from scipy.sparse._sparsetools import csc_matvec
    except ImportError:   # (a private module of scipy: used only where it exists)
        return plain
    indptr, indices, data = A.indptr, A.indices, A.data

    def product(x):
        y = np.zeros(n)
        csc_matvec(n, n, indptr, indices, data, x, y)
        return y
    # used only where it is what ``A @ x`` computes, bit for bit (a private kernel whose
    # signature or meaning another scipy may change)
    probe = np.random.default_rng(1).standard_normal(n)
    try:
        same = np.array_equal(product(probe), plain(probe))
    except (TypeError, ValueError, RuntimeError):
        same = False
    return product if same else plain


def rigid_as_zero(lam, eigenvalue_scale: float, roundoff_fraction: float = 1e-8):
    """Rigid-body eigenvalues come out as roundoff (either sign): zero what is tiny next to
    the largest eigenvalue computed (and to 1e-9 of the model's eigenvalue scale)."""
    roundoff = max(1e-9 * eigenvalue_scale, roundoff_fraction * float(np.max(np.abs(lam))))
    return np.where(np.abs(lam) < roundoff, 0.0, lam)


def signed(shapes) -> np.ndarray:
    """``shapes`` (in place) with each mode's peak (:func:`peak_rows`) positive."""
    shapes *= np.sign(shapes[peak_rows(shapes), np.arange(shapes.shape[1])])
    return shapes


def _restricted(A, free, d):
    """D A[free][:, free] D (CSC; D = diag(d)) from ``A``'s CSR entries directly: the same
    numbers as sparse slicing and products, 4x faster (1.9 + 2.9 ms a solve on the
    three-storey frame, measured, for 0.6 ms)."""
    index = np.full(A.shape[0], -1)
    index[free] = np.arange(free.size)
    rows = index[np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))]
    cols = index[A.indices]
    keep = (rows >= 0) & (cols >= 0)
    r, c = rows[keep], cols[keep]
    return sp.csc_matrix((A.data[keep] * d[r] * d[c], (r, c)), shape=(free.size, free.size))


#: entries within this fraction of a mode's largest magnitude count as its peak
PEAK_TIE = 1e-6


def peak_rows(shapes) -> np.ndarray:
    """Per column, the first row whose magnitude is within :data:`PEAK_TIE` of the column's
    largest: the entry whose sign (or phase) a mode is given.  Not plain argmax: a mode of a
    symmetric structure has two peaks of one size, and which of them is larger by the last
    bit changed with the BLAS kernel, and with it the sign of the mode (and of the noise
    added to it by the realisation's noisy copies)."""
    a = np.abs(np.atleast_2d(shapes))
    return np.argmax(a >= (1.0 - PEAK_TIE) * np.max(a, axis=0), axis=0)


def condensed(model) -> bool:
    """Whether the modes of ``model`` (a Model or a Discretisation) come from the condensed
    route (:func:`_condensed_modes`): an Euler–Bernoulli beam above :data:`CONDENSE_ABOVE`
    elements, a shear beam there only above :data:`SHEAR_DIRECT_ELEMENTS` or if its pencil
    is conditioned worse than that (:func:`_shear_beam_condensed`)."""
    n = model.elements if hasattr(model, "elements") else model.n_elements
    if model.kind != "beam" or n <= CONDENSE_ABOVE:
        return False
    disc = model if isinstance(model, Discretisation) else discretise(model)
    return disc.shear_g is None or _shear_beam_condensed(disc, *disc.global_matrices())


def _shear_beam_condensed(disc, K, M) -> bool:
    """Whether a shear beam above :data:`CONDENSE_ABOVE` elements is condensed: above
    :data:`SHEAR_DIRECT_ELEMENTS` elements, or where its direct pencil is conditioned
    worse than the Euler–Bernoulli beam's at CONDENSE_ABOVE elements, the finest the
    direct route is given (its largest scaled diagonal max K_ii/M_ii over the eigenvalue
    scale EI/(ρA L⁴) above :data:`DIRECT_CONDITIONING`).  With shear deformation and rotary
    inertia that grows as N², not N⁴ (the rotation's mass ρI h/3 against its stiffness
    ~EI/h), and the groups of the condensation carry more internal dynamics (400 elements
    of L/h 12, 10 modes: no grouping passes its check), so there the direct route is both
    the cheaper and the surer."""
    if disc.n_elements > SHEAR_DIRECT_ELEMENTS:
        return True
    return pencil_conditioning(disc, K, M) > DIRECT_CONDITIONING


def pencil_conditioning(disc, K, M) -> float:
    """The direct pencil's conditioning as :data:`DIRECT_CONDITIONING` measures it: the
    largest scaled diagonal max K_ii/M_ii over the free DOFs, over the eigenvalue scale."""
    free = disc.free
    return float(np.max(K.diagonal()[free] / M.diagonal()[free])) / disc.eigenvalue_scale


def discretisation_modes(disc: Discretisation, n_modes: int, params=None,
                         matrices=None) -> Modes:
    """Modes of a discretisation, optionally with replaced generic stiffness parameters,
    checked (module docstring); raises :class:`GfeSolverError` if no route passes its check.

    Eigenvalues are the Rayleigh quotients of the computed (mass-normalised) shapes with the
    strain energy summed element by element (:meth:`Discretisation.strain_energy`).
    ``matrices`` may pass (K, M) already assembled (with ``params``), for either route.
    """
    if disc.kind == "beam" and disc.n_elements > CONDENSE_ABOVE:
        K, M = disc.global_matrices(params) if matrices is None else matrices
        if disc.shear_g is None or _shear_beam_condensed(disc, K, M):
            return _condensed_modes(disc, n_modes, params, (K, M))
        matrices = (K, M)
    return _direct_modes(disc, n_modes, params, matrices)


def _direct_modes(disc: Discretisation, n_modes: int, params=None, matrices=None) -> Modes:
    """The direct route (module docstring), checked."""
    K, M = disc.global_matrices(params) if matrices is None else matrices
    modes = solve_modes(K, M, n_modes, disc.constrained, disc.eigenvalue_scale,
                        dense=getattr(disc, "dense_solve", None), free=disc.free)
    lam = _rayleigh(disc, modes.shapes, params, M)
    worst = _residual(K, M, modes.shapes, lam, disc.free)
    if worst > RESIDUAL_TOLERANCE:
        raise GfeSolverError(f"modal solve failed its check: relative residual {worst:.2g} "
                             f"> {RESIDUAL_TOLERANCE:g} ({disc.n_elements} elements)")
    return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=modes.shapes)


def _rayleigh(disc, shapes, params, M) -> np.ndarray:
    """Rayleigh quotients, the strain energy from element deformations.  A rigid-body mode
    (below 1e-9 of the model's eigenvalue scale, or 1e-8 of the first elastic eigenvalue:
    the rounding a solve mixes into it) is zero; a negative energy is an error."""
    energy = disc.strain_energy(shapes, params)
    mass = np.einsum("ij,ij->j", shapes, M @ shapes)
    lam = energy / mass
    top = float(np.max(np.abs(lam), initial=0.0))
    elastic = lam[lam > 1e-6 * top]
    roundoff = max(1e-9 * disc.eigenvalue_scale,
                   1e-8 * float(np.min(elastic)) if elastic.size else 0.0)
    if np.any(lam < -roundoff):
        raise GfeSolverError(f"the stiffness is not positive semidefinite (a mode stores "
                             f"negative strain energy, λ = {lam.min():.3g}): a compression "
                             "above the buckling load, or a negative spring?")
    return np.where(lam < roundoff, 0.0, lam)


def _residual(K, M, shapes, lam, free) -> float:
    """Largest relative residual ‖(K − λM)φ‖ / ‖λMφ‖ over the elastic modes (free DOFs)."""
    elastic = lam > 0
    if not np.any(elastic):
        return 0.0
    phi = shapes[:, elastic]
    inertia = (M @ phi)[free] * lam[elastic]
    r = (K @ phi)[free] - inertia
    return float(np.max(np.linalg.norm(r, axis=0) / np.linalg.norm(inertia, axis=0)))


def condensation_groups(n_elements: int, n_modes: int) -> int:
    """√(πN) super-elements, and at least 8 per mode wanted (a group then spans a tenth of
    the shortest half-wave: its internal dynamics shift the eigenvalues by ~1e-4 before the
    correction).  At √(πN) the rounding of the static shapes inside a group of r elements
    (eps r⁴, weighted by the group-scale curvature (G/π)²) and of the reduced stiffness
    (eps r² G⁴/π⁴) balance; both enter the eigenvalues squared."""
    return min(max(8 * n_modes, int(round(np.sqrt(np.pi * n_elements)))), n_elements // 2)


def _condensed_modes(disc: Discretisation, n_modes: int, params, matrices=None) -> Modes:
    """The condensed route (module docstring), checked: the dynamic correction may change
    no Rayleigh quotient by more than :data:`CONDENSATION_TOLERANCE` (the error left is of
    its square); otherwise the groups are halved and the solve repeated, and with no finer
    grouping left the direct route solves it (:func:`_direct_modes`, its own check)."""
    n = disc.n_elements
    if n > MAX_BEAM_ELEMENTS:
        raise GfeInputError(None, "elements", f"{n} beam elements is above "
                            f"{MAX_BEAM_ELEMENTS}, the finest mesh whose modal solve gfe-opt "
                            "verifies (the stiffness condition number grows as N⁴); a few "
                            "thousand elements resolve the first modes to 1e-9")
    K, M = disc.global_matrices(params) if matrices is None else matrices
    groups = condensation_groups(n, n_modes)
    while True:
        guyan, corrected = _reduce_and_solve(disc, K, M, n_modes, groups, params)
        lam = _rayleigh(disc, corrected, params, M)
        lam_guyan = _rayleigh(disc, guyan, params, M)
        elastic = lam > 0
        change = float(np.max(np.abs(lam_guyan[elastic] - lam[elastic]) / lam[elastic],
                              initial=0.0))
        if change <= CONDENSATION_TOLERANCE:
            return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=corrected,
                         condensed=True)
        if 2 * groups > n // 2:
            # no finer grouping left (a shear beam's groups carry more internal dynamics:
            # 400 elements, 10 modes, κGA 1.4e7 N changed an eigenvalue by 1.5e-3 on 160
            # groups): the direct route, with its own check
            try:
                return _direct_modes(disc, n_modes, params, (K, M))
            except GfeSolverError as exc:
                raise GfeSolverError(
                    f"modal solve failed its check: the dynamic correction changes an "
                    f"eigenvalue by {change:.2g} on {groups} groups ({n} elements), and the "
                    f"direct solve: {exc}") from None
        groups *= 2


def _reduce_and_solve(disc, K, M, n_modes, groups, params):
    """Guyan reduction onto ``groups`` super-elements and a dense solve of the reduced
    pencil.  The reduced stiffness is summed element by element from the deformations of
    the reduced basis (Σ Dᵀ P D: no cancellation of the fine stiffness, whose entries are
    (N/groups)³ times the reduced ones).  Returns the fine shapes before and after one
    dynamic correction, both mass-normalised."""
    n, per = disc.n_elements, disc.dofs_per_node
    L = disc.element_length
    plan = _plan(n, per, groups)
    interior, boundary = plan.interior, plan.boundary
    diagonals = {k: K.diagonal(k) for k in range(-plan.width, plan.width + 1)}
    if sum(np.count_nonzero(d) for d in diagonals.values()) != K.count_nonzero():
        # (an element couples its two nodes alone: nothing lies outside the band)
        raise GfeSolverError("the condensed solve found stiffness outside the beam's band")
    rhs = _couplings(plan, diagonals)
    solve = _interior_solver(K, plan, diagonals)
    # basis values of every fine DOF in its group's 2·per local columns
    basis = np.zeros((disc.n_dof, 2 * per))
    basis[interior] = -solve(rhs)
    U = basis[plan.dofs]  # (n, 2 per, 2 per), boundary rows fixed below
    first, last, eye = plan.first, plan.last, np.eye(per)
    U[first, :per, :per], U[first, :per, per:] = eye, 0.0
    U[last, per:, per:], U[last, per:, :per] = eye, 0.0
    stiffness = _reduced_element_stiffness(disc, U, params, L)
    blocks_k = np.zeros((len(plan.coarse) - 1, 2 * per, 2 * per))
    blocks_m = np.zeros_like(blocks_k)
    np.add.at(blocks_k, plan.element_group, stiffness)
    Ut = np.swapaxes(U, 1, 2)
    np.add.at(blocks_m, plan.element_group, Ut @ disc.mass @ U)
    size = boundary.size
    Kc, Mc = np.zeros((size, size)), np.zeros((size, size))
    for g in range(len(plan.coarse) - 1):
        sl = slice(g * per, (g + 2) * per)
        Kc[sl, sl] += blocks_k[g]
        Mc[sl, sl] += blocks_m[g]
    for dof, value in disc.nodal_stiffness:
        at = plan.position[dof]
        if at < 0:
            raise GfeSolverError("a spring at an interior node cannot be condensed")
        Kc[at, at] += value
    fixed = np.flatnonzero(np.isin(boundary, disc.constrained))
    # the reduced pencil's rigid-body eigenvalues carry its rounding (eps times its condition
    # number, ~1e-7 of the modes computed); the fine Rayleigh quotients decide afterwards
    reduced = solve_modes(Kc, Mc, n_modes, fixed, disc.eigenvalue_scale,
                          roundoff_fraction=1e-5)
    lam_c = (2.0 * np.pi * reduced.frequencies_hz) ** 2
    T = sp.csr_matrix((np.concatenate([np.ones(size), basis[interior].ravel()]),
                       (plan.t_rows, plan.t_cols)), shape=(disc.n_dof, size))
    guyan = T @ reduced.shapes
    corrected = guyan.copy()
    corrected[interior] += solve((M @ guyan)[interior] * lam_c)  # dynamic correction
    out = []
    for shapes in (guyan, corrected):
        shapes[disc.constrained] = 0.0
        shapes = shapes / np.sqrt(np.einsum("ij,ij->j", shapes, M @ shapes))
        out.append(shapes * np.sign(shapes[peak_rows(shapes), np.arange(shapes.shape[1])]))
    return out


@dataclass(frozen=True)
class _Plan:
    """What the condensed route's index arithmetic depends on (the mesh, DOFs a node and
    the groups), worked out once (:func:`_plan`)."""

    coarse: np.ndarray       # the group ends (node indices)
    boundary: np.ndarray     # their DOFs, in order
    position: np.ndarray     # a DOF's position in ``boundary``, −1 for an interior one
    interior: np.ndarray     # the other DOFs, ascending
    local: np.ndarray        # (interior, 2 per): positions in ``boundary`` of its group's
    element_group: np.ndarray
    dofs: np.ndarray         # (n, 2 per) each element's DOFs
    first: np.ndarray        # element starts its group
    last: np.ndarray         # element ends its group
    width: int               # half-bandwidth of K (node-by-node DOFs: 2 per − 1)
    band: dict               # k ≥ 0: (columns of K_II's k-th superdiagonal, rows in K)
    coupling: dict           # k: (flat positions in (interior, 2 per), rows in K's k-th diagonal)
    t_rows: np.ndarray       # the Guyan basis T's entries: rows, then columns
    t_cols: np.ndarray


@lru_cache(maxsize=16)
def _plan(n: int, per: int, groups: int) -> _Plan:
    """The condensed route's indices for ``n`` elements of ``per`` DOFs a node in
    ``groups`` groups.  An element couples the DOFs of its two nodes only, so K's entries
    lie within ``2 per − 1`` of its diagonal, and an interior DOF's couplings to its group's
    boundary DOFs (and K_II's band) are read from K's diagonals."""
    coarse = np.unique(np.round(np.linspace(0, n, groups + 1)).astype(int))
    n_dof = per * (n + 1)
    boundary = (coarse[:, None] * per + np.arange(per)).ravel()
    is_b = np.zeros(n_dof, dtype=bool)
    is_b[boundary] = True
    interior = np.flatnonzero(~is_b)
    # each interior DOF couples to the boundary DOFs of its own group only: `per` at each end
    group_of_node = np.searchsorted(coarse, np.arange(n + 1), side="right") - 1
    group = group_of_node[interior // per]
    local = group[:, None] * per + np.arange(2 * per)[None, :]  # positions in `boundary`
    element_group = group_of_node[np.arange(n)]
    width = 2 * per - 1
    band = {}
    for k in range(width + 1):
        i = np.arange(interior.size - k)
        same = np.flatnonzero(interior[i + k] - interior[i] == k)  # else a boundary DOF between
        band[k] = (same + k, interior[same])
    offsets = boundary[local] - interior[:, None]
    coupling = {}
    for k in range(-width, width + 1):
        at = np.flatnonzero(offsets == k)
        if at.size:   # K[i, i + k] is the k-th diagonal's entry i (k ≥ 0), i + k (k < 0)
            coupling[k] = (at, interior[at // local.shape[1]] + min(k, 0))
    size = boundary.size
    position = np.full(n_dof, -1)
    position[boundary] = np.arange(size)
    plan = _Plan(coarse=coarse, boundary=boundary, position=position, interior=interior,
                 local=local, element_group=element_group,
                 dofs=np.arange(n)[:, None] * per + np.arange(2 * per)[None, :],
                 first=coarse[element_group] == np.arange(n),
                 last=coarse[element_group + 1] == np.arange(n) + 1,
                 width=width, band=band, coupling=coupling,
                 t_rows=np.concatenate([boundary, np.repeat(interior, 2 * per)]),
                 t_cols=np.concatenate([np.arange(size), local.ravel()]))
    for value in vars(plan).values():   # shared by every solve of the mesh: read-only
        for array in (value.values() if isinstance(value, dict) else [value]):
            for a in (array if isinstance(array, tuple) else (array,)):
                if isinstance(a, np.ndarray):
                    a.flags.writeable = False
    return plan


def _couplings(plan: _Plan, diagonals: dict) -> np.ndarray:
    """(interior DOFs, 2 per): K[interior DOF, each boundary DOF of its group], read from
    K's ``diagonals`` (offset → :meth:`~scipy.sparse.csr_matrix.diagonal`)."""
    out = np.zeros(plan.local.shape)
    for k, (at, source) in plan.coupling.items():
        out.flat[at] = diagonals[k][source]
    return out


def _interior_solver(K, plan: _Plan, diagonals: dict):
    """x ↦ K_II⁻¹ x for the interior DOFs of the condensed route: a banded Cholesky factor
    (LAPACK ``pbtrf``: the interior block is positive definite, its groups clamped at their
    ends), else (a compression past a group's buckling load) the sparse LU of ``K_II``.
    The sparse LU and its solves took a third of a condensed solve (2 000 elements)."""
    width, interior = plan.width, plan.interior
    ab = np.zeros((width + 1, interior.size))   # upper form: ab[width + i − j, j] = K_II[i, j]
    for k, (columns, rows) in plan.band.items():
        ab[width - k, columns] = diagonals[k][rows]
    try:
        factor = sla.cholesky_banded(ab, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        lu = spla.splu(sp.csc_matrix(K)[interior][:, interior].tocsc())
        return lu.solve
    return lambda x: sla.cho_solve_banded((factor, False), x, check_finite=False)


def _reduced_element_stiffness(disc, U, params, L):
    """Σ over each element of Dᵀ P D / L³ (+ its extra stiffness Uᵀ K_x U): the element's
    share of the reduced stiffness, D the deformations of the reduced basis ``U``
    (:data:`~gfe_opt.elements.BEAM_DEFORMATION_H` written out: w₁ − w₂ + Lθ₂ and
    L(θ₁ − θ₂); elementwise, where numpy's stacked 2 × 4 products cost ten times more)."""
    params = disc.stiffness_params if params is None else params
    d0 = U[:, 0] - U[:, 2] + L * U[:, 3]          # (n, 2 per)
    d1 = L * U[:, 1] - L * U[:, 3]
    ww, wt, tt = (params[k][:, None, None] for k in ("k_ww", "k_wt", "k_tt"))
    cross = d0[:, :, None] * d1[:, None, :]
    out = (ww * (d0[:, :, None] * d0[:, None, :]) + wt * (cross + np.swapaxes(cross, 1, 2))
           + tt * (d1[:, :, None] * d1[:, None, :])) / L**3
    if np.any(disc.extra_stiffness):
        out = out + np.swapaxes(U, 1, 2) @ disc.extra_stiffness @ U
    return out


def rigid_body_count(disc) -> int:
    """How many rigid-body modes (ω = 0) the supports and springs leave
    (:meth:`Discretisation.rigid_body_count`, a frame's
    :meth:`~gfe_opt.frame.FrameDiscretisation.rigid_body_count`)."""
    return disc.rigid_body_count()


@one_blas_thread
def model_modes(model: Model, n_modes: int) -> Modes:
    """The lowest ``n_modes`` modes of a model (all its effects included)."""
    return discretisation_modes(discretise(model), n_modes)
