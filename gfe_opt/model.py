"""Model files (TOML, SI units): a beam or bar, its material, section, supports and effects.

The file form is a contract (see README, "Model file")::

    name = "ss-steel-beam"
    kind = "beam"            # "beam" (transverse w, rotation) or "bar" (axial u)
    length = 0.575           # m
    elements = 46
    [material]
    E = 206e9                # Pa
    rho = 7800               # kg/m^3
    nu = 0.3
    [section]
    shape = "rectangle"      # or give A (m^2) and I (m^4) directly
    b = 0.009525             # m, breadth
    h = 0.03175              # m, depth
    [supports]
    left = "pinned"          # pinned | clamped | free | sliding (bar: fixed | free)
    right = "pinned"
    [[effects]]              # optional, any number
    effect = "crack"
    position = 0.19
    depth_ratio = 0.5
    found = true             # optional: fitted by gfe-opt (update writes it), not known
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .effects.base import as_float, no_unknown
from .errors import GfeInputError

BEAM_SUPPORTS = ("pinned", "clamped", "free", "sliding")
BAR_SUPPORTS = ("fixed", "free")
BEAM_MASS_MODELS = ("consistent", "higher_order")
BAR_MASS_MODELS = ("consistent", "lumped", "harmonic", "minimum_error")

@dataclass(frozen=True)
class Effect:
    """One instance of a physical effect in a model: its name (a registered
    :class:`~gfe_opt.effects.EffectType`) and physical parameters (SI).  ``found``: fitted
    to the data by gfe-opt (``update`` adds it so), not a known part of the structure the
    user modelled; selection step 10 weighs further effects against what found ones
    explain (not part of equality: the same effect either way)."""

    name: str
    parameters: dict[str, Any]
    found: bool = field(default=False, compare=False)

    def __str__(self) -> str:
        args = ", ".join(f"{k}={_fmt(v)}" for k, v in self.parameters.items())
        return f"{self.name}({args})"


def _fmt(v):
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return f"{v:.6g}" if isinstance(v, float) else str(v)


@dataclass(frozen=True)
class Model:
    """A uniform beam or bar discretised into equal elements, with optional effects.

    Attributes are SI: ``length`` [m], ``E`` [Pa], ``rho`` [kg/m³], ``area`` A [m²],
    ``inertia`` I [m⁴]; ``depth`` h [m] is known for rectangular sections (cracks need it).
    """

    name: str
    kind: str
    length: float
    elements: int
    E: float
    rho: float
    nu: float
    area: float
    inertia: float
    supports: tuple[str, str]
    depth: float | None = None
    breadth: float | None = None
    mass_model: str = "consistent"
    effects: tuple[Effect, ...] = field(default_factory=tuple)
    source: str | None = None

    # -- derived quantities -----------------------------------------------------------
    @property
    def youngs_modulus(self) -> float:
        """E with the effects (a ``material`` effect sets it)."""
        from .effects import effect_type

        E = self.E
        for e in self.effects:
            E = effect_type(e.name).youngs_modulus(e.parameters, E)
        return E

    @property
    def bending_rigidity(self) -> float:
        """EI [N m²] of the undamaged section."""
        return self.youngs_modulus * self.inertia

    @property
    def axial_rigidity(self) -> float:
        """EA [N]."""
        return self.youngs_modulus * self.area

    @property
    def mass_per_length(self) -> float:
        """ρA [kg/m]."""
        return self.rho * self.area

    @property
    def element_length(self) -> float:
        return self.length / self.elements

    @property
    def nodes(self) -> np.ndarray:
        return np.linspace(0.0, self.length, self.elements + 1)

    @property
    def dofs_per_node(self) -> int:
        return 2 if self.kind == "beam" else 1

    @property
    def n_dof(self) -> int:
        return self.dofs_per_node * (self.elements + 1)

    def effects_named(self, name: str) -> list[Effect]:
        return [e for e in self.effects if e.name == name]

    def with_effects(self, effects, check: bool = True) -> "Model":
        """A copy with ``effects`` (an iterable of :class:`Effect`) replacing the present ones,
        validated unless ``check`` is False (fitting loops, whose values lie in bounds)."""
        effects = tuple(effects)
        if check:
            effects = tuple(Effect(e.name, validate_effect(self, e.name, dict(e.parameters),
                                                           self.source or "model",
                                                           f"effects[{i}]."),
                                   e.found)
                            for i, e in enumerate(effects))
            check_repeats(effects, self.source or "model")
        return replace(self, effects=effects)

    def with_elements(self, elements: int) -> "Model":
        return replace(self, elements=int(elements))


# -------------------------------------------------------------------------------------------
# Loading and validation
# -------------------------------------------------------------------------------------------


def load_model(path, *, frames: bool = False) -> Model:
    """Read and validate a model TOML file; raises :class:`GfeInputError` on bad input.
    A plane frame (``kind = "frame"``) is read only where ``frames`` says the caller takes
    one (a :class:`~gfe_opt.frame.FrameModel`); elsewhere it is an input error saying what
    frames can do so far."""
    from .inputs import parse_failure, read_text

    where = str(path)
    text = read_text(path, "model")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise GfeInputError(where, None, f"not valid TOML ({exc})") from None
    except RecursionError:
        raise GfeInputError(where, None, "not valid TOML (nested too deeply)") from None
    except ValueError as exc:   # (an integer of more digits than Python converts)
        raise GfeInputError(where, None, f"not valid TOML ({parse_failure(exc)})") from None
    if isinstance(data, dict) and data.get("kind") == "frame":
        if not frames:
            raise GfeInputError(where, "kind", "a plane frame: gfe-opt computes its modes, "
                                "compares them with a test, diagnoses and updates it so far "
                                "(gfe-opt modes, compare, diagnose, update); batch and demo "
                                "take beams and bars")
        from .frame import frame_from_dict

        return frame_from_dict(data, where)
    return model_from_dict(data, where)


def model_from_dict(data: dict, where: str = "model") -> Model:
    """Build a :class:`Model` from the parsed TOML mapping (same validation as files)."""
    no_unknown(data, {"name", "kind", "length", "elements", "material", "section",
                       "supports", "effects", "mass"}, where, "")
    if not isinstance(data, dict):
        raise GfeInputError(where, None, "must be a table of keys")
    kind = _choice(data, "kind", ("beam", "bar"), where)
    length = _number(data, "length", where, positive=True)
    elements = data.get("elements")
    if elements is None:
        raise GfeInputError(where, "elements", "missing (number of elements, an integer >= 1)")
    if isinstance(elements, bool) or not isinstance(elements, int) or elements < 1:
        raise GfeInputError(where, "elements", f"must be an integer >= 1, got {elements!r}")
    from .inputs import MAX_ELEMENTS

    if kind in MAX_ELEMENTS and elements > MAX_ELEMENTS[kind]:
        raise GfeInputError(where, "elements", f"{elements} is above {MAX_ELEMENTS[kind]}, the "
                            f"finest {kind} mesh gfe-opt solves (README \"Limits\"); a few "
                            "thousand elements resolve the first modes to 1e-9")
    name = data.get("name", Path(where).stem)
    if not isinstance(name, str):
        raise GfeInputError(where, "name", f"must be a string, got {name!r}")

    material = _table(data, "material", where)
    no_unknown(material, {"E", "rho", "nu"}, where, "material.")
    E = _number(material, "E", where, positive=True, prefix="material.")
    rho = _number(material, "rho", where, positive=True, prefix="material.")
    nu = _number(material, "nu", where, prefix="material.", default=0.3)
    check_poisson(nu, where, "material.nu")

    section = _table(data, "section", where)
    depth = breadth = None
    shape = section.get("shape")
    if shape is not None:
        if shape != "rectangle":
            raise GfeInputError(where, "section.shape",
                                f"unknown shape {shape!r} (known: 'rectangle', or give A and I)")
        no_unknown(section, {"shape", "b", "h"}, where, "section.")
        breadth = _number(section, "b", where, positive=True, prefix="section.")
        depth = _number(section, "h", where, positive=True, prefix="section.")
        _check_proportions(length, breadth, depth, where)  # before b·h³ can overflow
        area, inertia = breadth * depth, breadth * depth**3 / 12.0
    else:
        no_unknown(section, {"A", "I", "h"}, where, "section.")
        area = _number(section, "A", where, positive=True, prefix="section.")
        need_i = kind == "beam"
        inertia = _number(section, "I", where, positive=True, prefix="section.",
                          default=None if need_i else 0.0)
        if "h" in section:
            depth = _number(section, "h", where, positive=True, prefix="section.")

    supports_tbl = _table(data, "supports", where)
    no_unknown(supports_tbl, {"left", "right"}, where, "supports.")
    allowed = BEAM_SUPPORTS if kind == "beam" else BAR_SUPPORTS
    supports = tuple(_choice(supports_tbl, side, allowed, where, prefix="supports.")
                     for side in ("left", "right"))

    mass_models = BEAM_MASS_MODELS if kind == "beam" else BAR_MASS_MODELS
    mass_model = data.get("mass", "consistent")
    if mass_model not in mass_models:
        raise GfeInputError(where, "mass", f"unknown mass model {mass_model!r} "
                            f"(known for a {kind}: {', '.join(mass_models)})")

    _check_proportions(length, breadth, depth, where)
    check_section_size(area, inertia if kind == "beam" else None, length, kind, where,
                       "section")
    check_stiffness_density(E, rho, where, "material.")
    model = Model(name=name, kind=kind, length=length, elements=elements, E=E, rho=rho, nu=nu,
                  area=area, inertia=inertia, supports=supports, depth=depth, breadth=breadth,
                  mass_model=mass_model, source=where)

    effects_raw = data.get("effects", [])
    if not isinstance(effects_raw, list):
        raise GfeInputError(where, "effects", "must be an array of tables ([[effects]])")
    effects = []
    for i, raw in enumerate(effects_raw):
        if not isinstance(raw, dict):
            raise GfeInputError(where, f"effects[{i}]", "must be a table")
        raw = dict(raw)
        name_ = raw.pop("effect", None)
        if name_ is None:
            raise GfeInputError(where, f"effects[{i}].effect", "missing (the effect's name)")
        found = pop_found(raw, where, f"effects[{i}].")
        effects.append(Effect(name_, validate_effect(model, name_, raw, where, f"effects[{i}]."),
                              found))
    check_repeats(effects, where)
    return replace(model, effects=tuple(effects))


def check_poisson(nu, where, key) -> None:
    if not -1.0 < nu < 0.5:
        raise GfeInputError(where, key, f"Poisson's ratio must lie in (-1, 0.5), got {nu}")


def check_stiffness_density(E, rho, where, prefix) -> None:
    """E and ρ in SI units (a wrong unit, not a material, otherwise)."""
    if not 1e7 <= E <= 1e13:
        raise GfeInputError(where, prefix + "E", f"{E:g} Pa is outside 1e7..1e13 Pa: give E in "
                            "Pa (206e9 for steel, not 206 or 206e3)")
    if not 100.0 <= rho <= 30000.0:
        raise GfeInputError(where, prefix + "rho", f"{rho:g} kg/m^3 is outside 100..30000: "
                            "give the density in kg/m^3")


def check_section_size(area, inertia, length, what, where, key) -> None:
    """√A and (with ``inertia``) √(I/A) between 1e-5 (1e-6) and 1 of a ``length`` m long
    ``what`` (a section in another unit, otherwise)."""
    size = math.sqrt(area) / length if math.isfinite(area) else math.inf
    gyration = math.sqrt(inertia / area) / length if inertia is not None and size > 0 else 0.5
    if not (1e-5 <= size <= 1.0 and 1e-6 <= gyration <= 1.0):
        raise GfeInputError(where, key, f"A = {area:g} m^2 and I = {inertia or 0.0:g} m^4 do "
                            f"not fit a {length:g} m long {what} (√A and √(I/A) between 1e-5 "
                            "and 1 of the length): is the section in metres?")


def _check_proportions(length, breadth, depth, where) -> None:
    """Plausible sizes in metres: a length of 1e-6..1e4 m, length / depth 1..2000, length /
    breadth 1..1e5 (a wrong unit, not a beam, otherwise)."""
    if not 1e-6 <= length <= 1e4:
        raise GfeInputError(where, "length", f"{length:g} m is outside 1e-6..1e4 m: give the "
                            "length in metres")
    if depth is not None and not 1.0 <= length / depth <= 2000.0:
        raise GfeInputError(where, "length", f"length / depth = {length / depth:.4g} is not a "
                            "beam or bar (expected 1 to 2000): are length and section in the "
                            "same unit (metres)?")
    if breadth is not None and not 1.0 <= length / breadth <= 1e5:
        raise GfeInputError(where, "section.b", f"length / breadth = {length / breadth:.4g} is "
                            "not a beam (expected 1 to 1e5): is the section in metres?")


def validate_effect(model: Model, name: str, params: dict, where: str, prefix: str = "",
                    partial: bool = False) -> dict:
    """Check an effect's name and parameters (its :class:`~gfe_opt.effects.EffectType`
    says how); return them.  ``partial``: only the parameters given are required."""
    from .effects import effect_type

    return effect_type(name, where, f"{prefix}effect").validate(model, params, where, prefix,
                                                                 partial)


def parse_effect(text: str, model: Model, where: str = "--add") -> Effect:
    """``crack`` or ``crack:position=0.2,depth_ratio=0.4`` -> Effect.  Every value given is
    checked against its allowed range (partial sets are starting values); a repeated or
    unknown key is an error.  Lists (profiles) separate values by ``;``."""
    from .effects import effect_type

    name, _, rest = text.partition(":")
    kind = effect_type(name.strip(), where, None)
    # on a frame the place too (crack:member=beam)
    keys = [p.name for p in (kind.all_parameters if model.kind == "frame" else
                             kind.parameters)]
    params = {}
    for item in rest.split(",") if rest.strip() else []:
        key, eq, value = (part.strip() for part in item.partition("="))
        if not eq or not value:
            raise GfeInputError(where, text, f"expected key=value, got {item!r}")
        if key not in keys:
            try:
                no_unknown({key: None}, set(keys), where, "")
            except GfeInputError as exc:
                raise GfeInputError(where, text, f"{key}: {exc.problem} ({name} takes "
                                    f"{', '.join(keys)})") from None
        if key in params:
            raise GfeInputError(where, text, f"{key} is given twice")
        rule = kind.parameter(key).rule
        if rule == "choice":
            params[key] = value
        else:
            try:
                numbers = [float(v) for v in value.split(";")]
            except ValueError:
                raise GfeInputError(where, text, f"{key} must be a number, got {value!r}"
                                    ) from None
            params[key] = numbers if rule in ("knots", "ratios") else (
                numbers[0] if len(numbers) == 1 else value)
    params = validate_effect(model, kind.name, params, f"{where} {text}", "", partial=True)
    return Effect(kind.name, params)


def check_repeats(effects, where: str, prefix: str = "effects") -> None:
    """A global effect (``material``, ``shear``, ...) may appear once; local ones repeat."""
    from .effects import effect_type

    seen = {}
    for i, e in enumerate(effects):
        if e.name in seen and not effect_type(e.name).local:
            raise GfeInputError(where, f"{prefix}[{i}].effect", f"{e.name!r} appears twice "
                                f"(also {prefix}[{seen[e.name]}]): a global effect is one per "
                                "model; local effects (crack, point_mass, point_spring, "
                                "section_loss, ...) may repeat")
        seen.setdefault(e.name, i)


def _number(tbl, key, where, positive=False, prefix="", default=None):
    if key not in tbl:
        if default is not None:
            return default
        raise GfeInputError(where, prefix + key, "missing")
    value = as_float(tbl[key], where, prefix + key)
    if positive and value <= 0:
        raise GfeInputError(where, prefix + key, f"must be > 0, got {value:g}")
    return value


def _choice(tbl, key, allowed, where, prefix=""):
    if key not in tbl:
        raise GfeInputError(where, prefix + key, f"missing (one of {', '.join(allowed)})")
    value = tbl[key]
    if value not in allowed:
        raise GfeInputError(where, prefix + key,
                            f"unknown value {value!r} (one of {', '.join(allowed)})")
    return value


def _table(data, key, where):
    tbl = data.get(key)
    if tbl is None:
        raise GfeInputError(where, key, f"missing [{key}] table")
    if not isinstance(tbl, dict):
        raise GfeInputError(where, key, "must be a table")
    return tbl


def model_to_dict(model: Model) -> dict:
    """The TOML mapping of a model (inverse of :func:`model_from_dict`; a plane frame's of
    :func:`gfe_opt.frame.frame_from_dict`)."""
    if model.kind == "frame":
        from .frame import frame_to_dict

        return frame_to_dict(model)
    data = {"name": model.name, "kind": model.kind, "length": model.length,
            "elements": model.elements}
    if model.mass_model != "consistent":
        data["mass"] = model.mass_model
    data["material"] = {"E": model.E, "rho": model.rho, "nu": model.nu}
    if model.breadth is not None and model.depth is not None:
        data["section"] = {"shape": "rectangle", "b": model.breadth, "h": model.depth}
    else:
        data["section"] = {"A": model.area}
        if model.kind != "bar" or model.inertia > 0:   # (a bar's file may leave I out)
            data["section"]["I"] = model.inertia
        if model.depth is not None:
            data["section"]["h"] = model.depth
    data["supports"] = {"left": model.supports[0], "right": model.supports[1]}
    if model.effects:
        data["effects"] = [effect_to_dict(e) for e in model.effects]
    return data


def effect_to_dict(effect: Effect) -> dict:
    """An effect as a model file writes it: ``{"effect": name, **parameters}``, and
    ``found = true`` when gfe-opt fitted it (:attr:`Effect.found`)."""
    return {"effect": effect.name, **effect.parameters, **({"found": True} if effect.found
                                                           else {})}


def pop_found(raw: dict, where: str, prefix: str) -> bool:
    """Take an effect table's optional ``found`` flag out of ``raw`` (true or false)."""
    found = raw.pop("found", False)
    if not isinstance(found, bool):
        raise GfeInputError(where, prefix + "found", f"must be true or false, got {found!r}")
    return found


def save_model(model: Model, path, *, force: bool = False, protect=()) -> None:
    """Write ``model`` as TOML atomically.  Refuses to overwrite any path in ``protect``
    (e.g. the input) and, unless ``force``, any existing file."""
    import tomli_w

    from .outputs import atomic_write, check_output_path

    check_output_path(path, force, protect, kind="model")
    text = tomli_w.dumps(model_to_dict(model))
    atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"), replace=force)
