r"""What a physical effect is: one object that knows everything gfe-opt does with it.

An :class:`EffectType` declares

* its **parameters** (:class:`Parameter`: name, SI unit, the rule that checks a value, the
  value at which the effect vanishes);
* how it **changes the matrices**: :meth:`EffectType.contribute` tells a
  :class:`~gfe_opt.assembly.Builder` to scale EI(x) or ρA(x), add a point mass or spring, an
  element stiffness term or a support spring (the builder turns that into element matrices);
* its **order-one variables** (:class:`Variable`: physical value = scale · z or
  scale · 10^z, with bounds and a starting grid) for fitting;
* its **realisation signature**: what it leaves in the continuous equation of a node;
* its **marker** on the structure sketch of the figures.

Effects are *global* (``material``, ``shear``, ``axial_load``, ``foundation``: at most one of
each in a model) or *local* (any number of instances: two cracks are two ``crack`` entries).
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import GfeInputError


@dataclass(frozen=True)
class Parameter:
    """A physical parameter of an effect.

    ``rule`` is one of ``"position"`` (m, on the structure), ``"positive"`` (> 0),
    ``"real"``, ``"fraction"`` (in (0, 1)), ``"range"`` (in [lower, upper]), ``"choice"``
    (one of ``choices``), ``"knots"`` (increasing positions from one end to the other) or
    ``"ratios"`` (a list of positive numbers, one per knot).  ``null`` is the value at which
    the effect vanishes (``"inf"`` when it vanishes as the value grows, as a shear rigidity);
    the size of a fitted effect is measured from it in standard deviations.
    """

    name: str
    unit: str
    rule: str
    description: str
    lower: float | None = None
    upper: float | None = None
    choices: tuple = ()
    null: Any = None

    def describe_range(self, model) -> str:
        if self.rule == "position":
            return f"0 to {model.length:g} m"
        if self.rule == "positive":
            return f"> 0 {self.unit}".strip()
        if self.rule == "fraction":
            return "between 0 and 1 (exclusive)"
        if self.rule == "range":
            return f"{self.lower:g} to {self.upper:g} {self.unit}".strip()
        if self.rule == "choice":
            return "one of " + ", ".join(self.choices)
        if self.rule == "knots":
            return f"increasing positions from 0 to {model.length:g} m"
        if self.rule == "ratios":
            return "positive numbers, one per knot"
        return "a finite number"

    def check(self, value, model, where: str, field: str, length: float | None = None):
        """The value, validated (lists as lists of floats); raises :class:`GfeInputError`.
        ``length``: what knots span (a frame member's; default the structure's)."""
        if self.rule == "choice":
            if value not in self.choices:
                raise GfeInputError(where, field, f"must be {self.describe_range(model)}, "
                                    f"got {value!r}")
            return value
        if self.rule in ("knots", "ratios"):
            if not isinstance(value, (list, tuple)) or len(value) < 2:
                raise GfeInputError(where, field, "must be a list of at least 2 numbers")
            values = [as_float(v, where, f"{field}[{i}]") for i, v in enumerate(value)]
            if self.rule == "ratios":
                bad = [i for i, v in enumerate(values) if not 0.0 < v <= 100.0]
                if bad:
                    raise GfeInputError(where, f"{field}[{bad[0]}]", "must lie in (0, 100], "
                                        f"got {values[bad[0]]:g}")
            else:
                span = model.length if length is None else length
                tol = 1e-9 * span
                if abs(values[0]) > tol or abs(values[-1] - span) > tol:
                    what = "the whole structure" if length is None else "the whole member"
                    raise GfeInputError(where, field, f"must run from 0 to {span:g} m "
                                        f"({what}), got {values[0]:g} to {values[-1]:g}")
                if np.any(np.diff(values) <= 0):
                    raise GfeInputError(where, field, "positions must increase")
            return values
        value = as_float(value, where, field)
        if self.rule == "positive" and value <= 0:
            raise GfeInputError(where, field, f"must be > 0 [{self.unit}], got {value:g}")
        if self.rule == "fraction" and not 0.0 < value < 1.0:
            raise GfeInputError(where, field, f"must lie between 0 and 1 (exclusive), "
                                f"got {value:g}")
        if self.rule == "range" and not self.lower <= value <= self.upper:
            raise GfeInputError(where, field, f"must lie in [{self.lower:g}, {self.upper:g}]"
                                f" {self.unit}, got {value:g}".rstrip())
        if self.rule == "position" and not 0.0 <= value <= model.length:
            raise GfeInputError(where, field, f"{value:g} m lies outside the structure "
                                f"[0, {model.length:g}] m")
        return value


@dataclass(frozen=True)
class Variable:
    """An order-one fitting variable z of parameter ``key`` (element ``index`` of a list):
    physical value = ``scale(model) * z`` or, with ``log``, ``scale(model) * 10**z``."""

    key: str
    lower: float
    upper: float
    grid: tuple
    scale: Callable = lambda model: 1.0
    log: bool = False
    index: int | None = None

    @property
    def label(self) -> str:
        return self.key if self.index is None else f"{self.key}[{self.index}]"

    def physical(self, model, z: float) -> float:
        s = self.scale(model)
        return float(s * 10.0**z) if self.log else float(s * z)

    def order_one(self, model, value: float) -> float:
        s = self.scale(model)
        if self.log:
            return float(np.log10(value / s)) if value > 0 else self.lower
        return float(value / s)


def position_variable(model=None) -> Variable:
    """x / length in [0, 1], grid of 19 places from 0.05 to 0.95: the position of a local
    effect; with ``model``, also each end whose support lets it move (a mass at the tip of
    a cantilever)."""
    ends = () if model is None else tuple(
        float(end) for end in (0, 1) if model.supports[end] not in FIXED_TRANSLATION)
    return Variable("position", 0.0, 1.0, tuple(np.linspace(0.05, 0.95, 19)) + ends,
                    scale=lambda model: model.length)


def inward(model, x: float) -> str:
    """The alignment of a label at x that runs inwards from an end of the sketch (centred,
    a tip body's was cut off)."""
    side = x / model.length
    return "right" if side > 0.7 else "left" if side < 0.3 else "center"


def end_at(model, x: float) -> tuple[str, str] | None:
    """``("left", support)`` or ``("right", support)`` when x lies on an end, else None."""
    tol = 1e-9 * model.length
    if abs(x) <= tol:
        return "left", model.supports[0]
    if abs(x - model.length) <= tol:
        return "right", model.supports[1]
    return None


#: supports that hold the translation still (beam w, bar u): a mass or a spring there does
#: nothing
FIXED_TRANSLATION = ("pinned", "clamped", "fixed")
#: supports where the bending moment vanishes: a crack there changes nothing
FREE_MOMENT = ("pinned", "free")


def translation_held(model, end: int) -> bool:
    """Whether the support at ``end`` (0 left, 1 right) holds the translation still, with
    the model's effects (a ``support_translation`` lets it give)."""
    if model.supports[end] not in FIXED_TRANSLATION:
        return False
    side = ("left", "right")[end]
    for e in model.effects:
        if side in effect_sides(e.parameters) and \
                getattr(_registry_type(e.name), "releases_translation", False):
            return False
    return True


def effect_sides(params) -> tuple:
    """The ends a ``side`` parameter names."""
    side = params.get("side")
    return ("left", "right") if side == "both" else (side,) if side else ()


def _registry_type(name):
    from . import effect_type

    return effect_type(name)


def check_not_on_support(model, params, where, prefix, name, supports, why):
    """A point effect on an end whose support makes it meaningless is an error."""
    if "position" not in params:
        return
    end = end_at(model, params["position"])
    if end is not None and end[1] in supports:
        raise GfeInputError(where, f"{prefix}position", f"{params['position']:g} m is the "
                            f"{end[1]} {end[0]} end, where {why}: a {name} there does "
                            "nothing")


def as_float(value, where, field) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise GfeInputError(where, field, f"must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise GfeInputError(where, field, f"must be finite, got {value}")
    return value


def no_unknown(tbl, known, where, prefix):
    """Unknown keys are errors, with a "did you mean" hint."""
    for key in tbl:
        if key not in known:
            close = difflib.get_close_matches(key, sorted(known), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise GfeInputError(where, prefix + key, f"unknown key{hint}")


def frame_member_at(model, node: str):
    """The first member (file order) that starts or ends at ``node`` of a frame."""
    return next(m for m in model.members if node in (m.start, m.end))


def frame_member_scale(model, node: str, power: int) -> float:
    """EI / L^power of the first member at ``node``: the order-one scale of a spring there
    (power 1: rotation, N m/rad; 3: translation, N/m)."""
    m = frame_member_at(model, node)
    return m.E * m.inertia / model.member_length(m) ** power


def frame_free_ends(model, member, held) -> tuple:
    """The ends of a frame ``member`` (0.0 its start, 1.0 its end) where an effect acting on
    the DOFs ``held`` (0 x, 1 y) does something: those whose node no support holds in every
    one of them."""
    from ..frame import SUPPORT_TYPES

    supports = dict(model.supports)
    return tuple(float(t) for t, node in ((0, member.start), (1, member.end))
                 if not set(held) <= set(SUPPORT_TYPES.get(supports.get(node), ())))


def frame_position_variable(model, member, ends=()) -> Variable:
    """A place along a frame ``member``: x / its length in [0, 1], grid at 19 interior
    places (and ``ends``, 0 or 1, where the effect may sit on a joint)."""
    length = model.member_length(member)
    return Variable("position", 0.0, 1.0, tuple(np.linspace(0.05, 0.95, 19)) + tuple(ends),
                    scale=lambda m: length)


def nominal_rigidity(model) -> float:
    """EI (beam) or EA (bar) of the model file's section and E, without effects [N m², N]:
    the fixed scale of the order-one variables."""
    return model.E * (model.inertia if model.kind == "beam" else model.area)


class EffectType:
    """Base class of every physical effect (see the module docstring).

    Subclasses set the class attributes and override :meth:`contribute`; the rest has
    defaults that fit most effects.
    """

    #: the name in model files, ``--add`` and JSON (a contract)
    name: str = ""
    #: one line of physics, shown in help and the README
    physics: str = ""
    #: what the effect leaves in the continuous equation of a node (paper, section 3)
    signature: str = ""
    #: "beam", "bar" or both
    kinds: tuple = ("beam",)
    #: local effects may repeat; global ones appear at most once
    local: bool = False
    #: proposed by ``diagnose`` unless the user chooses the candidates
    candidate: bool = True
    #: tried by ``diagnose`` on a frame without being named (with :attr:`candidate`)
    frame_candidate: bool = True
    #: parameters (contract) and those fitted (the others, e.g. a side, are fixed per fit)
    parameters: tuple = ()
    #: a uniform change every other candidate must beat (a uniform change is not a crack)
    uniform_reference: bool = False
    #: effects whose presence holds this one (E and a stiffness profile are one parameter)
    redundant_with: tuple = ()
    #: parameters at whose null the effect is still there (a body's rotary inertia: it is
    #: then a point mass), unlike a size at its null, where the effect vanishes and its
    #: place is not determined by the data
    present_at_null: tuple = ()
    #: the kind this one extends, which it is where its own size (:meth:`size_in_sigmas`)
    #: lies within the significance's σ of nothing (a body whose J the data do not tell is
    #: the point mass): not offered in place of another effect nor as a pair's second then
    simpler: str | None = None
    #: acts as a moment at a point (a body's rotary inertia): inside an element the
    #: curvature jumps there, which the element's cubic cannot follow, so the model reads it
    #: less exactly than at a node (:func:`gfe_opt.diagnosis._mesh_notes`)
    point_moment: bool = False
    #: on a plane frame (``"frame"`` in :attr:`kinds`): the parameters that place the effect
    #: (a member, a node, a direction; chosen, not fitted), in place of a beam's ``side``
    frame_parameters: tuple = ()

    # -- parameters -------------------------------------------------------------------
    @property
    def keys(self) -> tuple:
        return tuple(p.name for p in self.parameters)

    @property
    def all_parameters(self) -> tuple:
        """The frame's place parameters, then the others (what :meth:`describe` prints)."""
        return (*self.frame_parameters, *self.parameters)

    def candidate_for(self, model) -> bool:
        """Whether ``diagnose`` tries it on ``model`` by default (with :attr:`candidate`;
        an effect that only completes another, the rotary inertia of an attached mass,
        asks for that one in the model)."""
        return True

    def every_start(self, model) -> bool:
        """Whether a fit of it on ``model`` runs from each of its starts (:meth:`starts`
        with the same place) to its end and keeps the best, not only from the best grid
        point over them (a frame's body: a point mass that slides off a joint stands for a
        small J, a valley the grid's best point lies in)."""
        return False

    def is_local(self, model) -> bool:
        """Whether the effect may appear more than once in ``model`` (:attr:`local`; an
        effect global on a beam may be one a member on a frame)."""
        return self.local

    def parameter(self, key: str) -> Parameter:
        return next(p for p in self.all_parameters if p.name == key)

    def validate(self, model, params: dict, where: str, prefix: str = "",
                 partial: bool = False) -> dict:
        """Checked parameters (every key, or with ``partial`` those given); raises
        :class:`GfeInputError` naming the field and the allowed range."""
        if model.kind == "frame" and model.kind not in self.kinds:
            from . import EFFECTS

            taken = [n for n, e in EFFECTS.items() if "frame" in e.kinds]
            raise GfeInputError(where, f"{prefix}effect", f"effect {self.name!r} is not "
                                f"fitted on frames yet (a frame takes {', '.join(taken)})")
        if model.kind == "frame":
            return self._validate_frame(model, params, where, prefix, partial)
        if model.kind not in self.kinds:
            raise GfeInputError(where, f"{prefix}effect", f"effect {self.name!r} needs kind = "
                                f"{' or '.join(repr(k) for k in self.kinds)}")
        no_unknown(params, set(self.keys), where, prefix)
        out = {}
        for p in self.parameters:
            if p.name not in params:
                if partial:
                    continue
                raise GfeInputError(where, f"{prefix}{p.name}",
                                    f"missing ({self.name} needs {p.name} [{p.unit}])")
            out[p.name] = p.check(params[p.name], model, where, f"{prefix}{p.name}")
        self.check(model, out, where, prefix)
        return out

    def _validate_frame(self, model, params, where, prefix, partial) -> dict:
        """A frame's effect by the frame file's rules (:func:`gfe_opt.frame._effect`); with
        ``partial`` (``--add``) only what is given, and with no place given every place is
        tried (:meth:`starts`)."""
        from ..frame import _effect

        place = [p.name for p in self.frame_parameters]
        missing = [k for k in place if k not in params]
        if partial and len(missing) == len(place):
            no_unknown(params, {p.name for p in self.all_parameters}, where, prefix)
            return dict(params)
        if missing:
            raise GfeInputError(where, f"{prefix}{missing[0]}", f"missing (a {self.name} on a "
                                f"frame needs {' and '.join(place)})")
        full = {"effect": self.name, **params}
        if partial:   # placeholders for the values to be fitted: the place is checked
            for key, value in self.frame_placeholders(model, params).items():
                full.setdefault(key, value)
        checked = _effect(model, full, where, prefix).parameters
        return {k: checked[k] for k in checked if k in params}

    def frame_placeholders(self, model, params) -> dict:
        """Values that let a partly given frame effect (``--add``) be checked for its place."""
        return {"stiffness": 1.0}

    def told_trades(self, model) -> tuple:
        """Pairs of parameters (frozensets of keys) whose trade against each other leaves
        the effect a finding: the data fix their combination, which is the physics (a short
        zone's length and its ratios: its compliance).  Any other trade makes the effect not
        estimable."""
        return ()

    def told_values(self, model, params: dict) -> dict:
        """The combinations of the parameters the data fix when a trade of
        :meth:`told_trades` leaves each value loose: {key: (label, unit, value)} (the fit
        gives each its σ, :attr:`~gfe_opt.fitting.Fit.told`).  None by default."""
        return {}

    def check(self, model, params: dict, where: str, prefix: str) -> None:
        """Checks across parameters or against the model (override when needed)."""

    # -- matrices ---------------------------------------------------------------------
    def contribute(self, model, params: dict, build) -> None:
        """Tell ``build`` (:class:`~gfe_opt.assembly.Builder`) how the effect changes the
        structure."""
        raise NotImplementedError

    def youngs_modulus(self, params: dict, E: float) -> float:
        """Young's modulus with this effect (only ``material`` changes it)."""
        return E

    # -- fitting ----------------------------------------------------------------------
    def variables(self, model, fixed: dict) -> list[Variable]:
        """Order-one variables for the fitted parameters (``fixed`` holds the others)."""
        raise NotImplementedError

    def fixed_keys(self, model=None) -> tuple:
        """Parameters that are chosen, not fitted (e.g. a spring's side; on a frame
        ``model``, the place); without a model, every one of either."""
        beam = tuple(p.name for p in self.parameters if p.rule in ("choice", "knots"))
        frame = tuple(p.name for p in self.frame_parameters)
        if model is None:
            return beam + frame
        return frame if model.kind == "frame" else beam

    def starts(self, model, hint: float) -> list[dict]:
        """Starting parameter sets to try besides the grid (``hint`` = where the model
        fails, x / length); each a dict of fixed and (some) fitted parameters."""
        return [{}]

    def to_physical(self, model, variables: list[Variable], z, fixed: dict) -> dict:
        out = dict(fixed)
        for v, value in zip(variables, z):
            phys = v.physical(model, value)
            if v.index is None:
                out[v.key] = phys
            else:
                out.setdefault(v.key, [])
                out[v.key].append(phys)
        return {k: out[k] for k in (p.name for p in self.all_parameters) if k in out}

    def tie(self, model, variables: list[Variable], z):
        """Directions in which the fitted variables ``z`` can still move without changing
        the effect in a way the variables do not show (a zone with an edge on an end):
        ``(T, labels)``, T of shape (variables, directions), or None when every variable
        moves freely (the default)."""
        return None

    def untie(self, model, variables: list[Variable], z):
        """The same effect off a kink of the residual, where a fit can start (default: z
        itself)."""
        return z

    def snap(self, model, variables: list[Variable], z):
        """The effect with an edge that stopped short of an end moved onto it (started past
        it, off the kink), where a fit may end as well with one parameter fewer; None when
        there is no such edge (the default)."""
        return None

    def to_variables(self, model, variables: list[Variable], params: dict) -> np.ndarray:
        out = []
        for v in variables:
            value = params[v.key] if v.index is None else params[v.key][v.index]
            out.append(np.clip(v.order_one(model, value), v.lower, v.upper))
        return np.array(out, dtype=float)

    def size_in_sigmas(self, model, params: dict, sigma: dict) -> float:
        """How far the fitted effect lies from 'no effect', in standard deviations: the
        largest |value − null| / σ over the parameters that have a null value (a reciprocal
        for null = "inf").  0 when the data do not determine it (σ infinite or unknown)."""
        best = 0.0
        for p in self.parameters:
            if p.null is None or p.name not in params:
                continue
            values = np.atleast_1d(np.asarray(params[p.name], float))
            sig = np.atleast_1d(np.asarray(sigma.get(p.name, np.inf), float))
            null = model.E if p.null == "E" else p.null
            if p.null == "inf":
                z = values / sig  # 1/v from 0 in units of σ(1/v) = σ/v²
            else:
                z = np.abs(values - null) / sig
            z = np.where(np.isfinite(z), z, 0.0)
            best = max(best, float(np.max(z)))
        return best

    # -- what users see ---------------------------------------------------------------
    def describe(self, params: dict, sigma: dict | None = None,
                 bounds: dict | None = None) -> str:
        """``position = 0.190 ± 0.001 m, depth_ratio = 0.50 ± 0.01``; a parameter on a bound
        of its range (``bounds``: "at least" / "at most") as ``stiffness ≥ 1e9 N/m``."""
        parts = []
        for p in self.all_parameters:
            if p.name not in params:
                continue
            if p.name in (bounds or {}):
                parts.append(format_bound(p, params[p.name], bounds[p.name]))
                continue
            parts.append(format_value(p, params[p.name], (sigma or {}).get(p.name)))
        return ", ".join(parts)

    def mark(self, ax, model, params: dict, sigma: dict | None, y: float,
             bounds: dict | None = None) -> None:
        """Draw the effect on the structure sketch (a matplotlib axis, x in m) at height y
        (``bounds``: parameters on a bound of their range, as :meth:`describe` takes them);
        default, for effects of the whole structure: the name and the fitted values, from
        the left end."""
        ax.annotate(f"{self.name}: {self.describe(params, sigma, bounds)}", (0.0, y),
                    textcoords="offset points", xytext=(0, 8), ha="left", fontsize=7,
                    color="tab:red")

    def position(self, params: dict) -> float | None:
        """Where a local effect sits [m] (None for distributed ones)."""
        return params.get("position")

    def figures(self, model, params: dict, band) -> dict:
        """Extra figures when this effect is found (name -> matplotlib figure); ``band`` is
        the generic update's :class:`~gfe_opt.realisation.ProfileBand` or None."""
        return {}


def format_bound(p: Parameter, value, side: str) -> str:
    """A parameter on a bound of its range: ``stiffness ≥ 1e+09 N/m (one-sided: ...)``."""
    unit = f" {p.unit}" if p.unit and p.unit != "-" else ""
    sign = "≥" if side == "at least" else "≤"
    return (f"{p.name} {sign} {value:.4g}{unit} (the end of its range: the data tell only "
            f"that it is {side} this)")


def format_value(p: Parameter, value, sigma=None) -> str:
    """One parameter for people: 4 significant digits, ± σ, the unit."""
    unit = f" {p.unit}" if p.unit and p.unit != "-" else ""
    if isinstance(value, str):
        return f"{p.name} = {value}"
    if isinstance(value, (list, tuple)):
        if sigma is not None and np.all(np.isfinite(sigma)):
            inner = ", ".join(f"{v:.3g}±{s:.2g}" for v, s in zip(value, sigma))
        else:
            inner = ", ".join(f"{v:.4g}" for v in value)
        return f"{p.name} = [{inner}]{unit}"
    if sigma is None:
        return f"{p.name} = {value:.4g}{unit}"
    if not np.isfinite(sigma):
        return f"{p.name} = {value:.4g}{unit} (not determined by the data)"
    digits = max(0, -int(np.floor(np.log10(abs(sigma)))) + 1) if sigma > 0 else 4
    if abs(value) >= 1e5 or (abs(value) < 1e-3 and value != 0):
        return f"{p.name} = {value:.4g} ± {sigma:.2g}{unit}"
    digits = min(digits, 8)
    return f"{p.name} = {value:.{digits}f} ± {sigma:.{digits}f}{unit}"
