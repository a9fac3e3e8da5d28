r"""A fit's grid of starting points screened in bulk (issue 22, item 3).

A fit starts from the best point of a coarse grid (:func:`gfe_opt.fitting._grid_start`):
an effect at 19 places and several sizes, each point a full modal solve (5 ms on the
three-storey frame's 351 free DOFs, 1.3 ms on the 46-element demo beam).  The points differ
from the first one only on a few DOFs (those of one member of a frame; a place along a
beam), so a small basis serves them (Rayleigh–Ritz): the first point's modes,
:data:`EXTRA_MODES` more than the residual pairs, and the static response
:math:`(K_0 + s M_0)^{-1} E_S` to a unit load at each DOF of ``S``, where the point's K or M
differs from the first's (:math:`s` the model's eigenvalue scale: positive definite also
when the structure is free).  The exact modes of a point satisfy
:math:`(K_0 - λM_0)φ = -(ΔK - λΔM)φ`, a load on ``S``; the basis holds its static part
exactly and its dynamic part through the modes.  One basis serves the whole grid where the
points together differ on at most :data:`LOCAL_FRACTION` of the free DOFs (a frame
member), else one each set of DOFs (a place along a beam; points of one place share it);
where a basis would hold more than that fraction (a uniform change of E; a model of a few
elements, whose basis would be the model), the grid is solved point by point as before.
Measured on the portal's and the three-storey frame's grids (crack, point mass, point
spring, section loss, axial load, joint spring): χ² within 1e-9 (median) and 2e-5 (worst,
relative) of the exact solve's; on the 46-element demo beam's (crack, point mass and
spring, section loss, support spring; a crack's Christides–Barr disturbance, above 1e-12
of the largest entry, reaches 0.2 m each way: its basis there holds more than half the
model) within 1e-8 and 1e-7, and on its support translation's 1.2e-4 (a grid of 5 points,
below :data:`MIN_POINTS`: solved point by point).

The screened values only choose which points are solved exactly: every point whose
screened χ² lies within :data:`MARGIN` of the lowest, and the :data:`SHORTLIST` lowest
(of all points, and of those where the effect is present: the grid's guess of a place).
The grid's choice is then the exact solve's whenever the screen errs by less than half the
margin, which is checked on the points solved exactly: a larger error there, or a point
the reduced solve cannot take, and every point is solved exactly.  A beam solved through
condensed super-elements (above :data:`~gfe_opt.modal.CONDENSE_ABOVE` elements) is not
projected itself (its stiffness on smooth vectors loses eps N⁴ to cancellation): the same
beam at CONDENSE_ABOVE elements stands for it in the screen, and the points kept are
solved exactly on that stand-in too, where the fit then converges first
(:data:`~gfe_opt.fitting.STAND_IN`; until stop 80 they were solved on the beam's own mesh).
Measured against its own solve on every point of the grid (a
crack at 0.3 m in the data, 45 sensors, 5 modes; 400, 600 and 2 000 elements): crack
within 3.4e-5, section loss 2.3e-5, point spring 2.1e-7, point mass 6.9e-5 (2 000) to
1.5e-4 (600; the condensed solve's own error at that mesh), against the check's 2.5e-4;
the lowest point the same in each.  The 2 000-element diagnosis of ``scripts/bench.py``
and 600- and 1 000-element ones (a point mass, a zone) end identical to the last digit,
7.0 → 5.0 s, 4.7 → 3.9 s and 3.8 → 2.7 s.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import discretise
from .errors import GfeSolverError
from .measured import observation
from .modal import CONDENSE_ABOVE, Modes, condensed, rigid_as_zero, signed, solve_modes

#: the screen's basis (the first point's modes and the static responses) holds at most this
#: fraction of the free DOFs, else the points are solved one by one (a small model: its
#: solve costs what a basis would; a uniform change touches every DOF).  Measured on
#: ``update --add crack`` (one BLAS thread, best of 3, the same fit to the last digit
#: either way): 0.5 left a crack's grid on a beam unscreened at every mesh tried, 16 to
#: 180 elements (its disturbance covers a fixed share of the beam); 0.75 screens it from
#: 46 elements on, 196 → 171 ms there, 541 → 303 ms on 100 and 1.54 → 0.88 s on 180; 1.0
#: would screen 24 elements too, no faster (147 → 150 ms) than solving each point.  The
#: frames' grids were screened alike under 0.5 and 0.75 (their diagnoses the same to the
#: last digit)
LOCAL_FRACTION = 0.75
#: points whose screened χ² lies within this fraction of the lowest are solved exactly
#: (100 times the worst screening error measured: the module docstring)
MARGIN = 1e-3
#: and at least this many of the lowest
SHORTLIST = 3
#: a change of K or M below this fraction of its largest entry is rounding, not a change
RELATIVE_CHANGE = 1e-12
#: modes of the first point in the basis beyond those the residual pairs
EXTRA_MODES = 10
#: fewer points than this are solved one by one (a basis costs a solve with more modes, a
#: factorisation and a QR: not worth it for a handful of points; not tuned)
MIN_POINTS = 8
#: screens run and screens that fell back to solving every point (tests and benchmarks
#: read them)
TALLY = {"screened": 0, "fallback": 0}


def screened_chi2(residual, chi2, zs, null) -> list[float] | None:
    """χ² at each of the points ``zs`` of one grid (``null[j]``: the effect vanishes at
    point j; of such points the grid passes only one): exact (``chi2(z)``, the fit's own)
    at the points the screen keeps (module docstring), screened at the others; None when
    the grid is to be solved point by point."""
    if len(zs) < MIN_POINTS:
        return None
    from .fitting import FAILED_RESIDUAL

    values = screen(residual, zs)
    if values is None:
        return None
    TALLY["screened"] += 1
    present = ~np.asarray(null, dtype=bool)
    keep = _shortlist(values, np.ones(values.size, dtype=bool)) | _shortlist(values, present)
    keep |= values >= FAILED_RESIDUAL**2   # what the screen could not solve is solved exactly
    out = list(values)
    worst = 0.0
    for j in np.flatnonzero(keep):
        exact = chi2(zs[j])
        exact_ok = np.isfinite(exact) and exact < FAILED_RESIDUAL**2
        if values[j] < FAILED_RESIDUAL**2:   # the screen's error where both solved it
            worst = max(worst, abs(values[j] - exact) / max(exact, 1e-300)
                        if exact_ok else np.inf)
        out[j] = exact
    if worst > MARGIN / 4:
        TALLY["fallback"] += 1
        return None
    return out


def screen(residual, zs) -> np.ndarray | None:
    """The screened χ² of the points ``zs`` (:data:`FAILED_RESIDUAL`² where the reduced
    solve fails), or None where the grid's points do not differ locally or the basis
    cannot be built."""
    from .fitting import _TRIAL_ERRORS, FAILED_RESIDUAL, model_modes, point_of

    measured, noise = residual.measured, residual.noise
    C = residual.C
    try:
        models = [residual.model_at(z) for z in zs]
        coarse = condensed(models[0])
        if coarse:
            # the same beam at the finest mesh solved directly stands for it: the screen
            # only ranks the points, and the points solved exactly check it
            models = [m.with_elements(CONDENSE_ABOVE) for m in models]
        d0 = discretise(models[0])
        if coarse and not measured.frequency_only:
            C = observation(d0, measured)   # (a shear beam's point_of builds its own)
        free = d0.free
        n_model = model_modes(models[0], d0, measured)
        n_basis = n_model + EXTRA_MODES
        limit = LOCAL_FRACTION * free.size
        if n_basis >= limit:
            return None   # a small model: its basis would be the model (a 10-element beam)
        discs, matrices = [d0], [d0.global_matrices()]
    except _TRIAL_ERRORS:
        return None
    K0, M0 = matrices[0]
    index = np.full(K0.shape[0], -1)
    index[free] = np.arange(free.size)
    # the DOFs where a point's K or M differs from the first point's beyond rounding (a
    # crack's disturbance decays without end: 1e-12 of the largest entry is no change)
    tiny = [RELATIVE_CHANGE * abs(A).max() for A in (K0, M0)]
    count = len(models)
    discs += [None] * (count - 1)
    matrices += [None] * (count - 1)
    sets = [None] * count
    same_mass = [False] * count   # the point's M is the first point's, to 1e-12
    row_of = {}
    # the middle point first: along a beam it is the middle place, whose disturbance (a
    # crack's) reaches furthest; where no basis serves it the grid is known to be solved
    # point by point before the others are assembled (any order gives the same sets)
    for j in [0, count // 2] + [k for k in range(1, count) if k != count // 2]:
        if sets[j] is not None:
            continue
        if j:
            try:
                discs[j] = discretise(models[j])
                matrices[j] = discs[j].global_matrices()
            except _TRIAL_ERRORS:
                return None
        K, M = matrices[j]
        if K.shape != K0.shape or not np.array_equal(discs[j].free, free):
            return None   # the mesh itself differs from point to point (a released joint)
        changed = [_changed_rows(A, A0, t, row_of)
                   for A, A0, t in ((K, K0, tiny[0]), (M, M0, tiny[1]))]
        same_mass[j] = changed[1].size == 0
        rows = index[np.concatenate(changed)]
        sets[j] = np.unique(rows[rows >= 0])
        if n_basis + len(sets[j]) > limit:
            # no basis serves this point (nor the grid, which holds it): solved one by one
            return None
    # a basis (its modes and static responses) of at most LOCAL_FRACTION of the free DOFs:
    # one for the grid, else one for each set of DOFs a point differs on
    union = np.unique(np.concatenate(sets))
    shared = n_basis + union.size <= limit
    try:
        first = solve_modes(K0, M0, n_basis, d0.constrained, d0.eigenvalue_scale,
                            dense=getattr(d0, "dense_solve", None)).shapes[free]
        Kf = sp.csc_matrix(K0)[free][:, free]
        Mf = sp.csc_matrix(M0)[free][:, free]
        lu = spla.splu(sp.csc_matrix(Kf + d0.eigenvalue_scale * Mf))
    except (*_TRIAL_ERRORS, RuntimeError):
        return None
    bases = {}

    def basis(local):
        """The first point's modes and the static response at the DOFs ``local``, zero at
        the constrained DOFs (one for the grid where its points differ on few DOFs, else
        one for each set of DOFs a point differs on: a place along a beam)."""
        key = local.tobytes()
        if key not in bases:
            loads = np.zeros((free.size, local.size))
            loads[local, np.arange(local.size)] = 1.0
            Q = np.linalg.qr(np.hstack([first, lu.solve(loads)]))[0]
            # M0-orthonormal (Tᵀ M0 T = I): a point whose M is the first's is then a
            # standard eigenproblem in the basis
            R = np.linalg.cholesky(Q.T @ (Mf @ Q))
            T = np.zeros((K0.shape[0], Q.shape[1]))
            T[free] = sla.solve_triangular(R, Q.T, lower=True).T
            bases[key] = T
        return bases[key]

    screened = []
    for model, disc, (K, M), local, unit in zip(models, discs, matrices, sets, same_mass):
        try:
            T = basis(union if shared else local)
            n = model_modes(model, disc, measured)
            if n > T.shape[1]:
                raise ValueError("more modes than the basis holds")
            modes = _reduced_modes(K, None if unit else M, T, n, disc.eigenvalue_scale)
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                r = point_of(disc, K, M, modes, measured, noise, C).r
            screened.append(float(np.sum(r ** 2)))
        except (*_TRIAL_ERRORS, RuntimeError):
            screened.append(FAILED_RESIDUAL**2)
    return np.array(screened)


def _changed_rows(A, A0, tiny: float, row_of: dict) -> np.ndarray:
    """The rows of the entries where ``A`` differs from ``A0`` by more than ``tiny`` (each
    row once per such entry, in the order of ``A − A0``'s entries).  Where the two share
    their sparsity pattern (a point of a grid on the first point's mesh) the entries are
    compared in place: the same rows as the sparse difference, without building it (a sixth
    of a crack grid's screen on the 46-element beam, measured); ``row_of`` keeps each
    pattern's row of every entry."""
    if (sp.issparse(A) and sp.issparse(A0) and A.format == A0.format == "csr"
            and A.has_canonical_format
            and A0.has_canonical_format and A.indptr.size == A0.indptr.size
            and A.indices.size == A0.indices.size and np.array_equal(A.indptr, A0.indptr)
            and np.array_equal(A.indices, A0.indices)):
        key = (id(A0), A0.indptr.size, A0.indices.size)
        rows = row_of.get(key)
        if rows is None:
            rows = row_of[key] = np.repeat(np.arange(A0.shape[0]), np.diff(A0.indptr))
        return rows[np.abs(A.data - A0.data) > tiny]
    D = sp.coo_matrix(A - A0)
    return D.row[np.abs(D.data) > tiny]


def _shortlist(values, among) -> np.ndarray:
    """Of the points ``among``, those within :data:`MARGIN` of their lowest screened χ²
    and the :data:`SHORTLIST` lowest."""
    keep = np.zeros(values.size, dtype=bool)
    index = np.flatnonzero(among)
    if index.size == 0:
        return keep
    v = values[index]
    keep[index[v <= np.min(v) * (1.0 + MARGIN)]] = True
    keep[index[np.argsort(v, kind="stable")[:SHORTLIST]]] = True
    return keep


def _reduced_modes(K, M, T, n_modes, eigenvalue_scale) -> Modes:
    """The ``n_modes`` lowest modes of (K, M) in the basis ``T`` (zero at the constrained
    DOFs), mass normalised (by the reduced solve), each signed as
    :func:`~gfe_opt.modal.solve_modes` signs them.  ``M`` None: the mass the basis is
    orthonormal in (Tᵀ M T = I), a standard eigenproblem (a third faster than the
    generalised one at the 40-90 basis vectors of a beam's grid, measured)."""
    Kr = T.T @ (K @ T)
    if M is None:
        lam, q = sla.eigh(0.5 * (Kr + Kr.T), subset_by_index=[0, n_modes - 1])
    else:
        Mr = T.T @ (M @ T)
        lam, q = sla.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T),
                          subset_by_index=[0, n_modes - 1])
    lam = rigid_as_zero(lam, eigenvalue_scale)
    if np.any(lam < 0):
        raise GfeSolverError("negative eigenvalue in the screened solve")
    return Modes(frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), shapes=signed(T @ q))
