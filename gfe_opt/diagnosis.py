r"""Diagnosis and update with physical effects: which effect is missing, and its parameters.

Misfit
------
For a model, the lowest modes are paired with the measured ones by MAC (Hungarian,
threshold 0.3) and the weighted residual is

.. math:: χ^2 = \sum_j \Big(\frac{f_j/f_{t,j} - 1}{σ_f}\Big)^2
        + \sum_j \sum_s \Big(\frac{\hat φ_{sj} - \hat y_{sj}}{σ_s \max_s|\hat y_{sj}|}\Big)^2

with unit-norm, sign-aligned shapes at the sensors, σ_f the relative frequency noise and
σ_s the shape noise relative to each mode's largest amplitude (defaults 0.05 % and 0.3 %).
A measured mode with no partner costs :math:`(0.5/σ_f)^2`.

Fitting (IPOPT)
---------------
Each candidate's physical parameters are mapped to order-one variables with bounds (e.g. a
crack's position / length and depth ratio, tension / Euler load, log10 of a spring's
stiffness / (EI/ℓ)), started from the best point of a coarse grid (the crack and the point
mass also from the localisation of :func:`~gfe_opt.correlation.compare`), and χ² is
minimised by IPOPT through CasADi with central finite-difference gradients and a
limited-memory Hessian.  Effects already in the model are re-estimated with the candidate.

Significance
------------
An effect is significant when it lowers χ² by more than the 99.9 % quantile of
χ²(p) (p its number of parameters) against the model without it *and*, for effects other
than ``material``, against the best material-only fit: a uniform change is not reported as a
crack.  ``support_spring`` tries ``left``, ``right`` and ``both`` and keeps the best.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from scipy.special import chdtri

from .correlation import compare, mac, pair_modes
from .errors import GfeInputError, GfeSolverError
from .measured import MeasuredModes, sensor_matrix
from .modal import model_modes
from .model import EFFECT_PARAMETERS, Effect, Model, validate_effect

DEFAULT_FREQ_NOISE = 0.0005
DEFAULT_SHAPE_NOISE = 0.003
SIGNIFICANCE_LEVEL = 0.999
CANDIDATES = ("material", "crack", "shear", "axial_load", "foundation", "support_spring",
              "point_mass")


# -------------------------------------------------------------------------------------------
# Misfit
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Misfit:
    """χ² of a model against measured modes, with the summary numbers users read."""

    chi2: float
    freq_error_rms_pct: float
    mac_mean: float
    n_residuals: int


def misfit(model: Model, measured: MeasuredModes, freq_noise=DEFAULT_FREQ_NOISE,
           shape_noise=DEFAULT_SHAPE_NOISE, C=None) -> Misfit:
    """Weighted residual of ``model`` against ``measured`` (see module docstring)."""
    r, f_err, macs = _residuals(model, measured, freq_noise, shape_noise, C)
    if r is None:
        return Misfit(np.inf, np.inf, 0.0, 0)
    return Misfit(chi2=float(np.sum(r**2)),
                  freq_error_rms_pct=float(100 * np.sqrt(np.mean(f_err**2))) if f_err.size
                  else float("inf"),
                  mac_mean=float(np.mean(macs)) if macs.size else 0.0, n_residuals=r.size)


def _residuals(model, measured, freq_noise, shape_noise, C=None):
    """Fixed-length residual vector (per measured mode: frequency, then sensors), the
    relative frequency errors and MACs of the pairs; ``(None, ...)`` if the solve fails."""
    n_model = measured.n_modes + 4
    try:
        modes = model_modes(model, n_model)
    except GfeSolverError:
        return None, np.zeros(0), np.zeros(0)
    if C is None:
        C = sensor_matrix(model.nodes, model.kind, measured.x, measured.dof, measured.source)
    shapes = C @ modes.shapes
    mac_matrix = mac(measured.shapes, shapes)
    pairs = pair_modes(mac_matrix, threshold=0.3)
    rows = np.array([t for t, _ in pairs], dtype=int)
    cols = np.array([m for _, m in pairs], dtype=int)
    r = np.zeros((measured.n_modes, 1 + measured.n_sensors))
    r[:, 0] = 0.5 / freq_noise  # an unpaired mode
    f_err = modes.frequencies_hz[cols] / measured.frequencies_hz[rows] - 1.0
    y = measured.shapes[:, rows] / np.linalg.norm(measured.shapes[:, rows], axis=0)
    s = shapes[:, cols] / np.linalg.norm(shapes[:, cols], axis=0)
    s = s * np.sign(np.sum(s * y, axis=0))
    r[rows, 0] = f_err / freq_noise
    r[rows, 1:] = ((s - y) / (shape_noise * np.max(np.abs(y), axis=0))).T
    return r.ravel(), f_err, mac_matrix[rows, cols]


# -------------------------------------------------------------------------------------------
# Parameter maps: physical parameters <-> order-one variables with bounds
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Variable:
    name: str
    lower: float
    upper: float
    grid: tuple


def _variables(model: Model, name: str) -> list[Variable]:
    """Order-one variables of an effect (documented in the module docstring)."""
    if name == "material":
        return [Variable("E", 0.5, 2.0, (0.9, 1.0, 1.1))]
    if name == "crack":
        return [Variable("position", 0.0, 1.0, tuple(np.linspace(0.05, 0.95, 19))),
                Variable("depth_ratio", 0.01, 0.9, (0.2, 0.45, 0.7))]
    if name == "shear":
        return [Variable("shear_rigidity", -1.0, 6.0, (0.0, 1.0, 2.0, 3.0, 5.0))]
    if name == "axial_load":
        return [Variable("tension", -0.95, 50.0, (-0.5, 0.0, 0.5, 2.0, 8.0))]
    if name == "foundation":
        return [Variable("stiffness", 1e-4, 100.0, (0.05, 0.5, 2.0, 10.0))]
    if name == "support_spring":
        return [Variable("stiffness", -3.0, 6.0, (-1.0, 0.0, 1.0, 2.0))]
    if name == "point_mass":
        return [Variable("position", 0.0, 1.0, tuple(np.linspace(0.05, 0.95, 19))),
                Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5))]
    raise GfeInputError(None, "effect", f"unknown effect {name!r} "
                        f"(known: {', '.join(EFFECT_PARAMETERS)})")


def _to_physical(model: Model, name: str, z, side: str | None = None) -> dict:
    """Physical parameters of effect ``name`` from its order-one variables ``z``."""
    EI, ell = model.bending_rigidity, model.length
    if name == "material":
        return {"E": float(z[0] * model.E)}
    if name == "crack":
        return {"position": float(z[0] * ell), "depth_ratio": float(z[1])}
    if name == "shear":
        return {"shear_rigidity": float(10.0 ** z[0] * EI / ell**2 * 100.0)}
    if name == "axial_load":
        return {"tension": float(z[0] * np.pi**2 * EI / ell**2)}
    if name == "foundation":
        return {"stiffness": float(z[0] * EI * (np.pi / ell) ** 4)}
    if name == "support_spring":
        return {"stiffness": float(10.0 ** z[0] * EI / ell), "side": side}
    if name == "point_mass":
        return {"position": float(z[0] * ell), "mass": float(z[1] * model.mass_per_length * ell)}
    raise AssertionError(name)


def _to_variables(model: Model, name: str, params: dict) -> np.ndarray:
    """Inverse of :func:`_to_physical` (starting values from physical parameters)."""
    EI, ell = model.bending_rigidity, model.length
    table = {
        "material": lambda p: [p["E"] / model.E],
        "crack": lambda p: [p["position"] / ell, p["depth_ratio"]],
        "shear": lambda p: [np.log10(p["shear_rigidity"] / (EI / ell**2 * 100.0))],
        "axial_load": lambda p: [p["tension"] / (np.pi**2 * EI / ell**2)],
        "foundation": lambda p: [p["stiffness"] / (EI * (np.pi / ell) ** 4)],
        "support_spring": lambda p: [np.log10(p["stiffness"] / (EI / ell))],
        "point_mass": lambda p: [p["position"] / ell, p["mass"] / (model.mass_per_length * ell)],
    }
    return np.array(table[name](params), dtype=float)


# -------------------------------------------------------------------------------------------
# Fitting
# -------------------------------------------------------------------------------------------


@dataclass
class Fit:
    """A model with fitted effects and its misfit."""

    effect: str
    parameters: dict
    model: Model
    misfit: Misfit
    status: str
    success: bool
    evaluations: int
    significant: bool = False


class _Residual(ca.Callback):
    """r(z) as a CasADi function with a forward-difference Jacobian whose own derivative is
    zero, so IPOPT's exact-Hessian mode on ½‖r‖² performs Gauss–Newton steps."""

    def __init__(self, fun, n: int, m: int, step: float = 1e-6):
        ca.Callback.__init__(self)
        self.fun, self.n, self.m, self.step = fun, n, m, step
        self.construct("residual", {})

    def get_n_in(self):
        return 1

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.n, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.m, 1)

    def eval(self, arg):
        return [self.fun(np.array(arg[0]).ravel())]

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._jacobian = _ForwardDifference(name, self)
        return self._jacobian


class _ForwardDifference(ca.Callback):
    def __init__(self, name, outer: _Residual):
        ca.Callback.__init__(self)
        self.outer = outer
        self.construct(name, {})

    def get_n_in(self):
        return 2

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.outer.n if i == 0 else self.outer.m, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.outer.m, self.outer.n)

    def eval(self, arg):
        z, r0 = np.array(arg[0]).ravel(), np.array(arg[1]).ravel()
        jac = np.zeros((self.outer.m, self.outer.n))
        for k in range(self.outer.n):
            dz = z.copy()
            h = self.outer.step * max(1.0, abs(z[k]))
            dz[k] += h
            jac[:, k] = (self.outer.fun(dz) - r0) / h
        return [jac]

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._zero = _Zero(name, self.outer.n, self.outer.m)
        return self._zero


class _Zero(ca.Callback):
    """The (neglected) second derivative of the residual: Gauss–Newton."""

    def __init__(self, name, n, m):
        ca.Callback.__init__(self)
        self.n, self.m = n, m
        self.construct(name, {})

    def get_n_in(self):
        return 3

    def get_n_out(self):
        return 2

    def get_sparsity_in(self, i):
        return [ca.Sparsity.dense(self.n, 1), ca.Sparsity.dense(self.m, 1),
                ca.Sparsity.dense(self.m, self.n)][i]

    def get_sparsity_out(self, i):
        return ca.Sparsity(self.m * self.n, self.n if i == 0 else self.m)

    def eval(self, arg):
        return [ca.DM(ca.Sparsity(self.m * self.n, self.n)),
                ca.DM(ca.Sparsity(self.m * self.n, self.m))]


def _slots(model: Model, adding: list[Effect]):
    """Free effects: the model's present ones (re-estimated) and those being added."""
    slots = [(e.name, e.parameters.get("side")) for e in model.effects]
    for e in adding:
        if e.name not in [s[0] for s in slots]:
            slots.append((e.name, e.parameters.get("side")))
    return slots


def fit_effects(model: Model, measured: MeasuredModes, adding: list[Effect], *,
                freq_noise=DEFAULT_FREQ_NOISE, shape_noise=DEFAULT_SHAPE_NOISE,
                start: dict | None = None, max_iter: int = 25) -> Fit:
    """Fit the physical parameters of the model's effects and of ``adding`` (IPOPT).

    ``adding`` holds effects whose parameters are starting values (``Effect(name, {})`` for
    none: then a coarse grid chooses them).  ``start`` maps effect names to known starting
    parameters (e.g. a crack position from the localisation).
    """
    base = model.with_effects([])
    slots = _slots(model, adding)
    present = {e.name: e for e in model.effects}
    present.update({e.name: e for e in adding if e.parameters})
    variables = [_variables(model, name) for name, _ in slots]
    sizes = [len(v) for v in variables]
    lower = np.concatenate([[v.lower for v in vs] for vs in variables])
    upper = np.concatenate([[v.upper for v in vs] for vs in variables])
    C = sensor_matrix(model.nodes, model.kind, measured.x, measured.dof, measured.source)
    counter = {"n": 0}

    def effects_of(z):
        out, i = [], 0
        for (name, side), size in zip(slots, sizes):
            out.append(Effect(name, _to_physical(base, name, z[i:i + size], side)))
            i += size
        return out

    def residual(z):
        counter["n"] += 1
        try:
            trial = base.with_effects(effects_of(z))
        except GfeInputError:
            return np.full(n_res, 1e6)
        r = _residuals(trial, measured, freq_noise, shape_noise, C)[0]
        return np.full(n_res, 1e6) if r is None else r

    def chi2(z):
        return float(np.sum(residual(z) ** 2))

    n_res = measured.n_modes * (1 + measured.n_sensors)
    # -- starting point: present values, given starts, then a grid over the rest ---------
    z0 = []
    for (name, _side), vs in zip(slots, variables):
        params = (start or {}).get(name) or (present[name].parameters if name in present
                                             else None)
        if params and all(v.name in params for v in vs):
            z0.append(np.clip(_to_variables(base, name, params), [v.lower for v in vs],
                              [v.upper for v in vs]))
        else:
            z0.append(None)
    z_start = _grid_start(chi2, variables, z0)
    # -- IPOPT (Gauss-Newton Hessian, finite-difference Jacobian) ------------------------
    n = z_start.size
    chi2_start = chi2(z_start)
    scale = np.sqrt(max(chi2_start, 1.0))  # objective starts at 1/2: relative tolerances
    r_fun = _Residual(lambda z: residual(z) / scale, n, n_res)
    x = ca.MX.sym("z", n)
    solver = ca.nlpsol("effects", "ipopt", {"x": x, "f": 0.5 * ca.sumsqr(r_fun(x))},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                        "ipopt.max_iter": max_iter, "ipopt.tol": 1e-6,
                        # finite-difference gradients carry ~1e-6 relative noise: stop when
                        # the objective no longer moves rather than chase the gradient
                        "ipopt.acceptable_tol": 1e-1, "ipopt.acceptable_iter": 2,
                        "ipopt.acceptable_obj_change_tol": 1e-7})
    sol = solver(x0=z_start, lbx=lower, ubx=upper)
    stats = solver.stats()
    z = np.array(sol["x"]).ravel()
    if chi2(z) > chi2_start:  # never return worse than the start
        z = z_start
    effects = effects_of(z)
    fitted = base.with_effects(effects)
    status = str(stats.get("return_status"))
    success = bool(stats.get("success")) or status in ("Solved_To_Acceptable_Level",
                                                       "Maximum_Iterations_Exceeded")
    name = adding[0].name if adding else "baseline"
    params = next((e.parameters for e in effects if e.name == name), {})
    return Fit(effect=name, parameters=params, model=fitted,
               misfit=misfit(fitted, measured, freq_noise, shape_noise, C), status=status,
               success=success, evaluations=counter["n"])


def _grid_start(chi2, variables, z0):
    """Best point of a coarse grid over the variables that have no starting value."""
    fixed = [z for z in z0 if z is not None]
    free = [i for i, z in enumerate(z0) if z is None]
    if not free:
        return np.concatenate(fixed) if fixed else np.zeros(0)
    grids = [np.array(np.meshgrid(*[v.grid for v in variables[i]], indexing="ij")).reshape(
        len(variables[i]), -1).T for i in free]
    best, best_z = np.inf, None
    # search each free slot's grid with the others at their first grid point
    current = [z if z is not None else grids[free.index(i)][0] for i, z in enumerate(z0)]
    for slot, grid in zip(free, grids):
        for point in grid:
            trial = list(current)
            trial[slot] = point
            value = chi2(np.concatenate(trial))
            if value < best:
                best, best_z = value, trial
        current = best_z
    return np.concatenate(current)


# -------------------------------------------------------------------------------------------
# Diagnose and update
# -------------------------------------------------------------------------------------------


@dataclass
class Diagnosis:
    """Ranked candidate effects (best first) and the baseline misfit."""

    baseline: Misfit
    fits: list
    seconds: float
    localisation: list = field(default_factory=list)
    realisation: list = field(default_factory=list)   # the nodal equations in words
    nodal: list = field(default_factory=list)         # Realisation per node
    generic_update: object = None                     # the UpdateResult they come from

    def to_json(self) -> dict:
        """The ``diagnose --json`` contract."""
        return {"baseline": {"freq_error_rms_pct": self.baseline.freq_error_rms_pct,
                             "mac_mean": self.baseline.mac_mean},
                "effects": [{"effect": f.effect, "parameters": f.parameters,
                             "freq_error_rms_pct": f.misfit.freq_error_rms_pct,
                             "mac_mean": f.misfit.mac_mean, "significant": f.significant}
                            for f in self.fits]}

    @property
    def best(self) -> Fit | None:
        return next((f for f in self.fits if f.significant), None)


def check_enough_modes(measured: MeasuredModes, effects) -> None:
    """Each fitted effect needs at least as many measured modes as it has parameters (one
    mode cannot tell a crack's position from its depth); several effects add up."""
    need = sum(len(EFFECT_PARAMETERS[e.name]) - (1 if e.name == "support_spring" else 0)
               for e in effects)
    if measured.n_modes < need:
        names = " + ".join(e.name for e in effects)
        raise GfeInputError(measured.source, "modes", f"{names} needs at least {need} "
                            f"measured modes, the file has {measured.n_modes}")


def _threshold(p: int) -> float:
    return float(chdtri(p, 1.0 - SIGNIFICANCE_LEVEL))  # the χ²(p) quantile


def diagnose(model: Model, measured: MeasuredModes, *, candidates=CANDIDATES,
             freq_noise=DEFAULT_FREQ_NOISE, shape_noise=DEFAULT_SHAPE_NOISE,
             progress=None, realise: bool = False) -> Diagnosis:
    """Rank candidate effects by how much of the discrepancy each explains.

    Each candidate is fitted together with the model's present effects (IPOPT); the
    remaining error and significance are reported (module docstring).  ``progress`` is
    called as ``progress(done, total, name)``.  With ``realise`` (beams), the generic-element
    update (nodal k_i, ∂k_i/∂x) is run too and its nodal equations are read in words
    (:func:`~gfe_opt.realisation.summarise`).
    """
    start = time.perf_counter()
    for name in candidates:
        _variables(model, name)  # rejects unknown names before any work
    C = sensor_matrix(model.nodes, model.kind, measured.x, measured.dof, measured.source)
    baseline = misfit(model, measured, freq_noise, shape_noise, C)
    localisation = compare(model, measured, noise=max(shape_noise, 1e-3)).failure_places()
    hint = localisation[0][0] / model.length if localisation else 0.5
    # the model's present effects re-estimated alone: the reference for the candidates
    reference = fit_effects(model, measured, [], freq_noise=freq_noise,
                            shape_noise=shape_noise) if model.effects else None
    ref_chi2 = reference.misfit.chi2 if reference else baseline.chi2
    fits = []
    jobs = []
    present = {e.name for e in model.effects}
    for name in candidates:
        if name in present:  # already in the model: re-estimated in every fit
            continue
        try:
            check_enough_modes(measured, [*model.effects, Effect(name, {})])
        except GfeInputError:
            continue  # too few modes to fit this candidate with the present effects
        sides = ("left", "right", "both") if name == "support_spring" else (None,)
        jobs += [(name, side) for side in sides]
    fits = _run_jobs([(model, measured, name, {"side": side} if side else {}, hint,
                       freq_noise, shape_noise) for name, side in jobs], progress)
    # keep the best side of the support spring
    springs = [f for f in fits if f.effect == "support_spring"]
    if springs:
        best_spring = min(springs, key=lambda f: f.misfit.chi2)
        fits = [f for f in fits if f.effect != "support_spring"] + [best_spring]
    material = next((f for f in fits if f.effect == "material"), None)
    for f in fits:
        p = len(_variables(model, f.effect))
        better_than_reference = ref_chi2 - f.misfit.chi2 > _threshold(p)
        if f.effect == "material" or material is None:
            f.significant = better_than_reference and f.success
        else:
            extra = max(p - (0 if any(e.name == "material" for e in model.effects) else 0), 1)
            f.significant = (better_than_reference and f.success
                             and material.misfit.chi2 - f.misfit.chi2 > _threshold(extra))
    fits.sort(key=lambda f: (not f.significant, f.misfit.chi2))
    words, nodal, generic = (_generic_realisation(model, measured, shape_noise) if realise
                             else ([], [], None))
    return Diagnosis(baseline=baseline, fits=fits, seconds=time.perf_counter() - start,
                     localisation=localisation, realisation=words, nodal=nodal,
                     generic_update=generic)


def _generic_realisation(model: Model, measured: MeasuredModes, shape_noise: float):
    """The generic-element update (beams) and what its nodal equations say:
    ``(words, per-node realisations, UpdateResult)``."""
    if model.kind != "beam":
        return [], [], None
    from .assembly import discretise
    from .realisation import realise, summarise
    from .updating import update_generic

    disc = discretise(model)
    result = update_generic(disc, measured, noise=max(shape_noise, 1e-3))
    if not result.ok:
        return [f"(the generic-element update did not converge: {result.status})"], [], result
    nodal = realise(result.discretisation, disc)
    words = summarise(nodal) or ["no change in the continuous equation beyond the noise"]
    return words, nodal, result


def _run_jobs(jobs, progress):
    """Fit the candidates, in parallel over the machine's cores (fork, one BLAS thread per
    worker; serial where processes cannot be forked or only one core is there); results in
    the order given."""
    workers = min(len(jobs), os.cpu_count() or 1)
    if progress:
        progress(0, len(jobs), "")
    results = [None] * len(jobs)
    try:
        if workers < 2:
            raise OSError("one core")
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                 initializer=_single_threaded_blas) as pool:
            futures = {pool.submit(_fit_candidate, *job): i for i, job in enumerate(jobs)}
            for done, future in enumerate(as_completed(futures), start=1):
                results[futures[future]] = future.result()
                if progress:
                    progress(done, len(jobs), jobs[futures[future]][2])
    except (OSError, ValueError, BrokenProcessPool):
        for i, job in enumerate(jobs):
            if results[i] is None:
                results[i] = _fit_candidate(*job)
            if progress:
                progress(i + 1, len(jobs), job[2])
    return results


def _single_threaded_blas():
    """One BLAS thread per worker: the matrices are small and the workers share the cores
    (measured: 2.9 s instead of 7.9 s with threaded BLAS in each worker)."""
    from threadpoolctl import threadpool_limits

    global _BLAS_LIMIT
    _BLAS_LIMIT = threadpool_limits(limits=1)


_BLAS_LIMIT = None


def _localisation_hint(model, measured, shape_noise) -> float:
    """Where :func:`~gfe_opt.correlation.compare` says the model fails, as x / length."""
    places = compare(model, measured, noise=max(shape_noise, 1e-3)).failure_places()
    return places[0][0] / model.length if places else 0.5


def _fit_candidate(model, measured, name, params, hint, freq_noise, shape_noise):
    """Fit one candidate; crack and point mass also try a start at the localisation."""
    fit = fit_effects(model, measured, [Effect(name, params)], freq_noise=freq_noise,
                      shape_noise=shape_noise)
    if name in ("crack", "point_mass"):
        guess = {"crack": {"position": hint * model.length, "depth_ratio": 0.45},
                 "point_mass": {"position": hint * model.length,
                                "mass": 0.2 * model.mass_per_length * model.length}}[name]
        other = fit_effects(model, measured, [Effect(name, guess)], freq_noise=freq_noise,
                            shape_noise=shape_noise)
        if other.misfit.chi2 < fit.misfit.chi2:
            fit = other
    return fit


@dataclass
class UpdateOutcome:
    """Result of :func:`update`: the misfit before and after and the fitted model."""

    before: Misfit
    after: Misfit
    model: Model
    fit: Fit

    def to_json(self) -> dict:
        """The ``update --json`` contract."""
        def summary(m):
            return {"freq_error_rms_pct": m.freq_error_rms_pct, "mac_mean": m.mac_mean}

        return {"before": summary(self.before), "after": summary(self.after),
                "effects": [{"effect": e.name, "parameters": e.parameters}
                            for e in self.model.effects]}


def parse_effect(text: str, model: Model, where: str = "--add") -> Effect:
    """``crack`` or ``crack:position=0.2,depth_ratio=0.4`` -> Effect (parameters validated
    when all are given; partial ones are starting values)."""
    name, _, rest = text.partition(":")
    if name not in EFFECT_PARAMETERS:
        raise GfeInputError(where, text, f"unknown effect {name!r} "
                            f"(known: {', '.join(EFFECT_PARAMETERS)})")
    params = {}
    for item in filter(None, rest.split(",")):
        key, eq, value = item.partition("=")
        if not eq or key not in EFFECT_PARAMETERS[name]:
            raise GfeInputError(where, text, f"expected key=value with keys "
                                f"{', '.join(EFFECT_PARAMETERS[name])}, got {item!r}")
        if key == "side":
            params[key] = value
        else:
            try:
                params[key] = float(value)
            except ValueError:
                raise GfeInputError(where, text, f"{key} must be a number, got {value!r}"
                                    ) from None
    if set(params) == set(EFFECT_PARAMETERS[name]):
        params = validate_effect(model, name, params, where, "")
    return Effect(name, params)


def update(model: Model, measured: MeasuredModes, add, *, freq_noise=DEFAULT_FREQ_NOISE,
           shape_noise=DEFAULT_SHAPE_NOISE) -> UpdateOutcome:
    """Add effects (names, ``name:key=value`` strings or :class:`Effect`) and fit all of the
    model's effects' physical parameters with IPOPT.  Starting values: those given, else
    the diagnosis of each effect alone."""
    effects = [parse_effect(a, model) if isinstance(a, str) else a for a in add]
    check_enough_modes(measured, [*model.effects,
                                  *[e for e in effects if e.name not in
                                    {m.name for m in model.effects}]])
    C = sensor_matrix(model.nodes, model.kind, measured.x, measured.dof, measured.source)
    before = misfit(model, measured, freq_noise, shape_noise, C)
    incomplete = [e for e in effects if set(e.parameters) != set(EFFECT_PARAMETERS[e.name])]
    hint = _localisation_hint(model, measured, shape_noise) if incomplete else 0.5
    starts = []
    for e in effects:
        if e.name == "support_spring" and "side" not in e.parameters:
            single = min((_fit_candidate(model, measured, e.name, {"side": s}, hint,
                                         freq_noise, shape_noise)
                          for s in ("left", "right", "both")), key=lambda f: f.misfit.chi2)
            starts.append(Effect(e.name, single.parameters))
        elif set(e.parameters) != set(EFFECT_PARAMETERS[e.name]):
            single = _fit_candidate(model, measured, e.name,
                                    {k: v for k, v in e.parameters.items() if k == "side"},
                                    e.parameters.get("position", hint * model.length)
                                    / model.length, freq_noise, shape_noise)
            starts.append(Effect(e.name, {**single.parameters, **e.parameters}))
        else:
            starts.append(e)
    fit = fit_effects(model, measured, starts, freq_noise=freq_noise, shape_noise=shape_noise,
                      start={e.name: e.parameters for e in starts})
    if not fit.success:
        raise GfeSolverError(f"IPOPT did not fit the effects ({fit.status})")
    return UpdateOutcome(before=before, after=fit.misfit, model=fit.model, fit=fit)
