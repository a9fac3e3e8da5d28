r"""Fitting the physical parameters of effects to measured modes (damped Gauss–Newton).

Misfit
------
For a model, the lowest modes are paired with the measured ones by MAC (Hungarian,
threshold 0.3) and the weighted residual is

.. math:: χ^2 = \sum_j \Big(\frac{f_j/f_{t,j} - 1}{σ_f}\Big)^2
        + \sum_j \sum_s \Big(\frac{\hat φ_{sj} - \hat y_{sj}}{σ_s \max_s|\hat y_{sj}|}\Big)^2

with unit-norm, sign-aligned shapes at the sensors, σ_f the relative frequency noise and
σ_s the shape noise relative to each mode's largest amplitude.  A measured mode with no
partner costs :math:`(0.5/σ_f)^2`.  ``χ² per residual`` (χ²/n) is 1 for a model that fits
to the stated noise (a little less after fitting p parameters: (n − p)/n).

Fitting
-------
Every instance of an effect in the model is a *slot*: its fitted parameters are order-one
variables (:class:`~gfe_opt.effects.Variable`, with bounds), its chosen ones (a spring's
side, a profile's knots) are fixed.  Instances already in the model start where they are;
added ones start from given values or from the best point of a coarse grid.  χ² is
minimised by damped Newton steps (:func:`_finish`: the analytic Jacobian J, the Hessian
JᵀJ plus the Dennis–Gay–Welsch secant estimate of the second-order term, a
Levenberg–Marquardt damping, bounds held by projection) until a scale-free rule holds (the
Newton decrement below 1e-9 noise floors), so that machines whose arithmetic differs in the
last bits end at the same point; a fit that does not settle has failed.  The old path,
IPOPT through CasADi to the valley and then the same steps (``GFE_OPT_FIT_SOLVER=ipopt``:
the objective ½‖r‖², its gradient Jᵀr and the Gauss–Newton Hessian JᵀJ as small callbacks),
stays for comparison (``scripts/bench.py --parts fits,frames``): on the semi-rigid portal
frame's diagnosis it took 4 times the residual evaluations and 2.6 times the Jacobians
after the grid, to the same finding (README, Speed).

Uncertainty
-----------
At the optimum, the Gauss–Newton covariance of the variables is
:math:`s^2 (J^T J)^{-1}` with J the Jacobian of the normalised residuals and
:math:`s^2 = \max(1, χ^2/(n-p))` (the stated noise, or more when the fit is worse than it);
standard deviations of the physical parameters follow through the variable maps.  A
parameter the data cannot determine (a mass on a pinned support) gets an infinite one.
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.linalg import block_diag
from scipy.special import chdtri

from . import names
from .assembly import discretise, local_difference
from .correlation import mac, pair_by_frequency, pair_modes
from .effects import EffectType, effect_type
from .errors import GfeInputError, GfeSolverError
from .measured import MeasuredModes, observation
from .modal import CONDENSE_ABOVE, condensed, discretisation_modes, rigid_body_count
from .model import Effect, Model
from .screening import screened_chi2
from .structure import structure

DEFAULT_FREQ_NOISE = names.DEFAULT_FREQ_NOISE
DEFAULT_SHAPE_NOISE = names.DEFAULT_FIT_SHAPE_NOISE
#: cost of a residual when the model cannot be solved (e.g. buckled by a compression)
FAILED_RESIDUAL = 1e6


@dataclass(frozen=True)
class Noise:
    """Relative noise of the measured frequencies and shapes; ``given`` when the user
    stated it (otherwise these are assumptions and the data's own level is estimated)."""

    freq: float = DEFAULT_FREQ_NOISE
    shape: float = DEFAULT_SHAPE_NOISE
    given: bool = False

    def __post_init__(self):
        for name, value in (("frequency noise", self.freq), ("shape noise", self.shape)):
            if not 0.0 < value < 1.0:
                raise GfeInputError(None, name, f"must lie between 0 and 1 (relative), got "
                                    f"{value!r}: zero noise would make every difference "
                                    "infinitely significant")


def noise_of(freq_noise=None, shape_noise=None) -> Noise:
    """A :class:`Noise` from optional values (both None: the defaults, not given)."""
    given = freq_noise is not None or shape_noise is not None
    return Noise(DEFAULT_FREQ_NOISE if freq_noise is None else float(freq_noise),
                 DEFAULT_SHAPE_NOISE if shape_noise is None else float(shape_noise), given)


# -------------------------------------------------------------------------------------------
# Misfit
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Misfit:
    """χ² of a model against measured modes, with the numbers users read."""

    chi2: float
    freq_error_rms_pct: float
    mac_mean: float | None        # None: a frequency-only test (no MAC)
    n_residuals: int
    chi2_freq: float = 0.0
    n_freq: int = 0

    @property
    def chi2_per_residual(self) -> float:
        return self.chi2 / self.n_residuals if self.n_residuals else float("inf")

    def summary(self) -> dict:
        """The JSON form (``baseline``, ``before``, ``after``)."""
        return {"freq_error_rms_pct": self.freq_error_rms_pct, "mac_mean": self.mac_mean,
                "chi2_per_residual": self.chi2_per_residual}


def misfit(model: Model, measured: MeasuredModes, noise: Noise, C=None) -> Misfit:
    """Weighted residual of ``model`` against ``measured`` (module docstring)."""
    r, f_err, macs = residuals(model, measured, noise, C)
    n = measured.n_values
    no_mac = None if measured.frequency_only else 0.0
    if r is None:
        return Misfit(np.inf, np.inf, no_mac, n, np.inf, measured.n_modes)
    freq = r.reshape(measured.n_modes, -1)[:, 0]
    return Misfit(chi2=float(np.sum(r**2)),
                  freq_error_rms_pct=float(100 * np.sqrt(np.mean(f_err**2))) if f_err.size
                  else float("inf"),
                  mac_mean=float(np.mean(macs)) if macs is not None and macs.size else no_mac,
                  n_residuals=r.size, chi2_freq=float(np.sum(freq**2)),
                  n_freq=measured.n_modes)


def residuals(model, measured, noise: Noise, C=None):
    """Fixed-length residual vector (per measured mode: frequency, then sensors), the
    relative frequency errors and MACs of the pairs (None for a frequency-only test, whose
    modes pair by frequency and whose residuals are the frequencies alone); ``(None, ...)``
    if the solve fails."""
    point = evaluate(model, measured, noise, C)
    if point is None:
        return None, np.zeros(0), np.zeros(0)
    return point.r, point.f_err, point.macs


@dataclass
class Point:
    """One evaluation of the residual, with what its derivative needs: the discretisation,
    its matrices and modes, the pairs (measured ``rows``, model ``cols``), the observation
    matrix and the normalisation of the paired shapes at the sensors."""

    r: np.ndarray
    f_err: np.ndarray
    macs: np.ndarray | None
    disc: object
    K: object
    M: object
    modes: object
    rows: np.ndarray
    cols: np.ndarray
    C: object = None
    shat: np.ndarray | None = None      # unit shapes at the sensors (n_sensors, pairs)
    norm: np.ndarray | None = None      # their norms before normalising
    sign: np.ndarray | None = None      # the sign that aligns them with the measured ones
    scale: np.ndarray | None = None     # σ_s max|y| of each pair


def evaluate(model, measured, noise: Noise, C=None) -> Point | None:
    """The residual of :func:`residuals` at ``model`` with its intermediate results; None
    if the solve fails."""
    try:
        disc = discretise(model)
        n_model = model_modes(model, disc, measured)
        K, M = disc.global_matrices()
        modes = discretisation_modes(disc, n_model, matrices=(K, M))
    except (GfeSolverError, ValueError, np.linalg.LinAlgError):
        return None
    return point_of(disc, K, M, modes, measured, noise, C)


def model_modes(model, disc, measured) -> int:
    """How many model modes a residual pairs the measured ones with: four more than were
    measured, and the rigid-body ones."""
    return min(measured.n_modes + 4 + rigid_body_count(disc), _max_modes(disc))


def point_of(disc, K, M, modes, measured, noise: Noise, C=None) -> Point:
    """The :class:`Point` of :func:`evaluate` from the model's modes, however solved."""
    if measured.frequency_only:
        pairs = pair_by_frequency(measured.frequencies_hz, modes.frequencies_hz)
        rows = np.array([t for t, _ in pairs], dtype=int)
        cols = np.array([m for _, m in pairs], dtype=int)
        r = np.full(measured.n_modes, 0.5 / noise.freq)
        f_err = modes.frequencies_hz[cols] / measured.frequencies_hz[rows] - 1.0
        r[rows] = f_err / noise.freq
        return Point(r, f_err, None, disc, K, M, modes, rows, cols)
    if C is None or disc.shear_g is not None:   # (a frame's C is None: structure.Frame)
        C = observation(disc, measured)
    shapes = C @ modes.shapes
    mac_matrix = mac(measured.shapes, shapes)
    elastic = np.where(modes.frequencies_hz > 0, np.nan_to_num(mac_matrix), 0.0)
    pairs = pair_modes(elastic, 0.3, measured.frequencies_hz, modes.frequencies_hz)
    rows = np.array([t for t, _ in pairs], dtype=int)
    cols = np.array([m for _, m in pairs], dtype=int)
    r = np.zeros((measured.n_modes, 1 + measured.n_sensors))
    r[:, 0] = 0.5 / noise.freq  # an unpaired mode
    f_err = modes.frequencies_hz[cols] / measured.frequencies_hz[rows] - 1.0
    y = measured.shapes[:, rows] / np.linalg.norm(measured.shapes[:, rows], axis=0)
    norm = np.linalg.norm(shapes[:, cols], axis=0)
    shat = shapes[:, cols] / norm
    sign = np.sign(np.sum(shat * y, axis=0))
    scale = noise.shape * np.max(np.abs(y), axis=0)
    r[rows, 0] = f_err / noise.freq
    r[rows, 1:] = ((shat * sign - y) / scale).T
    return Point(r.ravel(), f_err, mac_matrix[rows, cols], disc, K, M, modes, rows, cols,
                 C, shat, norm, sign, scale)


def point_jacobian(point: Point, z, model_at, measured, noise: Noise, lower, upper,
                   step: float = 1e-5, columns=None, owner=None) -> np.ndarray:
    """The Jacobian of the residual at ``point`` (the evaluation at z) with respect to z,
    the pairing held: eigenvalue and eigenvector derivatives
    (:func:`~gfe_opt.sensitivity.eigen_derivatives`) with ∂K, ∂M (and, for a shear beam,
    the observation's ∂C) from second-order differences of the *matrices* of
    ``model_at(z)`` (central; at a bound one-sided three-point, stepping inwards), no
    modal solve besides the one of ``point``.  ``owner``: per variable, the index of the
    effect of ``model_at(z)`` it moves; the matrices are then differenced on the elements
    that effect changes (:func:`~gfe_opt.assembly.local_difference`) where it changes few.
    Raises ``ValueError`` where the modes have no derivative (a repeated or zero eigenvalue
    among the paired ones).  ``columns``: only those columns are wanted (the others come
    out zero): the matrices of the other variables are not built, and the
    eigen-derivatives still solve for every column (zero ones there), so each wanted
    column is the full Jacobian's to the last bit."""
    from .sensitivity import eigen_derivatives

    n = z.size
    shear = point.disc.shear_g is not None and not measured.frequency_only

    def matrices(zz):
        disc = discretise(model_at(zz))
        K, M = disc.global_matrices()
        return K, M, (observation(disc, measured) if shear else None)

    def local(k, points, weights):
        """The weighted sum of the matrices at ``points`` from the elements variable k's
        effect changes (None: not local)."""
        if owner is None or shear:
            return None
        part = local_difference([model_at(zz) for zz in points], weights, owner[k])
        return None if part is None else (*part, None)

    dK, dM, dC = [], [], []
    wanted = range(n) if columns is None else set(int(k) for k in columns)
    zero = sp.csr_matrix(point.K.shape)
    zero_c = sp.csr_matrix(point.C.shape) if shear else None
    for k in range(n):
        if k not in wanted:
            dK.append(zero)
            dM.append(zero)
            dC.append(zero_c)
            continue
        h = step * max(1.0, abs(z[k]))
        up, down = z.copy(), z.copy()
        if z[k] + h <= upper[k] and z[k] - h >= lower[k]:
            up[k] += h
            down[k] -= h
            diff = local(k, (up, down), (1 / (2 * h), -1 / (2 * h)))
            if diff is None:
                a, b = matrices(up), matrices(down)
                diff = [(x - y) / (2 * h) if x is not None else None for x, y in zip(a, b)]
        else:
            h = h if z[k] + 2 * h <= upper[k] else -h
            up[k] += h
            down[k] += 2 * h
            diff = local(k, (up, down, z), (4 / (2 * h), -1 / (2 * h), -3 / (2 * h)))
            if diff is None:
                here = (point.K, point.M, point.C if shear else None)
                a, b = matrices(up), matrices(down)
                diff = [(4 * x - y - 3 * c) / (2 * h) if x is not None else None
                        for x, y, c in zip(a, b, here)]
        dK.append(diff[0])
        dM.append(diff[1])
        dC.append(diff[2])
    lam_all = (2 * np.pi * point.modes.frequencies_hz) ** 2
    cols, rows = point.cols, point.rows
    lam = lam_all[cols]
    if np.any(lam <= 0):
        raise ValueError("a paired mode has zero frequency: no derivative")
    phi = point.modes.shapes[:, cols]
    dlam, dphi = eigen_derivatives(point.K, point.M, point.disc.free, lam, phi, dK, dM,
                                   all_lam=lam_all,
                                   dense=getattr(point.disc, "dense_derivatives", None),
                                   shapes=not measured.frequency_only)
    f_model = point.modes.frequencies_hz[cols]
    dfreq = dlam / (2 * lam[:, None]) * (f_model / measured.frequencies_hz[rows])[:, None] \
        / noise.freq
    if measured.frequency_only:
        J = np.zeros((measured.n_modes, n))
        J[rows] = dfreq
        return J
    J = np.zeros((measured.n_modes, 1 + measured.n_sensors, n))
    J[rows, 0] = dfreq
    C = point.C
    for i, t in enumerate(rows):
        raw = C @ dphi[:, i, :]                                   # (sensors, n)
        if shear:
            raw = raw + np.column_stack([dC[k] @ phi[:, i] for k in range(n)])
        s = point.shat[:, i]
        ds = point.sign[i] * (raw - np.outer(s, s @ raw)) / point.norm[i]
        J[t, 1:] = ds / point.scale[i]
    return J.reshape(-1, n)


def _max_modes(disc) -> int:
    """At most one fewer than the free DOFs (a support that gives frees its DOF: the
    discretisation's, not the supports' count)."""
    return disc.free.size - 1


# -------------------------------------------------------------------------------------------
# Slots: effect instances with their variables
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Slot:
    """One effect instance in a fit: its type, fixed parameters, starting parameters and
    order-one variables (none when it is held at ``start``)."""

    effect: EffectType
    fixed: dict
    start: dict
    variables: tuple
    added: bool
    found: bool   # the effect it gives is fitted to data (added, or found before)


def slots_for(model: Model, adding) -> list[Slot]:
    """Slots of the model's instances (re-estimated from where they are) and of the added
    ones (``Effect`` with partial or no parameters).  An effect that is redundant with
    another in the fit (E with a stiffness profile) is held."""
    base = model.with_effects([], check=False)
    entries = [(e, False) for e in model.effects] + [(e, True) for e in adding]
    names = {e.name for e, _ in entries}
    out = []
    for e, added in entries:
        kind = effect_type(e.name)
        fixed = {k: e.parameters[k] for k in kind.fixed_keys(model) if k in e.parameters}
        missing = [k for k in kind.fixed_keys(model) if k not in fixed]
        if missing:
            raise GfeInputError(None, e.name, f"needs {', '.join(missing)} to be fitted")
        held = any(n in names for n in kind.redundant_with)
        variables = () if held else tuple(kind.variables(base, fixed))
        out.append(Slot(kind, fixed, dict(e.parameters), variables, added,
                        added or e.found))
    return out


def n_variables(slots) -> int:
    return sum(len(s.variables) for s in slots)


# -------------------------------------------------------------------------------------------
# The fit
# -------------------------------------------------------------------------------------------


@dataclass
class Fit:
    """A model with fitted effects, its misfit and the uncertainty of every parameter.

    ``effects`` are all instances of the fitted model in order; ``sigma`` holds one dict of
    standard deviations per instance; ``added`` indexes the instance this fit was about
    (None for a re-estimate of the present effects).  ``significant``, ``failed`` and
    ``size_sigmas`` are set by the diagnosis.
    """

    name: str
    effects: tuple
    sigma: tuple
    added: int | None
    model: Model
    misfit: Misfit
    n_params: int
    status: str
    success: bool
    evaluations: int   # full residual evaluations, a condensed beam's stand-in's included
    #                    (grid points the screen took not counted)
    significant: bool = False
    #: lowers χ² by more than its threshold alone, its size's σ aside: may lead a pair
    #: when a uniform change fits best alone (set by the diagnosis)
    gains_enough: bool = False
    #: significant only as the first of a pair that explains the data (set by the diagnosis)
    leads_pair: bool = False
    failed: bool = False
    size_sigmas: float = 0.0
    gain: float = 0.0          # χ² of the present effects alone minus this fit's
    threshold: float = 0.0     # the gain it needed to be significant
    notes: list = field(default_factory=list)
    mirror_position: float | None = None   # fits as well at x -> L - x (set by diagnosis)
    equivalent: list = field(default_factory=list)  # other effect sets that fit as well
    #: on a frame, the candidate's fits at its other places: (effects, χ²) each (set by the
    #: diagnosis; a place that fits as well is said)
    other_places: list = field(default_factory=list)
    unidentified: list = field(default_factory=list)  # parameters these data do not estimate
    #: trades the effect declares a finding (on a frame a short zone: its length against
    #: its ratios; the data fix the combination, not each value): sentences
    traded: list = field(default_factory=list)
    #: per effect, the combinations of its parameters it declares the data fix
    #: (:meth:`~gfe_opt.effects.base.EffectType.told_values`; a frame zone's added bending
    #: compliance and mass): {key: {"label", "unit", "value", "sigma"}}
    told: tuple = ()
    #: per effect, parameters that ended on a bound of their range: {key: "at least" |
    #: "at most"} (the data tell one side only)
    bounds: tuple = ()
    #: per effect, the keys of its variables that ended on a bound of their range, on any
    #: scale (a zone's stiffness ratio at 0.05, a place at an end; a key once a variable):
    #: held there, not free parameters of the fit
    held: tuple = ()

    @property
    def effect(self) -> str:
        return self.name

    @property
    def parameters(self) -> dict:
        return self.effects[self.added].parameters if self.added is not None else {}

    @property
    def uncertainty(self) -> dict:
        return self.sigma[self.added] if self.added is not None else {}

    @property
    def bound(self) -> dict:
        """The added effect's parameters on a bound of their range (one-sided)."""
        return self.bound_of(self.added) if self.added is not None else {}

    @property
    def n_held(self) -> int:
        """How many of the fit's variables ended on a bound of their range."""
        return sum(len(keys) for keys in self.held)

    def held_of(self, i: int) -> tuple:
        """Effect i's keys of variables on a bound of their range (:attr:`held`)."""
        return self.held[i] if i < len(self.held) else ()

    def bound_of(self, i: int) -> dict:
        """Effect i's parameters on a bound of their range."""
        return self.bounds[i] if i < len(self.bounds) else {}

    def describe(self) -> str:
        """``crack: position = 0.190 ± 0.001 m, depth_ratio = 0.50 ± 0.01``."""
        if self.added is None:
            return "present effects re-estimated"
        return f"{self.name}: " + effect_type(self.name).describe(
            self.parameters, self.uncertainty, self.bound)

    def effect_json(self, i: int) -> dict:
        """Effect i of the fit: name, parameters, σ and the parameters on a bound."""
        e = self.effects[i]
        return {"effect": e.name, "parameters": jsonable(e.parameters),
                "uncertainty": jsonable(self.sigma[i]),
                "bounds": {k: v.replace(" ", "_") for k, v in self.bound_of(i).items()}}

    def to_json(self) -> dict:
        added = (self.effect_json(self.added) if self.added is not None
                 else {"parameters": {}, "uncertainty": {}, "bounds": {}})
        return {"effect": self.name, "parameters": added["parameters"],
                "uncertainty": added["uncertainty"], **self.misfit.summary(),
                "significant": self.significant, "mirror_position": self.mirror_position,
                "equivalent": [[{"effect": e.name, "parameters": jsonable(e.parameters)}
                                for e in effects] for effects in self.equivalent],
                "not_estimable": list(self.unidentified), "traded": list(self.traded),
                "told": jsonable(self.told[self.added]) if self.added is not None
                and self.told else {},
                "bounds": added["bounds"]}


def jsonable(params: dict) -> dict:
    """Parameters with numpy values as floats (integers as integers: an index), infinite σ
    as null (valid JSON); nested lists and dicts (a frame's sensor in ``remaining``)
    likewise."""
    def one(v):
        if isinstance(v, (list, tuple, np.ndarray)):
            return [one(x) for x in v]
        if isinstance(v, dict):
            return {k: one(x) for k, x in v.items()}
        if isinstance(v, str):
            return v
        if isinstance(v, (bool, np.bool_)):
            return bool(v)
        if isinstance(v, (int, np.integer)):
            return int(v)   # an index stays one (``not_needed``'s and ``moved``'s)
        v = float(v)
        return v if np.isfinite(v) else None

    return {k: one(v) for k, v in params.items()}


#: how fits differentiate the residual: "analytic" (eigen-derivatives) or "difference" (of
#: the modal solves: the old path, kept for scripts/bench.py --parts fits, which sets it for
#: every process through the environment variable GFE_OPT_JACOBIAN)
JACOBIAN = os.environ.get("GFE_OPT_JACOBIAN", "analytic")
#: grids screened in bulk (:mod:`gfe_opt.screening`) where their points differ locally;
#: ``GFE_OPT_SCREEN=0`` solves every grid point (``scripts/bench.py`` compares both)
SCREEN = os.environ.get("GFE_OPT_SCREEN", "1") != "0"
if JACOBIAN not in ("analytic", "difference"):
    raise GfeInputError("GFE_OPT_JACOBIAN", None, f"must be 'analytic' or 'difference', got "
                        f"{JACOBIAN!r}")
#: what minimises an effect fit from its start: "newton" (the finish's damped Newton steps,
#: :func:`_finish`, from the start on) or "ipopt" (IPOPT through CasADi to the valley, then
#: the finish: the old path, kept for scripts/bench.py --parts fits, which sets it for every
#: process through the environment variable GFE_OPT_FIT_SOLVER)
FIT_SOLVER = os.environ.get("GFE_OPT_FIT_SOLVER", "newton")
if FIT_SOLVER not in ("newton", "ipopt"):
    raise GfeInputError("GFE_OPT_FIT_SOLVER", None, f"must be 'newton' or 'ipopt', got "
                        f"{FIT_SOLVER!r}")
#: errors of a trial model that make its residual the failed one
_TRIAL_ERRORS = (GfeInputError, GfeSolverError, ValueError, FloatingPointError,
                 np.linalg.LinAlgError)


class Objective:
    """The residual r(z) of a fit, counted, the last evaluation kept (the Jacobian at a
    point reuses its modal solve); ``jacobian(z, r, lower, upper)`` is the analytic one
    (:func:`point_jacobian`, falling back to differences of r where the modes have no
    derivative; None at a point whose modes came from the condensed route, which the caller
    differences with its own step), None when fits difference the residual itself."""

    def __init__(self, model_at, measured, noise, C, analytic: bool = True, owner=None):
        self.model_at, self.measured, self.noise, self.C = model_at, measured, noise, C
        #: per variable, the index of the effect of ``model_at(z)`` it moves
        self.owner = owner
        self.count = 0
        self.fallbacks = 0
        self._last = None
        self._last_jacobian = None
        self.jacobian = self._analytic if analytic else None
        #: the residual of the same fit on a coarser mesh solved directly, where a fit of a
        #: beam solved through condensed super-elements converges first (:func:`_minimise`)
        self.stand_in = None

    def point(self, z) -> Point | None:
        z = np.asarray(z, dtype=float)
        key = z.tobytes()
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        self.count += 1
        try:
            # a trial at the far end of a range may overflow in the solve: a failed point,
            # not a warning to the user
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                point = evaluate(self.model_at(z), self.measured, self.noise, self.C)
        except _TRIAL_ERRORS:
            point = None
        self._last = (key, point)
        return point

    def __call__(self, z) -> np.ndarray:
        point = self.point(z)
        return np.full(self.measured.n_values, FAILED_RESIDUAL) if point is None else point.r

    def pairing(self):
        """Which measured mode the last evaluation paired with which model mode (None where
        it failed): where two points' pairings differ, a seam of χ² lies between them
        (:func:`_finish`)."""
        point = None if self._last is None else self._last[1]
        return None if point is None else (point.rows.tobytes(), point.cols.tobytes())

    def _analytic(self, z, r, lower, upper, columns=None) -> np.ndarray:
        z = np.asarray(z, dtype=float)
        # the last one kept (read-only): a fit's σ asks again at the point its finish
        # ended on
        key = (z.tobytes(), None if columns is None else tuple(int(k) for k in columns),
               np.asarray(lower, dtype=float).tobytes(),
               np.asarray(upper, dtype=float).tobytes())
        if self._last_jacobian is not None and self._last_jacobian[0] == key:
            return self._last_jacobian[1]
        J = None
        point = self.point(z)
        if point is not None and point.modes.condensed:
            # the residual of the condensed route's approximate shapes: the caller
            # differences it, as where no analytic Jacobian is given (a shear beam's route
            # turns on its parameters: one fit may see both)
            return None
        if point is not None:
            try:
                J = point_jacobian(point, z, self.model_at, self.measured, self.noise, lower,
                                   upper, columns=columns, owner=self.owner)
            except _TRIAL_ERRORS:
                pass
        if J is None:
            self.fallbacks += 1
            J = _difference_jacobian(self, z, r, lower, upper)
        J.flags.writeable = False
        self._last_jacobian = (key, J)
        return J


@dataclass
class FitProblem:
    """What a fit works on: the model without effects, the slots, their variables' bounds,
    the residual (:class:`Objective`) and the map from variables to effects."""

    base: Model
    slots: list
    lower: np.ndarray
    upper: np.ndarray
    residual: Objective

    def effects_of(self, z) -> list:
        out, i = [], 0
        for slot in self.slots:
            k = len(slot.variables)
            if k == 0:
                out.append(Effect(slot.effect.name, slot.start, slot.found))
            else:
                out.append(Effect(slot.effect.name, slot.effect.to_physical(
                    self.base, slot.variables, z[i:i + k], slot.fixed), slot.found))
            i += k
        return out

    def canonical(self, z) -> np.ndarray:
        """``z`` with each slot's variables as its effect lies on the structure
        (:meth:`~gfe_opt.effects.base.EffectType.to_physical`); unchanged where they
        already are."""
        def one(slot, zs):
            again = slot.effect.to_variables(self.base, slot.variables, slot.effect.to_physical(
                self.base, slot.variables, zs, slot.fixed))
            return again if np.max(np.abs(again - zs)) > 1e-12 else zs
        return self._per_slot(z, one)

    def untied(self, z) -> np.ndarray:
        """``z`` moved off the kinks of its effects (:meth:`EffectType.untie`: a zone with
        an edge on an end starts past it), the same structure; a fit started on a kink
        could not certify its stopping rule."""
        return np.clip(self._per_slot(z, lambda slot, zs: slot.effect.untie(
            self.base, slot.variables, zs)), self.lower, self.upper)

    def snapped(self, z) -> np.ndarray | None:
        """``z`` with each effect's edge that stopped short of an end moved onto it
        (:meth:`EffectType.snap`), or None when no effect has one."""
        moved = False

        def one(slot, zs):
            nonlocal moved
            out = slot.effect.snap(self.base, slot.variables, zs)
            moved = moved or out is not None
            return zs if out is None else out
        z = np.clip(self._per_slot(z, one), self.lower, self.upper)
        return z if moved else None

    def reordered(self, z, other, within: float) -> bool:
        """Whether ``other`` is ``z`` with the variables of slots of one effect, and of the
        same fixed parameters, exchanged (each within ``within`` of its counterpart): two
        instances of an effect fitted together end in either slot as one structure (two
        cracks, the first's place and depth in the second's slot), not another end."""
        parts, i = [], 0
        for slot in self.slots:
            k = len(slot.variables)
            parts.append((slot.effect.name, repr(sorted(slot.fixed.items())),
                          tuple(v.key for v in slot.variables), i, k))
            i += k
        left = list(range(len(parts)))
        for name, fixed, keys, i, k in parts:
            match = next((j for j in left if parts[j][:3] == (name, fixed, keys) and np.max(
                np.abs(np.asarray(other)[parts[j][3]:parts[j][3] + k] - np.asarray(z)[i:i + k]),
                initial=0.0) <= within), None)
            if match is None:
                return False
            left.remove(match)
        return True

    def _per_slot(self, z, fn) -> np.ndarray:
        z = np.array(z, dtype=float)
        i = 0
        for slot in self.slots:
            k = len(slot.variables)
            if k:
                z[i:i + k] = fn(slot, z[i:i + k])
            i += k
        return z


#: a beam solved through condensed super-elements (above
#: :data:`~gfe_opt.modal.CONDENSE_ABOVE` elements) has its fits started on the same beam at
#: CONDENSE_ABOVE elements, solved directly with the analytic Jacobian (its grids, the points
#: their screens keep, a first convergence: :func:`_minimise`), and finished on its own
#: mesh.  Measured on ``scripts/bench.py``'s 2 000-element diagnosis (serial fits, one BLAS
#: thread, no realisation): the fine mesh's evaluations 320 → 97, 7.2 → 4.2 s, every fit's
#: χ² the same to 2e-10 (relative).  False: the grids and the finishes on the fine mesh
STAND_IN = True


def fit_problem(model: Model, measured: MeasuredModes, adding=(), *, noise: Noise, C=None,
                jacobian: str | None = None) -> FitProblem:
    """The :class:`FitProblem` of :func:`fit_effects` (same arguments)."""
    base = model.with_effects([], check=False)
    slots = slots_for(model, adding)
    if C is None:   # a frame's is None: read per model (evaluate)
        C = structure(model).sensor_matrix(measured)
    lower = np.array([v.lower for s in slots for v in s.variables])
    upper = np.array([v.upper for s in slots for v in s.variables])
    problem = FitProblem(base, slots, lower, upper, None)
    # the analytic Jacobian where the modal solve is direct: on a beam solved through
    # condensed super-elements (above CONDENSE_ABOVE elements) the residual is that of the
    # approximate shapes, and ∂K φ loses ~eps N⁴ to cancellation (3e-3 at 2 000 elements):
    # there its derivative and the residual's disagreed by 3e-4 and the finish could not
    # certify its rule, while differences of the residual cost the same (7.1 s both for
    # update --add crack on 2 000 elements)
    wanted = (jacobian or JACOBIAN) == "analytic"
    owner = [j for j, s in enumerate(slots) for _ in s.variables]
    problem.residual = Objective(
        lambda z: base.with_effects(problem.effects_of(z), check=False), measured, noise, C,
        wanted, owner=owner)
    if condensed(base) and STAND_IN:
        # the same beam at the finest mesh solved directly, where the fit converges first
        # (:func:`_minimise`); its own sensor matrix
        def coarse_at(z):
            return base.with_effects(problem.effects_of(z), check=False).with_elements(
                CONDENSE_ABOVE)
        coarse = base.with_elements(CONDENSE_ABOVE)
        problem.residual.stand_in = Objective(
            coarse_at, measured, noise, structure(coarse).sensor_matrix(measured), wanted,
            owner=owner)
    return problem


def fit_effects(model: Model, measured: MeasuredModes, adding=(), *, noise: Noise,
                max_iter: int = 25, C=None, name: str | None = None,
                alternatives=(), multistart="auto", jacobian: str | None = None) -> Fit:
    """Fit the parameters of the model's effects and of ``adding`` (effects whose given
    parameters are starting values; ``Effect(name, {})``: a grid chooses them).
    ``alternatives`` are further starting parameter sets of the last added effect (same
    fixed parameters): the best grid point over all of them starts the fit.  When that
    fit of frequencies alone does not reach the noise (``multistart="auto"``; with shapes
    the valleys are wide enough) or always (``True``), the fit runs
    again from profile starts (:func:`_profile_starts`: effects that trade against each
    other, a soft clamp and a tip mass) and, with ``True``, from every alternative; with
    ``"valleys"`` it runs again from the best grid point of every other valley along the
    last added effect's place (:func:`_valleys`), shapes or not; the best end is kept, and
    ends that fit as well elsewhere are the fit's ``equivalent``.
    ``jacobian``: ``"analytic"`` (eigen-derivatives, :func:`point_jacobian`) or
    ``"difference"`` (of the modal solves); default :data:`JACOBIAN`."""
    problem = fit_problem(model, measured, adding, noise=noise, C=C, jacobian=jacobian)
    base, slots, residual, effects_of = (problem.base, problem.slots, problem.residual,
                                         problem.effects_of)
    lower, upper, C = problem.lower, problem.upper, problem.residual.C
    n_res = measured.n_values

    def chi2(z):
        return float(np.sum(residual(z) ** 2))

    # a given value is the only grid point of its variable; the others use their grid
    def grid_of(slot, start):
        return [(v.order_one(base, _value(start, v)),) if _has(start, v)
                else _with_null(slot.effect, v, base) for v in slot.variables]

    grids = [grid_of(slot, slot.start) for slot in slots]
    # where each added effect is exactly nothing (one structure wherever its place is)
    nulls = [[_null_of(slot.effect, v, base, exact=True) for v in slot.variables]
             for slot in slots]
    starts, informed = [], []
    variants = [grids] + [grids[:-1] + [grid_of(slots[-1], alt)] for alt in alternatives]
    # where the fits start is chosen on a condensed beam's stand-in (:func:`_minimise`
    # converges there first): its grids, the points their screens keep, the profile starts
    stand_in = residual.stand_in
    starting = residual if stand_in is None else stand_in

    def start_chi2(z):
        return float(np.sum(starting(z) ** 2))

    def bulk(zs, null):   # grids screened in bulk (:mod:`.screening`)
        return screened_chi2(residual, start_chi2, zs, null) if SCREEN else None

    # each added effect's place variable (a valley of the grid along it may hold the
    # optimum that the grid's coarse sizes ranked second: frequencies alone)
    places = [next((k for k, v in enumerate(slot.variables) if v.key == "position"), None)
              for slot in slots]
    valleys = []
    for n, grid in enumerate(variants):
        start, guess = _grid_start(start_chi2, grid, nulls, bulk, places=places,
                                   valleys=valleys if n == 0 else None)
        starts.append(np.clip(start, lower, upper))
        if guess is not None:
            informed.append(problem.untied(np.clip(guess, lower, upper)))
    starts = [problem.untied(s) for s in starts]
    status, success = "Nothing_To_Fit", True
    z = starts[0]
    ends, equivalent = [], []
    if z.size:
        values = [start_chi2(s) for s in starts]
        first = starts[lowest(values)]
        ends.append(_minimise(residual, chi2, first, lower, upper, max_iter))
        if informed:
            # the added effect vanished at a grid's best point: its place there is no
            # guess; the fit runs again from where the grid puts it when present (the best
            # such start).  Its end replaces the first when it converged lower by more than
            # the finish's own margin (FINISH_SETTLED floors): the same valley reached from
            # two starts is one end, which rounding must not choose
            guess = informed[lowest([start_chi2(s) for s in informed])]
            other = _minimise(residual, chi2, guess, lower, upper, max_iter)
            floor = max(1.0, ends[0][1] / max(n_res - z.size, 1))
            if other[3] and other[1] < ends[0][1] - FINISH_SETTLED * floor:
                ends[0] = other
        at_noise = min(e[1] for e in ends) <= chdtri(max(n_res - z.size, 1), 1.0 - 0.999)
        def other_valleys(taken):   # the best grid point of every valley not yet started
            out = []
            for v in valleys:
                v = problem.untied(np.clip(v, lower, upper))
                if not any(np.array_equal(v, s) for s in (*taken, *out)):
                    out.append(v)
            return out

        if multistart == "valleys":
            # from the best grid point of every other valley along the last effect's place
            ends += [_minimise(residual, chi2, z0, lower, upper, max_iter)
                     for z0 in other_valleys([first])]
        elif multistart is True or (multistart == "auto" and not at_noise
                                    and measured.frequency_only):
            # effects that trade against each other (a soft clamp and a tip mass fitted
            # from frequencies: χ² rises 1e4-fold when the clamp alone moves 25 %) sit in a
            # narrow valley no coarse grid point hits: at each grid point of the last
            # effect, a few Gauss-Newton steps move the others first; the fit runs from the
            # best of those and from every start
            more = [s for s in starts if s is not first] if multistart is True else []
            profiled = _profile_starts(starting, start_chi2, first, grids, slots, lower, upper,
                                       nulls[-1] if nulls else None)
            more += profiled
            if not profiled:
                # one effect (no other to profile over): from the best grid point of every
                # other valley along its place.  Six frequencies give a crack a valley every
                # few tenths of the length, and the grid's coarse depths can rank the one
                # holding the optimum (χ² 8.6) below another (2 887): a confident wrong
                # answer when another effect fits better than the wrong valley
                more += other_valleys([first, *more])
            ends += [_minimise(residual, chi2, z0, lower, upper, max_iter) for z0 in more]
        # each end as its effects lie on the structure (a zone fitted past an end: the part
        # on it), so that ends that are one structure compare equal
        ends = [(problem.canonical(e[0]), *e[1:]) for e in ends]
        # the best converged end (ends within rounding of each other: the first one)
        converged = [e for e in ends if e[3]] or ends
        z, value, status, success = converged[lowest([e[1] for e in converged])]
        floor = max(1.0, value / max(n_res - z.size, 1))
        snapped = problem.snapped(z) if success else None
        if snapped is not None:
            # an edge that stopped short of an end: the fit again with it on the end, kept
            # when as good to the finish's own margin (one parameter fewer; the same valley)
            other = _minimise(residual, chi2, snapped, lower, upper, max_iter)
            if other[3] and other[1] <= value + FINISH_SETTLED * floor:
                z, value, status, success = problem.canonical(other[0]), *other[1:]
        for other in converged:
            # only converged ends are compared, with a margin far above their precision
            if (other[1] - value < ALIKE_CHI2 * floor
                    and np.max(np.abs(other[0] - z)) > SAME_END
                    and all(np.max(np.abs(other[0] - e)) > SAME_END for e in equivalent)
                    and not problem.reordered(z, other[0], SAME_END)):
                equivalent.append(other[0])
    effects = effects_of(z)
    fitted = base.with_effects(effects, check=False)
    fit_misfit = misfit(fitted, measured, noise, C)
    sides = _bound_sides(slots, z, lower, upper)
    saturated = _saturated(sides)
    sigma, unidentified, traded, told = _uncertainty(residual, z, slots, base, fit_misfit,
                                                     lower, upper, saturated)
    added = [i for i, s in enumerate(slots) if s.added]
    return Fit(name=name or (slots[added[0]].effect.name if added else "baseline"),
               effects=tuple(effects), sigma=tuple(sigma), added=added[0] if added else None,
               model=fitted, misfit=fit_misfit, n_params=z.size, status=status,
               success=success and np.isfinite(fit_misfit.chi2),
               evaluations=residual.count + (0 if stand_in is None else stand_in.count),
               equivalent=[tuple(effects_of(e)) for e in equivalent],
               unidentified=unidentified, traded=traded, told=tuple(told),
               bounds=tuple(saturated), held=_held(sides))


#: Δχ² (in units of the noise floor) under which two fits cannot be told apart (χ²₁, 95 %)
ALIKE_CHI2 = float(chdtri(1, 0.05))
#: multistart ends this close in every scaled variable (or so, their slots of one effect
#: exchanged) are one end, not an ``equivalent`` one
SAME_END = 0.05
#: values closer than this (relative) are ties, decided by their order, not by rounding: a
#: mirror-symmetric pair of places gives χ² equal to ~1e-13 on one machine and flipped on
#: another; the fits' own precision (:data:`FINISH_DECREMENT`) is far coarser than 1e-13 and
#: far finer than this
TIE = 1e-9


def lowest(values) -> int:
    """Index of the smallest value, the first of those within :data:`TIE` (relative) of it:
    the choice does not hinge on the last bits of the arithmetic.  NaN counts as +inf."""
    v = np.nan_to_num(np.asarray(values, dtype=float), nan=np.inf)
    if v.size == 0:
        raise ValueError("no values")
    m = float(np.min(v))
    if not np.isfinite(m):
        return 0
    return int(np.flatnonzero(v <= m + TIE * max(abs(m), 1.0))[0])


def ranked(values) -> list[int]:
    """Indices in increasing order of value, ties (:func:`lowest`) kept in their given
    order."""
    left = list(range(len(values)))
    out = []
    while left:
        i = left[lowest([values[j] for j in left])]
        out.append(i)
        left.remove(i)
    return out


#: profile starts: at most this many grid points, Gauss-Newton steps at each, best kept
PROFILE_GRID_LIMIT = 200
PROFILE_STEPS = 3
PROFILE_STARTS = 3


def _profile_starts(residual, chi2, z0, grids, slots, lower, upper, nulls=None) -> list:
    """Starting points for a fit of several effects: for each point of the last effect's
    grid (of its vanished points the first, :func:`_null_points`),
    :data:`PROFILE_STEPS` Gauss-Newton steps on the other effects' variables (from
    ``z0``); the :data:`PROFILE_STARTS` best."""
    sizes = [len(slot.variables) for slot in slots]
    inner = np.arange(sum(sizes[:-1]))
    if inner.size == 0 or inner.size > 4:
        return []
    last = grids[-1]
    points = np.array(np.meshgrid(*last, indexing="ij")).reshape(len(last), -1).T
    if len(points) > PROFILE_GRID_LIMIT:
        return []
    null = _null_points(points, nulls)
    found = []
    for j, point in enumerate(points):
        if null[j] and null[:j].any():
            continue
        z = np.concatenate([z0[inner], point])
        r = residual(z)
        for _ in range(PROFILE_STEPS):
            analytic = getattr(residual, "jacobian", None)
            J = None if analytic is None else analytic(z, r, lower, upper, columns=inner)
            if J is not None:
                J = J[:, inner]
            else:
                J = np.empty((r.size, inner.size))
                for k in inner:
                    dz = z.copy()
                    h = 1e-6 * max(1.0, abs(z[k]))
                    dz[k] += h
                    J[:, k] = (residual(dz) - r) / h
            step = np.linalg.lstsq(J, -r, rcond=None)[0]
            trial = z.copy()
            trial[inner] = np.clip(z[inner] + step, lower[inner], upper[inner])
            r_trial = residual(trial)
            if r_trial @ r_trial >= r @ r:
                break
            z, r = trial, r_trial
        found.append((float(r @ r), z))
    # distinct starts (ends that are the same point to rounding: the first)
    out, seen = [], []
    for i in ranked([value for value, _ in found]):
        value = found[i][0]
        if any(abs(value - v) <= TIE * max(abs(v), 1.0) for v in seen):
            continue
        seen.append(value)
        out.append(found[i][1])
    return out[:PROFILE_STARTS]


def _minimise(residual, chi2, z_start, lower, upper, max_iter):
    """Minimise χ² from ``z_start`` (module docstring).  With :data:`FIT_SOLVER`
    ``"newton"`` (the default) :func:`_finish` runs from the start (:data:`NEWTON_STEPS`
    steps) and the status is its outcome ("converged", "settled", "not_converged"); with
    ``"ipopt"`` IPOPT finds the valley first (:func:`gfe_opt.fit_ipopt.ipopt_valley`; its
    "acceptable" stop is off: it stopped on finite-difference noise at points that differed
    with the BLAS kernel), the status is its last run's, and the finish converges from
    there.  Returns (z, χ², status, whether the finish met its rule).

    A beam solved through condensed super-elements (``residual.stand_in``): the fit first
    converges on the same beam at :data:`~gfe_opt.modal.CONDENSE_ABOVE` elements (direct
    solves, the analytic Jacobian: the screen's stand-in) and the finish on its own mesh
    starts there; its optimum is the same to the discretisation's difference, so the finish
    takes two or three differenced Jacobians where from the grid point it took five
    (the stand-in only moves the start: the end meets the finish's rule on the fit's own
    mesh as before)."""
    stand_in = getattr(residual, "stand_in", None)
    if stand_in is not None:
        z, _, decrement = _finish(stand_in, z_start, None, lower, upper,
                                  steps=NEWTON_STEPS)
        if np.isfinite(decrement):
            z_start = z
    if FIT_SOLVER == "newton":
        z, value, decrement = _finish(residual, z_start, chi2(z_start), lower, upper,
                                      steps=NEWTON_STEPS)
        outcome = _outcome(decrement)
        SOLVER_TALLY[outcome] += 1
        return z, value, outcome, outcome != "not_converged"
    from .fit_ipopt import ipopt_valley

    z, value, status = ipopt_valley(residual, chi2, z_start, lower, upper, max_iter)
    SOLVER_TALLY[status] += 1
    z, value, decrement = _finish(residual, z, value, lower, upper)
    outcome = _outcome(decrement)
    SOLVER_TALLY[outcome] += 1
    return z, value, status, outcome != "not_converged"


def _outcome(decrement: float) -> str:
    """The finish's outcome from its last decrement in noise floors."""
    return ("converged" if decrement < FINISH_DECREMENT else
            "settled" if decrement < FINISH_SETTLED else "not_converged")


#: the finish stops when a full Newton (and Gauss–Newton) step would lower χ² by less than
#: this many noise-floor units: the parameters are then within √FINISH_DECREMENT ≈ 3e-5 of their
#: standard deviation from the optimum, far below any printed digit or any decision margin
FINISH_DECREMENT = 1e-9
#: a finish that cannot meet :data:`FINISH_DECREMENT` (no step lowers χ² any more, or its
#: steps run out) has still *settled* when its decrement is below this many noise floors: χ²
#: within 0.01 of its optimum, the parameters within 0.1 σ; no significance test can turn on
#: that (a spring of no stiffness at a pinned end, whose place then does not matter, ended
#: at 1e-5 from the end on one BLAS kernel and at the end on another).  Worse is a failed fit.
FINISH_SETTLED = 1e-2
FINISH_STEPS = 60
#: the finish's steps when it runs from the start (:data:`FIT_SOLVER` "newton")
NEWTON_STEPS = 100
#: directions of the scaled Jacobian with singular values below this fraction of the largest
#: are not determined by the data: their σ is 10⁴ times the best-determined one's (a zone at
#: a clamp whose centre and length trade exactly shows 1e-6)
FINISH_RANK = 1e-4
#: a finish stops after this many steps in a row pinned against a seam of χ² (:func:`_finish`)
PINNED_STEPS = 2
#: finish outcomes (and IPOPT statuses where it runs) of this process's fits (tests count
#: them)
SOLVER_TALLY: Counter = Counter()


def _jacobian(residual, z, r, lower, upper, step: float = 1e-5):
    """The residual's own Jacobian (:class:`Objective`) or :func:`_difference_jacobian`."""
    analytic = getattr(residual, "jacobian", None)
    J = None if analytic is None else analytic(z, r, lower, upper)
    return _difference_jacobian(residual, z, r, lower, upper, step) if J is None else J


def _difference_jacobian(residual, z, r, lower, upper, step: float = 1e-5):
    """Second-order difference Jacobian (central; at a bound the one-sided three-point
    formula, stepping inwards): errors of ~1e-10 where forward differences err by 1e-6 times
    a residual's curvature-to-slope ratio, enough for the finish to certify its rule on
    directions the data determine weakly (a crack's position when its depth is at a
    bound)."""
    J = np.empty((r.size, z.size))
    for k in range(z.size):
        h = step * max(1.0, abs(z[k]))
        up, down = z.copy(), z.copy()
        if z[k] + h <= upper[k] and z[k] - h >= lower[k]:
            up[k] += h
            down[k] -= h
            J[:, k] = (residual(up) - residual(down)) / (2 * h)
            continue
        h = h if z[k] + 2 * h <= upper[k] else -h
        up[k] += h
        down[k] += 2 * h
        J[:, k] = (-3 * r + 4 * residual(up) - residual(down)) / (2 * h)
    return J


def _finish(residual, z, value, lower, upper, steps: int = FINISH_STEPS):
    """Converge a fit to its optimum by a stopping rule that does not depend on how the
    parameters are scaled, so that two machines whose arithmetic differs in the last bits
    stop at the same point to far below the printed digits.

    Steps are damped Newton steps on χ² with the Hessian JᵀJ + S: J the second-order
    difference Jacobian (:func:`_jacobian`), S the second-order term Σ rᵢ∇²rᵢ built up by
    the structured secant update of Dennis, Gay & Welsch (NL2SOL; it matters when the
    residuals are large: a fit that does not reach the noise zig-zagged for 60 Gauss–Newton
    steps).  The fit has converged when
    the Newton decrement gᵀH⁻¹g (g = Jᵀr, the decrease of χ² a full step predicts; also the
    Gauss–Newton one) falls below :data:`FINISH_DECREMENT` times the noise floor
    max(1, χ²/(n − p)): the distance to the optimum is then √FINISH_DECREMENT standard
    deviations.  Variables held at a bound by their gradient are left out, and so are
    directions the data do not determine (singular values of J, its columns scaled to unit
    length, below :data:`FINISH_RANK` of the largest: a zone at a clamp whose centre and
    length trade exactly); their σ says so.

    A fit pinned against a seam of χ² (a measured mode that pairs no model mode past it:
    χ² jumps there) stops: where, on :data:`PINNED_STEPS` steps in a row, every trial the
    step rejected paired the modes otherwise than the point it left and the step it took
    then gained less than :data:`FINISH_SETTLED` noise floors, the steps only creep on
    towards the seam, a tenth of the gain every few steps while the Newton decrement,
    which looks past the seam, stays high: an end that is ``not_converged`` either way (on
    the three-storey frame's diagnosis such creeps took 900 of its 1 471 Jacobians).  One
    such step is not enough: after many rejections one small step, then steps that gain
    again, is how three of the semi-rigid portal's fits leave a seam and converge.

    Where no step lowers χ² while the decrement still predicts a gain above
    :data:`FINISH_SETTLED` floors, the variables are probed for a kink of χ² (a zone's
    edge on a node: :func:`_kinks`): one found is held where χ² rises both ways, the χ²
    it may still hide counted in the decrement, and the others go on; a probe that
    lowers χ² is a step.  Returns
    (z, χ², the last decrement in noise floors: 0 when nothing was left to fit, inf when the
    fit could not be evaluated)."""
    n = z.size
    r = residual(z)
    value = float(r @ r)
    if n == 0 or not np.isfinite(value) or value >= FAILED_RESIDUAL**2:
        return z, value, 0.0 if n == 0 else np.inf
    pairing, pinned = _pairing(residual), 0
    J = _jacobian(residual, z, r, lower, upper)
    d = np.linalg.norm(J, axis=0)
    d = np.where(d > 0, d, 1.0)   # fixed scaling: u = d z
    S = np.zeros((n, n))          # Σ rᵢ∇²rᵢ in the scaled variables (secant estimate)
    lam = 0.0
    span = np.maximum(upper - lower, 1e-300)
    # variables held on a kink of χ² (:func:`_kinks`), the χ² the kinks may still hide and
    # the steps taken to a probe
    on_kink, kink_gain, probe_steps = np.zeros(n, dtype=bool), 0.0, 0
    for _ in range(steps):
        Ju = J / d
        g = Ju.T @ r
        at_lower, at_upper = _on_bounds(z, lower, upper, span)
        held = (at_lower & (g > 0)) | (at_upper & (g < 0)) | on_kink
        floor = max(1.0, value / max(r.size - n, 1))
        # a variable that cannot change χ² by the stopping rule's amount over its whole
        # range (linearised: 2|r||J_k| span + (|J_k| span)²) takes no part: its column,
        # scaled to unit length, would carry only its rounding (a spring on a held DOF)
        reach = np.linalg.norm(J, axis=0) * span
        free = ~held & (2 * np.linalg.norm(r) * reach + reach**2 > FINISH_DECREMENT * floor)
        if not free.any():
            return z, value, kink_gain / floor
        decrement, sv, V, gk, H, lowest_eig = _decrement(Ju, g, r, S, free)
        if decrement < FINISH_DECREMENT * floor:   # (what kinks held may hide, reported)
            return z, value, max(decrement, kink_gain) / floor
        decrement = max(decrement, kink_gain)
        shift = max(0.0, -lowest_eig) + 1e-12 * sv[0] ** 2   # H + shift: positive definite
        accepted = False
        seams = others = 0   # rejected trials across a seam of the pairing, and the others
        while lam <= 1e10:
            try:
                w = -np.linalg.solve(H + (shift + lam * sv[0] ** 2) * np.eye(H.shape[0]), gk)
            except np.linalg.LinAlgError:   # H + shift singular to rounding: damp more
                lam = 1e-6 if lam == 0.0 else lam * 10.0
                continue
            trial = z.copy()
            trial[free] = np.clip(z[free] + (V @ w) / d[free], lower[free], upper[free])
            r_trial = residual(trial)
            trial_pairing = _pairing(residual)
            trial_value = float(r_trial @ r_trial)
            if trial_value < value:
                accepted = True
                break
            if pairing is not None and trial_pairing is not None and trial_pairing != pairing:
                seams += 1
            else:
                others += 1
            if -(2 * gk @ w + w @ H @ w) < FINISH_DECREMENT * floor:
                # it failed, and predicted less than the rule's amount: more damping only
                # predicts less (the tail of a fit whose χ² has stopped falling to rounding)
                break
            lam = 1e-6 if lam == 0.0 else lam * 10.0
        if not accepted and np.any(S):
            # no step lowers χ² with the secant term built up along the way (from a start far
            # off it may not fit here): Gauss–Newton again from this point
            S, lam = np.zeros((n, n)), 0.0
            continue
        if not accepted and decrement >= FINISH_SETTLED * floor:
            # the steps fail where the finish predicts a gain worth having: a kink of χ²
            # the slopes averaged across (:func:`_kinks`)?  Its variables are then held
            # where χ² rises both ways, and the others converge without them
            kinked, gain, lower_point = _kinks(residual, z, value, free, lower, upper, span)
            if kinked.any() and kink_gain + gain < FINISH_SETTLED * floor:
                on_kink |= kinked
                kink_gain += gain
                S, lam = np.zeros((n, n)), 0.0
                continue
            if lower_point is not None and probe_steps < len(KINK_STEPS):
                # a probe lowered χ² (towards a kink the slopes do not show yet): a step.
                # Each brings a kink within the next smaller probe's reach, so the ladder's
                # length of them reaches any; more would only creep along a valley
                probe_steps += 1
                z, r = lower_point
                value = float(r @ r)
                J = _jacobian(residual, z, r, lower, upper)
                pairing, S, lam = _pairing(residual), np.zeros((n, n)), 0.0
                continue
        if not accepted:  # no step lowers χ²: the optimum as far as rounding can tell
            return z, value, decrement / floor
        pinned = pinned + 1 if (seams and not others
                                and value - trial_value < FINISH_SETTLED * floor) else 0
        if pinned >= PINNED_STEPS:
            # pinned against a seam (docstring): creeping on would not change the outcome
            return trial, trial_value, decrement / floor
        pairing = trial_pairing
        lam = 0.0 if lam <= 1e-6 else lam / 10.0
        J_new = _jacobian(residual, trial, r_trial, lower, upper)
        on_bound = bool(np.any(np.logical_or(*_on_bounds(trial, lower, upper, span))))
        S = _secant(S, (trial - z) * d, J / d, J_new / d, r_trial, g, on_bound)
        z, r, value, J = trial, r_trial, trial_value, J_new
    return z, value, decrement / floor


def _decrement(Ju, g, r, S, free):
    """The Newton decrement of the finish (:func:`_finish`) on the variables ``free``
    (columns of the scaled Jacobian ``Ju``, gradient ``g`` = Juᵀ r, secant term ``S``),
    directions below :data:`FINISH_RANK` left out: (decrement, the singular values, the
    directions kept V, the reduced gradient, the reduced Hessian, its lowest eigenvalue);
    the decrement 0 when nothing is free."""
    if not free.any():
        return 0.0, None, None, None, None, 0.0
    Jf = Ju[:, free]
    U, sv, Vt = np.linalg.svd(Jf, full_matrices=False)
    keep = sv > FINISH_RANK * sv[0]
    V = Vt[keep].T
    ur = U[:, keep].T @ r
    gk = V.T @ g[free]
    H = V.T @ (Jf.T @ Jf + S[np.ix_(free, free)]) @ V
    H = 0.5 * (H + H.T)
    lowest_eig = float(np.linalg.eigvalsh(H)[0])
    decrement = float(ur @ ur)
    if lowest_eig > 0:
        try:
            decrement = max(decrement, float(gk @ np.linalg.solve(H, gk)))
        except np.linalg.LinAlgError:
            # positive to eigvalsh, singular to the LU (a frame's zone from frequencies
            # alone, the campaign's zone-3307): the Gauss-Newton decrement stands
            pass
    return decrement, sv, V, gk, H, lowest_eig


#: a kink is probed by steps of these fractions of a variable's range, the smallest first:
#: from where χ² still moves far above its rounding (a slope of 1 moves it by 1e-7, its
#: rounding 1e-13 relative) up to the Jacobian's own difference step (1e-5), the scale on
#: which a kink corrupts the slopes the finish steps along
KINK_STEPS = (1e-7, 1e-6, 1e-5)
#: ... and is one where χ²'s slope turns across it by more than this many times it turns
#: over a step on one side: a smooth χ² turns it alike on every step (ratio 1 for a
#: quadratic), a kink by its jump, which the step does not shrink (ratio ~ jump / (χ'' h):
#: 1e3 and more at these steps); 100 lies between, not tuned
KINK_RATIO = 100.0


def _kinks(residual, z, value, free, lower, upper, span):
    """The ``free`` variables along which χ² has a kink and its minimum within a probe's
    step of ``z`` (χ² at z ± h, z ± 2h: slopes nondecreasing, none negative ahead nor
    positive behind, turning between the middle two by more than :data:`KINK_RATIO` times
    on a step beside them; h each of :data:`KINK_STEPS` of the range in turn), the χ²
    that minimum may lie below
    χ²(z), summed over them (at most h max(|slope behind|, |slope ahead|) each, χ² being
    convex along the variable there, as its slopes say), and the lowest probe, ``(z, r)``,
    where one lies below χ²(z) (None otherwise; the variables are then not read).

    A zone whose edge lies on a node of the mesh (a 0.2 m zone from 0.6 m on a bar of
    0.05 m elements): an element's stiffness follows the part of it the zone covers, so
    χ² has a kink where the edge crosses a node, and the fit's optimum sits on it when
    the truth's edge does.  The Jacobian's differences straddle the kink and average its
    two slopes; no step along them lowers χ², and the decrement they predict stays above
    the finish's rule.  The fit that had found the zone to 0.05 % of the bar (6e-7 m
    short of the node) ended ``not_converged`` at 0.04 noise floors, and the diagnosis
    said that nothing explained the test (issue 21's second-worst answer)."""
    kinked, gain = np.zeros(z.size, dtype=bool), 0.0
    best = None
    for k in np.flatnonzero(free):
        for fraction in KINK_STEPS:
            h = fraction * span[k]
            if z[k] - 2 * h < lower[k] or z[k] + 2 * h > upper[k]:
                break
            values = []
            for step in (-2 * h, -h, h, 2 * h):
                trial = z.copy()
                trial[k] += step
                r_trial = residual(trial)
                values.append(float(r_trial @ r_trial))
                if values[-1] < value and (best is None or values[-1] < best[0]):
                    best = (values[-1], trial, r_trial)
            if not np.all(np.isfinite(values)):
                break
            back2, back, ahead, ahead2 = values
            slopes = np.array([back - back2, value - back, ahead - value, ahead2 - ahead]) / h
            turn = np.diff(slopes)   # a kink turns the slope between the middle two
            if slopes[1] <= 0.0 <= slopes[2] and np.all(turn >= 0.0) and \
                    turn[1] > KINK_RATIO * min(turn[0], turn[2]):
                kinked[k] = True
                gain += h * max(-slopes[1], slopes[2])
                break
    if best is not None:
        residual(best[1])   # (the residual's pairing is the point's)
        return kinked, gain, (best[1], best[2])
    return kinked, gain, None


def _on_bounds(z, lower, upper, span):
    """Which variables of ``z`` sit on their lower and on their upper bound (within 1e-12
    of their range ``span``): two boolean arrays."""
    return (z - lower) <= 1e-12 * span, (upper - z) <= 1e-12 * span


def _pairing(residual):
    """The pairing of the residual's last evaluation (:meth:`Objective.pairing`; None for a
    residual that does not tell, or a failed evaluation)."""
    tell = getattr(residual, "pairing", None)
    return None if tell is None else tell()


def _secant(S, s, J_old, J_new, r_new, g_old, on_bound: bool = False):
    """Dennis–Gay–Welsch update of the second-order term S ≈ Σ rᵢ∇²rᵢ from a step s (scaled
    variables): S s should match y♯ = (J_new − J_old)ᵀ r_new; sized down first as in NL2SOL.

    Where the gradient did not grow along the step (yᵀs ≤ 0: χ² curves down or not at all
    along it) no such update exists.  S is then kept, except where the step left a variable
    on its bound (``on_bound``): S is then dropped (Gauss–Newton again from here, the secant
    term built up anew), as the finish drops it when no step lowers χ².  Kept there, an S
    learnt on the step that took a point spring's stiffness to its lower bound (2.1e-3,
    against JᵀJ of 4e-11 along the place) held the spring's place on the three-storey frame
    at Newton steps of 3e-4 of the member for the finish's 100 steps, each gaining 1e-7 of a
    noise floor more than the last.  Dropped at every such step (bound or not), it ended 9
    of the beam campaign's 1 253 first-table fits more than 0.01 floors off (7 higher, by
    up to 4.7·10⁴ floors: a kept S leads many beam fits to their lower end)."""
    y_sharp = (J_new - J_old).T @ r_new
    y = J_new.T @ r_new - g_old
    ys = float(y @ s)
    if ys <= 1e-300 * max(float(s @ s), 1e-300):
        return np.zeros_like(S) if on_bound else S
    sSs = float(s @ S @ s)
    if sSs != 0.0:
        S = S * min(1.0, abs(float(s @ y_sharp)) / abs(sSs))
    e = y_sharp - S @ s
    return S + (np.outer(e, y) + np.outer(y, e)) / ys - float(e @ s) * np.outer(y, y) / ys**2


#: a parameter is not estimable from the data when its σ exceeds its own size, or when
#: its correlation with another fitted parameter exceeds this (they trade: only a
#: combination is determined)
IDENTIFIABLE_CORRELATION = 0.99
#: ... and, checked on the fit itself, their χ² two linearised σ along the trade rises by
#: less than one unit of the noise floor (a quadratic valley: four): the printed σ then
#: understates the trade more than twice over.  Where the valley is as steep as linearised,
#: the σ already covers the trade and a correlation alone does not undetermine anything (a
#: crack near a clamp: position and depth correlated +0.999, σ 0.3 % of the length)
TRADE_STEP_SIGMAS = 2.0


def bound_side(z: float, lower: float, upper: float) -> str | None:
    """``"upper"`` or ``"lower"`` when an order-one variable ``z`` ends on that bound of
    [lower, upper] (within 10⁻⁶ of the range: IPOPT stops a hair inside), else None."""
    span = 1e-6 * (upper - lower)
    if z >= upper - span:
        return "upper"
    if z <= lower + span:
        return "lower"
    return None


def _bound_sides(slots, z, lower, upper) -> list:
    """Per slot, each of its variables with the bound of its range it ends on
    (:func:`bound_side`: ``"upper"``, ``"lower"`` or None)."""
    out, i = [], 0
    for slot in slots:
        out.append([(v, bound_side(z[i + k], lower[i + k], upper[i + k]))
                    for k, v in enumerate(slot.variables)])
        i += len(slot.variables)
    return out


def _held(sides) -> tuple:
    """Per slot (of :func:`_bound_sides`), the keys of its variables that end on a bound of
    their range, on any scale."""
    return tuple(tuple(v.key for v, side in slot if side is not None) for slot in sides)


def _saturated(sides) -> list:
    """Per slot (of :func:`_bound_sides`), its log-scaled variables (stiffnesses over
    decades) that end on a bound of their range: ``{key: "at least"}`` on the upper one,
    ``"at most"`` on the lower.  The data then tell only one side (a roller read as a
    spring: rigid as far as the modes tell); a σ from the curvature there means nothing."""
    return [{v.key: "at least" if side == "upper" else "at most" for v, side in slot
             if side is not None and v.log and v.index is None} for slot in sides]


def _vanished(slot, marks) -> str | None:
    """The key of ``slot``'s variable held on the bound of its range where its effect
    vanishes (``marks``: the slot's :func:`_saturated` entry; a point spring's stiffness
    at its lower end, whose :attr:`~gfe_opt.effects.base.Parameter.null` is 0; a shear
    rigidity at its upper end, null ∞), or None."""
    for v in slot.variables:
        side = marks.get(v.key)
        if side is None or v.index is not None or v.key in slot.effect.present_at_null:
            continue
        null = slot.effect.parameter(v.key).null
        if (side == "at most" and isinstance(null, float) and null == 0.0) or (
                side == "at least" and null == "inf"):
            return v.key
    return None


def _uncertainty(residual, z, slots, base, fit_misfit, lower, upper, saturated=None):
    """Standard deviations of every slot's physical parameters (Gauss–Newton), and the
    parameters the data do not estimate (sentences: σ above the value, or a correlation
    above :data:`IDENTIFIABLE_CORRELATION` with another parameter).  ``saturated``
    (:func:`_saturated`) variables are held: σ infinite, the others' σ with them fixed."""
    n = z.size
    out = [{} for _ in slots]
    if n == 0 or not np.isfinite(fit_misfit.chi2):
        return out, [], [], [{} for _ in slots]
    saturated = saturated or [{}] * len(slots)
    held = np.array([v.key in marks for marks, slot in zip(saturated, slots)
                     for v in slot.variables], dtype=bool)
    r0 = residual(z)
    T, tied_names, tied_owner = _ties(slots, base, z)
    if T is None:
        # second-order differences: forward ones (step 1e-6) gave σ that moved by 1e-3
        # between two optima 1e-4 σ apart (a section loss on the demo), a printed digit at
        # 99.95 σ
        J = _jacobian(residual, z, r0, lower, upper, step=1e-4)
    else:
        # an effect with a tie (a zone with an edge on an end) is differenced along the
        # directions it can move in: across the tie the residual has a kink
        lo, hi = _tied_bounds(T, z, lower, upper)
        J = _difference_jacobian(lambda y: residual(z + T @ y), np.zeros(T.shape[1]), r0,
                                 lo, hi, step=1e-4)
    m = J.shape[1]
    if held.any():   # a held variable's direction(s) carry nothing
        J = J.copy()
        J[:, (held if T is None else (np.abs(T[held]) > 0).any(axis=0))] = 0.0
    A = J.T @ J
    ridge = 1e-12 * max(float(np.max(np.diag(A))), 1e-300)
    s2 = max(1.0, fit_misfit.chi2 / max(fit_misfit.n_residuals - n, 1))
    try:
        cov = s2 * np.linalg.inv(A + ridge * np.eye(m))
    except np.linalg.LinAlgError:
        cov = np.full((m, m), np.inf)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    sd = np.where(np.diag(A) > 1e-9 * max(float(np.max(np.diag(A))), 1e-300), sd, np.inf)
    if T is not None:   # σ of the variables themselves; a held one is not determined
        cov_z = T @ np.where(np.isfinite(cov), cov, 0.0) @ T.T
        sd_z = np.sqrt(np.maximum(np.diag(cov_z), 0.0))
        moves = np.abs(T) > 0
        sd_z = np.where(moves.any(axis=1) & ~(moves & ~np.isfinite(sd)).any(axis=1), sd_z,
                        np.inf)
    else:
        sd_z = sd
    names, unidentified = [], []
    wide = {}   # variable -> (slot, key, its σ above its value)
    sizes = {}  # variable -> (its physical value, d value / d variable)
    i = 0
    for j, slot in enumerate(slots):
        gone = _vanished(slot, saturated[j])
        for v in slot.variables:
            phys = v.physical(base, z[i])
            derivative = phys * np.log(10.0) if v.log else v.scale(base)
            sizes[i] = (phys, derivative)
            value = abs(derivative) * sd_z[i]
            if gone is not None and v.key != gone and not held[i]:
                # the effect is at the end of its range where it does nothing: where it
                # sits (or how long it is) the data cannot tell, whatever the curvature
                # of χ² along it (a point spring's position read ± 1e14 m)
                value = np.inf
                if slot.added:
                    unidentified.append(
                        f"{slot.effect.name}.{v.key}: not determined: "
                        f"{slot.effect.name}.{gone} is at the end of its range where the "
                        f"{slot.effect.name} vanishes")
            if v.index is None:
                out[j][v.key] = float(value)
            else:
                out[j].setdefault(v.key, []).append(float(value))
            label = (f"{slot.effect.name}.{v.key}" if v.index is None
                     else f"{slot.effect.name}.{v.key}[{v.index}]")
            names.append(label)
            rule = slot.effect.parameter(v.key).rule if v.index is None else "ratios"
            if slot.added and rule in ("positive", "fraction") and not value <= abs(phys) \
                    and not held[i]:
                wide[i] = (j, v.key, f"{label}: σ {value:.3g} exceeds its value {phys:.3g}")
            i += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    owner = [k for k, slot in enumerate(slots) for _ in slot.variables]
    if T is not None:   # correlations of the directions the effects move in
        names, owner = tied_names, tied_owner
    added = {i for i, k in enumerate(owner) if slots[k].added} or set(range(m))

    def trades(a, b) -> bool:
        """χ² along the (a, b) valley, the other parameters following it (linearised),
        rises by less than one floor unit at TRADE_STEP_SIGMAS σ."""
        sub = cov[np.ix_([a, b], [a, b])]
        w, V = np.linalg.eigh(sub)
        if not np.all(np.isfinite(cov[:, [a, b]])) or w[-1] <= 0.0:
            return True
        try:
            d = cov[:, [a, b]] @ np.linalg.solve(sub, V[:, -1] * np.sqrt(w[-1]))
        except np.linalg.LinAlgError:   # a block singular to rounding: its eigenvector
            d = cov[:, [a, b]] @ (V[:, -1] / np.sqrt(w[-1]))
        chi0, rises = float(r0 @ r0), []
        for sign in (1.0, -1.0):
            step = sign * TRADE_STEP_SIGMAS * (d if T is None else T @ d)
            zz = z + step
            if np.all(zz >= lower) and np.all(zz <= upper):
                rr = residual(zz)
                rises.append(float(rr @ rr) - chi0)
        return not rises or min(rises) < s2

    in_trade = set()   # (slot, key) of the parameters in a told trade

    def told(a, b) -> bool:
        """Two parameters of one effect whose trade the effect declares a finding
        (:meth:`~gfe_opt.effects.base.EffectType.told_trades`: a short zone's length and
        ratios, of which the data fix the combination)."""
        if owner[a] != owner[b]:
            return False
        keys = {TIE_KEYS.get(k, k) for k in (names[a].split(".", 1)[1],
                                             names[b].split(".", 1)[1])}
        if keys not in slots[owner[a]].effect.told_trades(base):
            return False
        in_trade.update((owner[a], k) for k in keys)
        return True

    shared = {}   # slot -> {key: told entry} of the sums two instances' trades leave told

    def summed(a, b) -> bool:
        """On a frame, the same size of two instances of one kind (two joints' springs)
        trading: the data fix their sum, not how it splits between them (frequencies alone
        on a symmetric portal, whose two beam ends move every frequency alike to first
        order).  Told, with the sum's σ, when that σ does not exceed the sum (as any size's
        must not); beams keep the stricter rule their campaign judged."""
        if T is not None or getattr(base, "kind", None) != "frame" or owner[a] == owner[b] \
                or held[a] or held[b]:
            return False
        ea, eb = slots[owner[a]].effect, slots[owner[b]].effect
        key = names[a].split(".", 1)[1]
        if ea.name != eb.name or key != names[b].split(".", 1)[1] or "[" in key \
                or ea.parameter(key).rule != "positive":   # (a profile's ratios[i]: not a size)
            return False
        g = np.zeros(m)
        g[a], g[b] = sizes[a][1], sizes[b][1]
        total = sizes[a][0] + sizes[b][0]
        sigma = float(np.sqrt(max(float(g @ np.where(np.isfinite(cov), cov, 0.0) @ g), 0.0)))
        if not np.all(np.isfinite(cov[np.ix_([a, b], [a, b])])) or not sigma <= abs(total):
            return False
        parameter = ea.parameter(key)
        entry = {"label": f"the sum of the two {ea.name}s' {key}",
                 "unit": parameter.unit, "value": float(total), "sigma": sigma}
        for k in (owner[a], owner[b]):
            shared.setdefault(k, {})[f"{key} sum"] = entry
        in_trade.update(((owner[a], key), (owner[b], key)))
        return True

    traded = []
    for a in range(m):
        for b in range(a + 1, m):
            if (a in added or b in added) and np.isfinite(corr[a, b]) \
                    and abs(corr[a, b]) > IDENTIFIABLE_CORRELATION and trades(a, b):
                (traded if told(a, b) or summed(a, b) else unidentified).append(
                    f"{names[a]} and {names[b]} trade against each other (correlation "
                    f"{corr[a, b]:+.3f})")
    # a σ above its value that a told trade explains is that trade's (a short zone's
    # length spans it), any other undetermines the effect
    for j, key, sentence in wide.values():
        (traded if (j, key) in in_trade else unidentified).append(sentence)
    finite = np.where(np.isfinite(cov), cov, 0.0) if T is None else cov_z
    told_values = _told(slots, base, z, finite, held)
    for k, entries in shared.items():
        told_values[k].update(entries)
    return out, unidentified, traded, told_values


def _told(slots, base, z, cov_z, held) -> list[dict]:
    """Per slot, the combinations of its parameters its effect declares the data fix
    (:meth:`~gfe_opt.effects.base.EffectType.told_values`) with their σ: √(gᵀ Σ g), g their
    gradient in the order-one variables (central differences of the physical values), Σ
    the variables' covariance.  A held variable's direction carries nothing."""
    out, i = [], 0
    for slot in slots:
        k = len(slot.variables)
        told_values = getattr(slot.effect, "told_values", None)
        zs = z[i:i + k]

        def values(zz, slot=slot, told_values=told_values):
            params = {**slot.fixed, **{v.key: v.physical(base, x)
                                       for v, x in zip(slot.variables, zz)}}
            return told_values(base, params)

        told = values(zs) if told_values is not None and k and all(
            v.index is None for v in slot.variables) else {}
        entry = {}
        for key, (label, unit, value) in told.items():
            g = np.zeros(k)
            for a in range(k):
                if held[i + a]:
                    continue
                h = 1e-6 * max(1.0, abs(zs[a]))
                up, down = zs.copy(), zs.copy()
                up[a] += h
                down[a] -= h
                g[a] = (values(up)[key][2] - values(down)[key][2]) / (2 * h)
            block = cov_z[i:i + k, i:i + k]
            entry[key] = {"label": label, "unit": unit, "value": float(value),
                          "sigma": float(np.sqrt(max(float(g @ block @ g), 0.0)))}
        out.append(entry)
        i += k
    return out


#: the parameter a tied direction moves (:meth:`EffectType.tie`: a zone's inner edge, its
#: length)
TIE_KEYS = {"inner edge": "length"}


def _ties(slots, base, z):
    """The directions the variables move in (:meth:`EffectType.tie`) as one matrix T
    (variables × directions), their labels and owning slots; (None, None, None) when every
    variable moves freely."""
    blocks, labels, owner, i, any_tie = [], [], [], 0, False
    for j, slot in enumerate(slots):
        k = len(slot.variables)
        tie = slot.effect.tie(base, slot.variables, z[i:i + k]) if k else None
        if tie is None:
            blocks.append(np.eye(k).reshape(k, k))
            labels += [f"{slot.effect.name}.{v.label}" for v in slot.variables]
        else:
            any_tie = True
            blocks.append(tie[0])
            labels += [f"{slot.effect.name}.{name}" for name in tie[1]]
        owner += [j] * blocks[-1].shape[1]
        i += k
    if not any_tie:
        return None, None, None
    return block_diag(*blocks), labels, owner


def _tied_bounds(T, z, lower, upper):
    """How far each direction of T may move from z within the variables' bounds."""
    lo, hi = np.full(T.shape[1], -np.inf), np.full(T.shape[1], np.inf)
    for j in range(T.shape[1]):
        for i in np.flatnonzero(T[:, j]):
            a, b = (lower[i] - z[i]) / T[i, j], (upper[i] - z[i]) / T[i, j]
            lo[j], hi[j] = max(lo[j], min(a, b)), min(hi[j], max(a, b))
    return lo, hi


def _null_of(effect: EffectType, v, base, exact: bool = False) -> float | None:
    """The variable's value (in the fit's variables, clipped to the bounds) where the effect
    vanishes, or comes closest to it: a bound for an infinite stiffness or a zero size on a
    log scale (a crack of a/d 0.01); None for a variable that does not size the effect (a
    place, a length).  ``exact``: NaN where the effect only comes close there (a crack of
    a/d 0.01 still differs from place to place, and that difference is the grid's
    information)."""
    null = effect.parameter(v.key).null
    if null is None:
        return None
    if null == "inf":
        return np.nan if exact else float(v.upper)
    value = base.E if null == "E" else float(null)
    if v.log and value <= 0:
        return np.nan if exact else float(v.lower)
    z = v.order_one(base, value)
    if exact and not v.lower <= z <= v.upper:
        return np.nan
    return float(np.clip(z, v.lower, v.upper))


def _with_null(effect: EffectType, v, base) -> tuple:
    """The variable's grid and the point where the effect vanishes (:func:`_null_of`):
    a fit can always fall back to about nothing, never end worse than without the effect."""
    z = _null_of(effect, v, base)
    if z is None:
        return v.grid
    return v.grid if any(abs(z - g) < 1e-12 for g in v.grid) else (z, *v.grid)


def _valleys(points: np.ndarray, values, null, k: int) -> list[int]:
    """The grid points that are each the best of a valley of the grid's profile along
    variable ``k`` (a place): at each value of it the lowest point where the effect is
    present (``null``: vanished points, which have no place), and of those the ones lower
    than the place before and no higher than the one after (a plateau's first; values
    within :data:`TIE` count as equal, so rounding does not move a valley)."""
    places = np.unique(points[:, k])
    profile, best = [], []
    for x in places:
        at = [j for j in np.flatnonzero(points[:, k] == x)
              if not null[j] and np.isfinite(values[j])]
        best.append(at[lowest([values[j] for j in at])] if at else None)
        profile.append(values[best[-1]] if at else np.inf)

    def below(a, b):   # a lower than b beyond a tie
        return np.isfinite(a) and a < b - TIE * max(abs(a), 1.0)

    return [best[m] for m in range(len(places)) if best[m] is not None
            and (m == 0 or below(profile[m], profile[m - 1]))
            and (m + 1 == len(places) or not below(profile[m + 1], profile[m]))]


def _null_points(points: np.ndarray, nulls) -> np.ndarray:
    """Which grid points are the effect vanished: every sizing variable at its exact null
    value (:func:`_null_of` with ``exact``; one that only comes close, NaN: no point).
    They are one structure wherever the effect's place and length are, so their χ² differ
    only by rounding and the mesh's last bits (1e-8 relative measured on a section loss of
    ratio 1 at 19 places): which of them is lowest depends on the BLAS kernel."""
    sized = [k for k, z in enumerate(nulls or ()) if z is not None]
    if not sized:
        return np.zeros(len(points), dtype=bool)
    return np.all([np.abs(points[:, k] - nulls[k]) < 1e-12 for k in sized], axis=0)


def _has(start: dict, v) -> bool:
    if v.key not in start:
        return False
    return v.index is None or (isinstance(start[v.key], (list, tuple))
                               and len(start[v.key]) > v.index)


def _value(start: dict, v) -> float:
    return start[v.key] if v.index is None else start[v.key][v.index]


def _grid_start(chi2, grids, nulls=None, bulk=None, places=None, valleys=None):
    """Best point of a coarse grid: each slot's grid (the product of its variables' grids)
    searched with the other slots at their current point.  Of the points where a slot's
    effect vanishes (``nulls``: per slot, per variable, :func:`_null_of`) only the first is
    evaluated: they are one structure.  Returns the start and, when a vanished effect with a
    place won the last searched slot, the best point where it does not (else None): the
    grid's own guess of its place, which a vanished start cannot give.  With ``places``
    (per slot, the index of its place variable or None) and a list ``valleys``, the last
    slot's valleys along its place (:func:`_valleys`) are appended to it as full points
    (the best one's included)."""
    current = [np.array([g[0] for g in slot], dtype=float) for slot in grids]
    if not current:
        return np.zeros(0), None
    informed = None
    for i, slot in enumerate(grids):
        if all(len(g) == 1 for g in slot):
            continue
        points = np.array(np.meshgrid(*slot, indexing="ij")).reshape(len(slot), -1).T
        null = _null_points(points, nulls[i] if nulls else None)
        # the first vanished point stands for them all
        solved = [j for j in range(len(points)) if not (null[j] and null[:j].any())]
        trials = []
        for j in solved:
            trial = list(current)
            trial[i] = points[j]
            trials.append(np.concatenate(trial))
        found = bulk(trials, null[solved]) if bulk is not None else None
        if found is None:
            found = [chi2(z) for z in trials]
        values = [np.inf] * len(points)
        for j, value in zip(solved, found):
            values[j] = value
        best = lowest(values)
        if valleys is not None and i == len(grids) - 1 and places and places[i] is not None:
            for j in _valleys(points, values, null, places[i]):
                trial = list(current)
                trial[i] = points[j]
                valleys.append(np.concatenate(trial))
        current[i] = points[best]
        informed = None
        placed = any(z is None for z in (nulls[i] if nulls else ()))  # a place, a length
        if null[best] and placed and not null.all():
            rest = [v if not n else np.inf for v, n in zip(values, null)]
            other = [c.copy() for c in current]
            other[i] = points[lowest(rest)]
            informed = other
    return np.concatenate(current), (None if informed is None else np.concatenate(informed))
