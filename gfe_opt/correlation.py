r"""Test–model correlation: MAC, pairing, frequency errors, COMAC and the modal residual force.

Residual force and expansion (documented contract of :func:`expand_modes`)
---------------------------------------------------------------------------
For a measured mode with circular frequency :math:`ω` and shape :math:`y` at the sensors
(:math:`C` maps model DOFs to sensors), the model's dynamic stiffness is
:math:`D = K - ω^2 M` (free DOFs).  We look for forces :math:`λ` *acting only at the
sensors* that make the model vibrate at :math:`ω` in the measured shape:

.. math:: D φ = C^T λ, \qquad C φ \approx y .

With :math:`G = C D^{-1} C^T` (the model's receptance between sensors at :math:`ω`),
:math:`λ` is the Tikhonov solution :math:`\min_λ \|Gλ - y\|^2 + α^2\|λ\|^2`, with α chosen
by the discrepancy principle :math:`\|Gλ - y\| = δ \max|y| \sqrt{n_s}` for the stated
shape noise δ (standard deviation relative to the mode's largest amplitude).
For noise-free data at the model nodes this is Kidder's dynamic expansion: unmeasured DOFs
(rotations, translations between sensors) satisfy their rows of :math:`Dφ = 0` exactly.
The expanded shape is :math:`φ = D^{-1}C^Tλ` and the residual force :math:`(K-ω^2M)φ`
equals :math:`C^Tλ`: it vanishes where the model is right and concentrates where it fails.
Per sensor i and mode j we report :math:`r_{ij} = |λ_{ij}| / \|ω_j^2 M φ_j\|`
(residual relative to the mode's inertia force) and combine modes as
:math:`r_i = (\sum_j r_{ij}^2)^{1/2}`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import linear_sum_assignment

from .assembly import Discretisation, discretise
from .errors import GfeInputError, GfeSolverError
from .measured import MeasuredModes, observation, on_model
from .modal import Modes, discretisation_modes, rigid_body_count
from .model import Model
from .names import DEFAULT_COMPARE_SHAPE_NOISE as DEFAULT_SHAPE_NOISE
from .names import DEFAULT_MAC_THRESHOLD
from .threads import one_blas_thread


def mac(a, b) -> np.ndarray:
    r"""Modal assurance criterion :math:`|a_i^H b_j|^2 / (|a_i|^2 |b_j|^2)`, shape (n_a, n_b).

    ``a`` (n, n_a) and ``b`` (n, n_b) hold shapes as columns on the same DOFs.
    """
    a = np.asarray(a)
    b = np.asarray(b)
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.einsum("ij,ij->j", a.conj(), a).real, np.einsum("ij,ij->j", b.conj(), b).real)
    return num / den


#: weight of |ln(f_model / f_test)| against MAC in the pairing: it only breaks near-ties
#: (a Timoshenko beam's thickness-shear mode has the deflection shape of a bending mode)
FREQUENCY_TIE_BREAK = 0.05


def pair_modes(mac_matrix, threshold: float = DEFAULT_MAC_THRESHOLD, test_hz=None,
               model_hz=None) -> list[tuple[int, int]]:
    """Pair test modes (rows) with model modes (columns) by MAC, not by index.

    A one-to-one assignment maximising the total MAC (Hungarian algorithm), near-ties broken
    by the frequency ratio when the frequencies are given; pairs whose MAC is below
    ``threshold`` are dropped, so a test mode the model lacks stays unpaired.
    """
    cost = -np.asarray(mac_matrix, dtype=float)
    if test_hz is not None and model_hz is not None:
        ratio = np.abs(np.log(np.maximum(np.asarray(model_hz), 1e-300)[None, :]
                              / np.asarray(test_hz)[:, None]))
        cost = cost + FREQUENCY_TIE_BREAK * np.minimum(ratio, 10.0)
    rows, cols = linear_sum_assignment(cost)
    keep = mac_matrix[rows, cols] >= threshold
    return sorted(zip(rows[keep].tolist(), cols[keep].tolist()))


def pair_by_frequency(test_hz, model_hz) -> list[tuple[int, int]]:
    """Pair test modes with model modes by frequency alone (a test without usable shapes):
    one to one, minimising the total |ln(f_model / f_test)| (Hungarian), so each test mode
    takes the nearest model mode that no closer test mode claims.  Rigid-body model modes
    (f = 0) are never partners."""
    test_hz = np.asarray(test_hz, float)
    model_hz = np.asarray(model_hz, float)
    cost = np.abs(np.log(np.maximum(model_hz, 1e-300)[None, :] / test_hz[:, None]))
    cost[:, model_hz <= 0] = 1e6
    rows, cols = linear_sum_assignment(cost)
    keep = model_hz[cols] > 0
    return sorted(zip(rows[keep].tolist(), cols[keep].tolist()))


def comac(test, model) -> np.ndarray:
    r"""Coordinate MAC per sensor for paired shapes ``test`` and ``model`` (n_sensors, n_pairs).

    Each pair is first brought to unit norm and a common sign; then
    :math:`\mathrm{COMAC}_i = (\sum_j t_{ij} m_{ij})^2 / (\sum_j t_{ij}^2 \sum_j m_{ij}^2)`
    (the signed form, which also sees a sensor whose sign disagrees).
    """
    t = test / np.linalg.norm(test, axis=0)
    m = model / np.linalg.norm(model, axis=0)
    m = m * np.sign(np.sum(t * m, axis=0))
    num = np.sum(t * m, axis=1) ** 2
    den = np.sum(t**2, axis=1) * np.sum(m**2, axis=1)
    return np.divide(num, den, out=np.ones_like(num), where=den > 0)


@dataclass(frozen=True)
class Expansion:
    """Expanded shapes (n_dof, n_modes) and residual forces at sensors (n_sensors, n_modes)."""

    shapes: np.ndarray
    forces: np.ndarray
    relative_residual: np.ndarray


def expand_modes(disc: Discretisation, C, omega, shapes, noise: float = DEFAULT_SHAPE_NOISE,
                 K=None, M=None) -> Expansion:
    """Regularised dynamic expansion of measured shapes (see module docstring)."""
    if K is None or M is None:
        K, M = disc.global_matrices()
    free = disc.free
    Kf = sp.csc_matrix(K)[free][:, free]
    Mf = sp.csc_matrix(M)[free][:, free]
    Cf = sp.csr_matrix(C)[:, free]
    n_dof = K.shape[0]
    out_shapes = np.zeros((n_dof, len(omega)))
    forces = np.zeros((C.shape[0], len(omega)))
    rel = np.zeros_like(forces)
    few = Cf.shape[0] <= DENSE_SENSOR_LIMIT
    # a small model with few sensors: dense LAPACK (a sparse factorisation's set-up costs
    # more than a dense one of a few hundred DOFs)
    dense = noise > 0 and few and free.size <= DENSE_EXPANSION_DOFS
    if dense:
        Kd, Md, CdT = Kf.toarray(), Mf.toarray(), Cf.T.toarray()
    thin_qr = None   # the low-rank route's QR of C: the same for every mode
    for j, w in enumerate(omega):
        y = shapes[:, j]
        if noise <= 0:
            # exact data: the sparse saddle-point system [[D, -Cᵀ], [C, 0]] [φ; λ] = [0; y]
            # (Kidder's expansion, O(n) work for any number of sensors)
            D = (Kf - w**2 * Mf).tocsc()
            saddle = sp.bmat([[D, -Cf.T], [Cf, None]]).tocsc()
            sol = spla.splu(saddle).solve(np.concatenate([np.zeros(D.shape[0]), y]))
            phi, lam = sol[:D.shape[0]], sol[D.shape[0]:]
        elif dense:
            phi, lam = _tikhonov_receptance(Cf, _dense_receptance(Kd, Md, w, CdT), y, noise)
        else:
            D = (Kf - w**2 * Mf).tocsc()
            try:
                lu = spla.splu(D)
            except RuntimeError:  # ω is exactly a model eigenvalue: nudge it
                lu = spla.splu((Kf - (w * (1 + 1e-9)) ** 2 * Mf).tocsc())
            if few:
                phi, lam = _tikhonov_receptance(Cf, lu.solve(Cf.T.toarray()), y, noise)
            elif Cf.shape[0] * Cf.shape[1] <= LOW_RANK_LIMIT:
                # many sensors on a coarse model: G has rank <= n_free, solved in that space
                if thin_qr is None:
                    thin_qr = np.linalg.qr(Cf.toarray())
                phi, lam = _tikhonov_low_rank(lu, Cf, y, noise, thin_qr)
            else:  # many sensors: the same solution from a sparse system, memory O(n)
                phi, lam = _tikhonov_sparse(D, Cf, y, noise)
        out_shapes[free, j] = phi
        inertia = np.linalg.norm(w**2 * (Mf @ phi))
        forces[:, j] = lam
        rel[:, j] = np.abs(lam) / inertia if inertia > 0 else np.inf
    return Expansion(out_shapes, forces, rel)


#: above this many sensors the expansion avoids dense sensor x sensor and DOF x sensor
#: matrices (a sensor at every node of a fine mesh)
DENSE_SENSOR_LIMIT = 200
#: up to this many free DOFs (and DENSE_SENSOR_LIMIT sensors) the expansion factors
#: K − ω²M dense (the 46-element demo beam: 0.3 against 0.75 ms a mode)
DENSE_EXPANSION_DOFS = 400


def _tikhonov_receptance(C, X, y, noise):
    """(φ, λ) of the Tikhonov expansion (:func:`_tikhonov_discrepancy`) from X = D⁻¹Cᵀ
    (n_free, n_sensors): G = C X, symmetric but for rounding, and φ = X λ."""
    G = C @ X
    lam = _tikhonov_discrepancy(0.5 * (G + G.T), y, noise)
    return X @ lam, lam


def _dense_receptance(K, M, w, CT):
    """(K − ω²M)⁻¹ Cᵀ by a dense LU (ω exactly a model eigenvalue: nudged, as the sparse
    route does)."""
    try:
        return np.linalg.solve(K - w**2 * M, CT)
    except np.linalg.LinAlgError:
        return np.linalg.solve(K - (w * (1 + 1e-9)) ** 2 * M, CT)


#: sensors x free DOFs up to which many sensors are expanded through the thin QR of C
#: (4 000 000 values, 32 MB): 5 000 sensors on a 46-element beam
LOW_RANK_LIMIT = 4_000_000


def _tikhonov_low_rank(lu, C, y, noise, thin_qr=None):
    r"""The Tikhonov expansion of :func:`_tikhonov_discrepancy` for many sensors on a model
    with few DOFs: with the thin QR C = QR (Q: sensors × DOFs), G = C D⁻¹ Cᵀ = Q H Qᵀ with
    H = R D⁻¹ Rᵀ, so its eigenpairs come from the small H (G has rank ≤ the DOFs however
    many sensors there are) and the discrepancy search costs nothing per α.  The same
    solution as the dense and sparse routes (the part of y outside the range of Q is misfit
    no α removes).  ``thin_qr``: (Q, R) of C when the caller has it (one for every mode of
    an expansion: the QR of 999 sensors × 2 000 DOFs took 0.2 s a mode).  Returns (φ, λ)."""
    Q, R = np.linalg.qr(C.toarray()) if thin_qr is None else thin_qr
    H = R @ lu.solve(np.ascontiguousarray(R.T))
    w, V = np.linalg.eigh(0.5 * (H + H.T))
    U = Q @ V
    beta = U.T @ y
    outside = float(np.sum((y - U @ beta) ** 2))
    target = noise * np.max(np.abs(y)) * np.sqrt(y.size)
    a = np.abs(w)

    def misfit(alpha):
        return np.sqrt(np.sum((alpha**2 / (a**2 + alpha**2) * beta) ** 2) + outside)

    alpha = _discrepancy_alpha(misfit, a.min() * 1e-6 + 1e-300, a.max() * 1e3, target, noise)
    lam = U @ (w / (w**2 + alpha**2) * beta)
    return lu.solve(C.T @ lam), lam


def _tikhonov_sparse(D, C, y, noise):
    r"""The Tikhonov expansion of :func:`_tikhonov_discrepancy` without forming
    :math:`G = C D^{-1} C^T`: for each α the sparse symmetric system

    .. math:: \begin{bmatrix} C^TC & 0 & D \\ 0 & α^2 I & -C \\ D & -C^T & 0
              \end{bmatrix} \begin{bmatrix} φ \\ λ \\ μ \end{bmatrix} =
              \begin{bmatrix} C^T y \\ 0 \\ 0 \end{bmatrix}

    (stationarity of ‖Cφ − y‖² + α²‖λ‖² subject to Dφ = Cᵀλ), α by bisection on log α to
    the discrepancy ‖Cφ − y‖ = δ max|y| √n_s.  Returns (φ, λ)."""
    n, s = D.shape[0], C.shape[0]
    target = noise * np.max(np.abs(y)) * np.sqrt(s)
    scale = np.sqrt(np.abs(D.diagonal()).max())  # D / scale² is O(1) next to CᵀC
    # rows scaled by 1/scale, μ carried as scale·μ: the same solution, better pivots
    base = sp.bmat([[(C.T @ C).tocsc(), None, D / scale],
                    [None, sp.csc_matrix((s, s)), -C / scale],
                    [D / scale, -C.T / scale, None]]).tocsc()
    lam_rows = sp.diags(np.concatenate([np.zeros(n), np.ones(s), np.zeros(n)])).tocsc()
    rhs = np.concatenate([C.T @ y, np.zeros(s + n)])

    def solve(log_alpha):
        sol = spla.splu((base + np.exp(2 * log_alpha) * lam_rows).tocsc()).solve(rhs)
        phi, lam = sol[:n], sol[n:n + s]
        return phi, lam, np.log(np.linalg.norm(C @ phi - y)) - np.log(target)

    # α has the units of the receptance G = C D⁻¹ Cᵀ: bracket it about an estimate of ‖G‖;
    # the misfit grows with α: regula falsi (Illinois) on log α, to 1e-4 in the misfit
    probe = np.ones(s) / np.sqrt(s)
    try:
        g_norm = np.linalg.norm(C @ spla.splu(D).solve(C.T @ probe))
    except RuntimeError:  # ω exactly a model eigenvalue: bracket with the mass scale
        g_norm = 1.0 / scale**2
    a, b = np.log(1e-9 * g_norm), np.log(1e3 * g_norm)
    phi, lam, fa = solve(a)
    if fa >= 0:
        return phi, lam
    phi, lam, fb = solve(b)
    if fb <= 0:
        return phi, lam
    side = 0
    for _ in range(60):
        c = b - fb * (b - a) / (fb - fa)
        phi, lam, fc = solve(c)
        if abs(fc) < 1e-4:
            break
        if fc < 0:
            a, fa = c, fc
            fb = fb / 2 if side == -1 else fb
            side = -1
        else:
            b, fb = c, fc
            fa = fa / 2 if side == 1 else fa
            side = 1
    return phi, lam


def _tikhonov_discrepancy(G, y, noise):
    """min ||G λ - y||² + α²||λ||² with α chosen so that ||G λ - y|| equals the expected
    norm of the noise, ``noise * max|y| * sqrt(n_sensors)``.  G is symmetric: its
    eigenpairs G = Q W Qᵀ give the singular values |w| and λ = Q (w / (w² + α²)) Qᵀ y (a
    third of the time of the SVD)."""
    w, Q = np.linalg.eigh(G)
    beta = Q.T @ y
    target = noise * np.max(np.abs(y)) * np.sqrt(y.size)
    s2 = w**2

    def misfit(alpha):
        return np.linalg.norm(alpha**2 / (s2 + alpha**2) * beta)

    a = np.abs(w)
    alpha = _discrepancy_alpha(misfit, a.min() * 1e-6 + 1e-300, a.max() * 1e3, target, noise)
    return Q @ (w / (s2 + alpha**2) * beta)


#: the generic update's expansion holds each mode's misfit at the noise norm that the
#: stated noise stays below with this probability (:func:`discrepancy_factor`)
DISCREPANCY_QUANTILE_Z = 1.959964   # the standard normal's 97.5 % point


def discrepancy_factor(n_sensors: int) -> float:
    """τ of Morozov's discrepancy principle, ‖Gλ − y‖ = τ δ max|y| √n: the 97.5 % point
    of the norm of n independent noise values of deviation δ max|y| over its expectation,
    √(χ²ₙ(0.975) / n), by the Wilson–Hilferty cube (within 0.13 % of the exact quantile
    from n = 3 on): 1.21 for 45 sensors, 1.39 for 12.  With τ = 1 (the expected norm) the
    expansion fits part of the noise of a mode whose noise came out above its mean, and
    the generic update rang.  Derived, not tuned; then measured on copies of four beams'
    data (12-45 sensors, 4-6 modes, 0.3 % shape noise, 40 noise seeds each; reference
    beams, not the package's elements): of the copies of the model's own modes, 24 of 160
    updates moved some node's k by more than 10 % with τ = 1, 1 of 160 with this τ; the
    90th percentile of a linear taper's RMS reading error fell from 0.035-0.17 to
    0.009-0.032; a crack's stayed as it was (within ±0.04); a 6 cm zone's median rose by
    0.004-0.026 (it is smoothed a little more); a uniform 10 % loss read better (90th
    percentile 0.005-0.014 against 0.009-0.075) (``scripts/study_discrepancy.py``).  The
    words of the realisation on reference-beam truths (``scripts/bench_realisation.py``, 39
    cases a seed set): the first feature right in 32 against 28 and 23 spurious features
    against 42 on seeds 1-3, 31 against 28 and 26 against 35 on seeds 4-6 (a crack's,
    a taper's or an E change's first feature lost in one or two cases of each set, the
    linear tapers' spurious features 13 and 7 to 1).  A frame's expansion keeps τ = 1: on the
    portal (12 sensors, 6 modes) 20 copies of its own modes rang in none at τ = 1, and at
    this τ its narrower band let spurious features through (a 5 % taper of a column beside
    a softer beam; a rise on the far column above a crack at a column base; a loose
    brace's EA read 0.60, where τ = 1 reads it below 0.6)."""
    n = max(int(n_sensors), 1)
    a = 2.0 / (9.0 * n)
    return float(np.sqrt((1.0 - a + DISCREPANCY_QUANTILE_Z * np.sqrt(a)) ** 3))


def _discrepancy_alpha(misfit, lo, hi, target, noise):
    """α in [lo, hi] with ``misfit(α)`` (rising with α) equal to ``target``: bisection on
    log α to 1e-6; ``lo`` when there is no noise or even ``lo`` misfits by more."""
    if noise <= 0 or misfit(lo) >= target:
        return lo
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if misfit(mid) < target else (lo, mid)
        if hi / lo < 1 + 1e-6:
            break
    return np.sqrt(lo * hi)


def check_model_size(disc: Discretisation, measured: MeasuredModes, where: str = "model"
                     ) -> None:
    """The model needs more elastic modes than the test measured (one to spare for
    pairing); a mesh too coarse for the test is one line, not a solver failure."""
    available = len(disc.free) - 1 - rigid_body_count(disc)
    if available < measured.n_modes + 1:
        per_mode = 4
        modes = f"{max(available, 0)} elastic mode{'' if available == 1 else 's'}"
        raise GfeInputError(where, "elements", f"{disc.n_elements} elements give the model "
                            f"{modes}, too few for the {measured.n_modes} measured: use at least "
                            f"{per_mode * (measured.n_modes + 1)} elements ({per_mode} per "
                            "mode)")


def check_frequency_units(measured: MeasuredModes, model_hz) -> None:
    """Reject measured frequencies whose ratio to the model's (median over the modes in
    order, elastic ones only) points to wrong units: close to 2π (rad/s given as Hz), to
    1/2π (Hz divided by 2π), or outside [1/20, 20] (kHz, a model in millimetres, or the
    wrong model)."""
    model_hz = np.asarray(model_hz)
    positive = model_hz[model_hz > 0]
    if positive.size == 0:
        return
    k = min(positive.size, measured.n_modes)
    ratio = float(np.median(measured.frequencies_hz[:k] / positive[:k]))
    where, first = measured.source, measured.frequencies_hz[0]
    if abs(ratio / (2 * np.pi) - 1) < 0.1:
        raise GfeInputError(where, "modes[0].frequency", f"{first:.4g} Hz: the measured "
                            f"frequencies are {ratio:.3g} times the model's, close to 2π: "
                            "given in rad/s? Frequencies are in Hz")
    if abs(ratio * 2 * np.pi - 1) < 0.1:
        raise GfeInputError(where, "modes[0].frequency", f"{first:.4g} Hz: the measured "
                            f"frequencies are 1/{1 / ratio:.3g} of the model's, close to "
                            "1/2π: divided by 2π twice? Frequencies are in Hz")
    if not 0.05 <= ratio <= 20.0:
        hint = ("in kHz? " if abs(np.log10(ratio) + 3) < 0.5 else
                "in mHz? " if abs(np.log10(ratio) - 3) < 0.5 else "")
        raise GfeInputError(where, "modes[0].frequency", f"{first:.4g} Hz is {ratio:.3g} "
                            f"times the model's first frequency {positive[0]:.4g} Hz: {hint}"
                            "wrong units (rad/s or kHz for Hz, millimetres for metres) or "
                            "wrong model?")


def check_units(model, measured: MeasuredModes) -> None:
    """:func:`check_frequency_units` against the model's own modes."""
    disc = discretise(model)
    n = min(measured.n_modes + rigid_body_count(disc), len(disc.free) - 1)
    check_frequency_units(measured, discretisation_modes(disc, n).frequencies_hz)


@dataclass(frozen=True)
class Pair:
    test_mode: int
    model_mode: int
    test_hz: float
    model_hz: float
    error_pct: float
    mac: float | None   # None: paired by frequency (a test without usable shapes)


class PairSummary:
    """The rms frequency error and mean MAC of a comparison's ``pairs`` (no MAC when the
    ``pairing`` is by frequency)."""

    @property
    def freq_error_rms_pct(self) -> float:
        err = np.array([p.error_pct for p in self.pairs])
        return float(np.sqrt(np.mean(err**2))) if err.size else float("nan")

    @property
    def mac_mean(self) -> float | None:
        if self.pairing == "frequency":
            return None
        return float(np.mean([p.mac for p in self.pairs])) if self.pairs else float("nan")


@dataclass(frozen=True)
class Comparison(PairSummary):
    """Result of :func:`compare` (modes numbered from 1 in ``pairs``).  A test without
    usable shapes (:attr:`~gfe_opt.measured.MeasuredModes.frequency_only`) is paired by
    frequency; its MAC matrix, COMAC, residual and expanded shapes are None."""

    pairs: list
    mac_matrix: np.ndarray | None
    unpaired_test_modes: list
    sensor_x: np.ndarray
    comac: np.ndarray | None
    residual: np.ndarray | None
    residual_per_mode: np.ndarray | None
    model_modes: Modes
    expanded_shapes: np.ndarray | None
    notes: list = field(default_factory=list)
    pairing: str = "mac"

    def localisation(self) -> list[dict] | None:
        if self.residual is None:
            return None
        return [{"x": float(x), "residual": float(r)} for x, r in zip(self.sensor_x,
                                                                        self.residual)]

    def failure_places(self, fraction: float = 0.6, at_most: int = 3) -> list[tuple[float, float]]:
        """Local maxima of the residual above ``fraction`` of the largest, largest first
        (none for a frequency-only test)."""
        r = self.residual
        if r is None or not np.any(r > 0):
            return []
        padded = np.concatenate([[-np.inf], r, [-np.inf]])
        peaks = np.flatnonzero((r >= padded[:-2]) & (r >= padded[2:]) & (r >= fraction * r.max()))
        peaks = peaks[np.argsort(-r[peaks])][:at_most]
        return [(float(self.sensor_x[i]), float(r[i] / r.max())) for i in peaks]

    def to_json(self) -> dict:
        """The ``compare --json`` contract."""
        return {
            "pairs": [{"test_mode": p.test_mode, "model_mode": p.model_mode,
                       "test_hz": p.test_hz, "model_hz": p.model_hz,
                       "error_pct": p.error_pct, "mac": p.mac} for p in self.pairs],
            "freq_error_rms_pct": self.freq_error_rms_pct,
            "mac_mean": self.mac_mean,
            "localisation": self.localisation(),
            "pairing": self.pairing,
        }


@one_blas_thread
def compare(model: Model, measured: MeasuredModes, *, mac_threshold=DEFAULT_MAC_THRESHOLD,
            noise=DEFAULT_SHAPE_NOISE, n_model_modes: int | None = None,
            disc: Discretisation | None = None) -> Comparison:
    """Compare a model with measured modes: pairs, frequency errors, MAC, COMAC, residual.

    ``noise`` is the relative shape noise δ used to regularise the expansion.  A plane
    frame (with its measured modes, :func:`~gfe_opt.frame_data.load_frame_measured`) is
    compared by :func:`~gfe_opt.frame_data.compare_frame`, as ``gfe-opt compare`` does.
    """
    if getattr(model, "kind", None) == "frame":
        from .frame_data import FrameMeasured, compare_frame

        if not isinstance(measured, FrameMeasured):
            raise GfeInputError(getattr(measured, "source", None), "sensors",
                                "a frame's measured modes name a node or a member at each "
                                "sensor: read them with gfe_opt.frame_data."
                                "load_frame_measured(path, model)")
        return compare_frame(model, measured, mac_threshold)
    disc = discretise(model) if disc is None else disc
    measured, dropped = on_model(measured, model)
    check_model_size(disc, measured, model.source or model.name)
    C = observation(disc, measured)
    n_free = len(disc.free)
    rigid = rigid_body_count(disc)
    n_model = n_model_modes or min(max(2 * measured.n_modes, measured.n_modes + 4) + rigid,
                                   n_free - 2)
    K, M = disc.global_matrices()
    modes = discretisation_modes(disc, n_model, matrices=(K, M))
    check_frequency_units(measured, modes.frequencies_hz)
    if measured.frequency_only:
        return _compare_frequencies(measured, modes, dropped)
    at_sensors = C @ modes.shapes
    mac_matrix = mac(measured.shapes, at_sensors)
    # measured modes vibrate (f > 0): a rigid-body model mode is never their partner
    pairs_idx = pair_modes(np.where(modes.frequencies_hz > 0, mac_matrix, 0.0), mac_threshold,
                           measured.frequencies_hz, modes.frequencies_hz)
    pairs = [Pair(test_mode=t + 1, model_mode=m + 1,
                  test_hz=float(measured.frequencies_hz[t]),
                  model_hz=float(modes.frequencies_hz[m]),
                  error_pct=float(100.0 * (modes.frequencies_hz[m] - measured.frequencies_hz[t])
                                  / measured.frequencies_hz[t]),
                  mac=float(mac_matrix[t, m])) for t, m in pairs_idx]
    notes = list(dropped)
    pairs, far = plausible(pairs, measured.source, notes)
    pairs_idx = [(p.test_mode - 1, p.model_mode - 1) for p in pairs]
    unpaired = sorted(set(range(measured.n_modes)) - {t for t, _ in pairs_idx})
    if unpaired and len(unpaired) > len(far):
        notes.append(f"test mode(s) {[u + 1 for u in unpaired]} have no model mode with "
                     f"MAC >= {mac_threshold}")
    if not pairs_idx:
        raise GfeSolverError("no test mode pairs with any model mode "
                             f"(MAC >= {mac_threshold}); check sensors and units")
    t_idx = [t for t, _ in pairs_idx]
    m_idx = [m for _, m in pairs_idx]
    expansion = expand_modes(disc, C, measured.omega[t_idx], measured.shapes[:, t_idx],
                             noise, K, M)
    residual = np.sqrt(np.sum(expansion.relative_residual**2, axis=1))
    return Comparison(pairs=pairs, mac_matrix=mac_matrix, unpaired_test_modes=unpaired,
                      sensor_x=measured.x, comac=comac(measured.shapes[:, t_idx],
                                                       at_sensors[:, m_idx]),
                      residual=residual, residual_per_mode=expansion.relative_residual,
                      model_modes=modes, expanded_shapes=expansion.shapes, notes=notes)


def plausible(pairs, source, notes) -> tuple[list, list]:
    """The shape pairs whose frequencies are within 20 times of each other, and the others.
    A shape pair 20 times off in frequency is not the same mode (with few sensors a high
    model mode can look like a low one: a pin that gives on a clamped-pinned beam, 3
    sensors, paired its 1537 Hz mode with 59 kHz): left unpaired, said in ``notes``; the
    test's units are refused only when no pair is plausible."""
    far = [p for p in pairs if not 0.05 <= p.test_hz / p.model_hz <= 20.0]
    if far and len(far) == len(pairs):
        p = far[0]
        raise GfeInputError(source, f"modes[{p.test_mode - 1}].frequency",
                            f"{p.test_hz:.4g} Hz is {p.test_hz / p.model_hz:.3g} times the "
                            f"frequency of the model mode its shape pairs with "
                            f"({p.model_hz:.4g} Hz): a typo or wrong units?")
    for p in far:
        notes.append(f"test mode {p.test_mode} ({p.test_hz:.4g} Hz) is most like model mode "
                     f"{p.model_mode} in shape, but at {p.model_hz:.4g} Hz it cannot be the "
                     "same mode: left unpaired")
    return [p for p in pairs if p not in far], far


def _compare_frequencies(measured: MeasuredModes, modes: Modes, notes) -> Comparison:
    """:func:`compare` for a test without usable shapes: pairs by frequency only."""
    pairs_idx = pair_by_frequency(measured.frequencies_hz, modes.frequencies_hz)
    pairs = [Pair(test_mode=t + 1, model_mode=m + 1,
                  test_hz=float(measured.frequencies_hz[t]),
                  model_hz=float(modes.frequencies_hz[m]),
                  error_pct=float(100.0 * (modes.frequencies_hz[m] - measured.frequencies_hz[t])
                                  / measured.frequencies_hz[t]), mac=None)
             for t, m in pairs_idx]
    unpaired = sorted(set(range(measured.n_modes)) - {t for t, _ in pairs_idx})
    return Comparison(pairs=pairs, mac_matrix=None, unpaired_test_modes=unpaired,
                      sensor_x=measured.x, comac=None, residual=None, residual_per_mode=None,
                      model_modes=modes, expanded_shapes=None,
                      notes=[*notes, measured.without_shapes_note()], pairing="frequency")
