r"""Plane frames of beam–bar members (issue 24, first part): model files, assembly, modes.

A member is the paper's generic beam element (bending, eq. 11 with the Euler–Bernoulli
parameters k_ww = 12EI, k_wθ = 6EI, k_θθ = 4EI, or those of the exact static element of
EI(x) where a crack changes it) together with its generic bar element (axial, eq. 2 with
k = EA), in the member's own axes; rotated into global axes by
:math:`T = \mathrm{diag}(R, R)`, :math:`R = [[c, s, 0], [-s, c, 0], [0, 0, 1]]`.  Consistent
masses (bar β = 1/6, beam m11 = 13/35 ...).  Every node has three DOFs (u, v, θ) in global
axes; members meeting at a joint share them (a rigid joint) unless a ``joint_spring`` gives
the member's end its own rotation, tied to the joint's by ½ k (θ_m − θ_J)².

Model file (``kind = "frame"``; README "Plane frames")::

    name = "portal"
    kind = "frame"
    [material]   E, rho, nu          (the default of every member)
    [section]    shape = "rectangle", b, h  (h in the frame's plane) | A, I [, h]
    [[nodes]]    id, x, y            (m)
    [[members]]  id, from, to, elements [, [members.material], [members.section]]
    [[supports]] node, type = "clamped" | "pinned" | "roller-x" | "roller-y"
    [[effects]]  effect = "crack": member, position (m from its start node), depth_ratio
                 effect = "joint_spring": node, member, stiffness (N m/rad)
                 effect = "support_spring": node, stiffness (N m/rad; a support's rotation)
                 effect = "support_translation": node, direction = "x" | "y", stiffness (N/m)
                 effect = "point_mass": member, position, mass (kg)
                 effect = "attached_body": member, position, mass (kg), inertia (kg m²;
                          a body that moves in x and y and turns with the frame there)
                 effect = "rotary_inertia": member, position, inertia (kg m²)
                 effect = "point_spring": member, position, direction = "x" | "y",
                          stiffness (N/m; a spring to ground along x or y there)
                 effect = "axial_stiffness": member, ratio;  effect = "material": E (Pa)
                 effect = "section_loss": member, position (the zone's centre), length (m),
                          stiffness_ratio (EI), mass_ratio (ρA and EA)
                 effect = "shear": shear_rigidity (N; κGA of the first member, every
                          member's κGA its GA over the first's times it: Timoshenko members)
                 effect = "member_shear": member, shear_rigidity (N; that member
                          Timoshenko with its own κGA, beside a shear its κ not the others')
                 effect = "axial_load": member, tension (N);  "foundation": member,
                          stiffness (N/m²)
                 effect = "stiffness_profile" | "mass_profile": member, x (knots, m from
                          its start node), ratio (EI or ρA over the member's at each)

Frames have modes (:func:`frame_modes`, ``gfe-opt modes``), are compared with tests
(:mod:`gfe_opt.frame_data`), go through the beam's fits (:class:`FrameDiscretisation`:
``update --add joint_spring``) and its diagnosis (:mod:`gfe_opt.diagnosis`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .effects.axial_load import slope_gram
from .errors import GfeInputError

SUPPORT_TYPES = {"clamped": (0, 1, 2), "pinned": (0, 1), "roller-x": (1,), "roller-y": (0,)}
FRAME_EFFECTS = ("crack", "joint_spring", "support_spring", "support_translation",
                 "point_mass", "point_spring", "axial_stiffness", "material", "section_loss",
                 "axial_load", "foundation", "shear", "stiffness_profile", "member_shear",
                 "mass_profile", "rotary_inertia", "attached_body")
#: the fixity each support effect replaces by a spring: rotation; translation along x / y
RELEASES = {"support_spring": 2, "x": 0, "y": 1}


@dataclass(frozen=True)
class Member:
    """One straight member: its end nodes (ids), mesh and section."""

    id: str
    start: str
    end: str
    elements: int
    E: float
    rho: float
    nu: float
    area: float
    inertia: float
    depth: float | None = None


@dataclass(frozen=True)
class FrameModel:
    """A plane frame: named nodes (x, y in m), members between them, supports, effects
    (:class:`~gfe_opt.model.Effect`, validated)."""

    name: str
    nodes: dict
    members: tuple
    supports: tuple          # (node id, type)
    effects: tuple = ()      # Effect instances (a dict {"effect": name, ...} is taken too)
    source: str | None = None
    kind: str = field(default="frame")

    def __post_init__(self):
        from .model import Effect

        object.__setattr__(self, "effects", tuple(
            Effect(e["effect"], {k: v for k, v in e.items() if k != "effect"})
            if isinstance(e, dict) else e for e in self.effects))

    def with_effects(self, effects, check: bool = True) -> FrameModel:
        """The same frame with ``effects`` (validated unless ``check`` is false)."""
        out = replace(self, effects=tuple(effects))
        if check:
            for i, e in enumerate(out.effects):
                _effect(out, {"effect": e.name, **e.parameters}, out.source or out.name,
                        f"effects[{i}].")
            check_repeats(out.effects, out.source or out.name)
        return out

    @property
    def elements(self) -> int:
        return self.n_elements

    @property
    def E(self) -> float:
        """The frame's reference Young's modulus, its first member's (the file's default
        material unless that member has its own): what a ``material`` effect's E replaces,
        every member's modulus scaled by the same factor."""
        return self.members[0].E

    @property
    def stiffness_factor(self) -> float:
        """Every member's E over its modelled E: a ``material`` effect's E over :attr:`E`
        (1 without one)."""
        return next((float(e.parameters["E"]) / self.E for e in self.effects
                     if e.name == "material" and "E" in e.parameters), 1.0)

    @property
    def raw_effects(self) -> list[dict]:
        """The effects as the file writes them: ``{"effect": name, **parameters}``."""
        return [{"effect": e.name, **e.parameters} for e in self.effects]

    def member(self, member_id: str) -> Member:
        return next(m for m in self.members if m.id == member_id)

    def member_length(self, member: Member) -> float:
        (x0, y0), (x1, y1) = self.nodes[member.start], self.nodes[member.end]
        return math.hypot(x1 - x0, y1 - y0)

    @property
    def n_elements(self) -> int:
        return sum(m.elements for m in self.members)


# ------------------------------------------------------------------------------------------
# reading
# ------------------------------------------------------------------------------------------


def frame_from_dict(data: dict, where: str = "model") -> FrameModel:
    """A :class:`FrameModel` from the parsed TOML mapping; :class:`GfeInputError` (one line:
    file, key, what is wrong) on bad input."""
    from .effects.base import no_unknown
    from .model import _number, check_section_size

    no_unknown(data, {"name", "kind", "material", "section", "nodes", "members", "supports",
                      "effects"}, where, "")
    name = data.get("name", where.rsplit("/", 1)[-1].rsplit(".", 1)[0])
    if not isinstance(name, str):
        raise GfeInputError(where, "name", f"must be a string, got {name!r}")
    # the defaults of every member; optional where each member has its own
    material = _material(data.get("material", {}), where, "material.", None)
    section = _section(data.get("section", {}), where, "section.", None)

    nodes = {}
    for i, raw in enumerate(_array(data, "nodes", where)):
        key = f"nodes[{i}]."
        no_unknown(raw, {"id", "x", "y"}, where, key)
        node_id = _ident(raw, "id", where, key)
        if node_id in nodes:
            raise GfeInputError(where, key + "id", f"{node_id!r} is used by another node")
        nodes[node_id] = (_number(raw, "x", where, prefix=key), _number(raw, "y", where,
                                                                        prefix=key))
    if len(nodes) < 2:
        raise GfeInputError(where, "nodes", "a frame needs at least two nodes")

    from .inputs import MAX_ELEMENTS

    members, ids = [], set()
    for i, raw in enumerate(_array(data, "members", where)):
        key = f"members[{i}]."
        no_unknown(raw, {"id", "from", "to", "elements", "material", "section"}, where, key)
        member_id = _ident(raw, "id", where, key)
        if member_id in ids:
            raise GfeInputError(where, key + "id", f"{member_id!r} is used by another member")
        ids.add(member_id)
        ends = [_ident(raw, k, where, key) for k in ("from", "to")]
        for k, node in zip(("from", "to"), ends):
            if node not in nodes:
                raise GfeInputError(where, key + k, f"no node {node!r} (nodes: "
                                    f"{', '.join(nodes)})")
        (x0, y0), (x1, y1) = nodes[ends[0]], nodes[ends[1]]
        length = math.hypot(x1 - x0, y1 - y0)
        if ends[0] == ends[1] or length == 0.0:
            raise GfeInputError(where, key + "to", "the member's ends are at the same place")
        n = raw.get("elements")
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise GfeInputError(where, key + "elements", f"must be an integer >= 1, got {n!r}")
        if n > MAX_ELEMENTS["beam"]:
            raise GfeInputError(where, key + "elements", f"{n} is above "
                                f"{MAX_ELEMENTS['beam']}, the finest beam mesh gfe-opt solves")
        mat = _material(raw.get("material", {}), where, key + "material.", material)
        sec = _section(raw.get("section", {}), where, key + "section.", section)
        if mat is None:
            raise GfeInputError(where, key + "material", "no material: give [material] or "
                                "[members.material]")
        if sec is None:
            raise GfeInputError(where, key + "section", "no section: give [section] or "
                                "[members.section]")
        check_section_size(sec[0], sec[1], length, "member", where, key + "section")
        members.append(Member(member_id, ends[0], ends[1], n, *mat, *sec))
    if not members:
        raise GfeInputError(where, "members", "a frame needs at least one member")
    used = {m.start for m in members} | {m.end for m in members}
    loose = [n for n in nodes if n not in used]
    if loose:
        raise GfeInputError(where, "nodes", f"node {loose[0]!r} is on no member")

    supports, held = [], set()
    for i, raw in enumerate(data.get("supports", []) if isinstance(data.get("supports", []),
                                                                  list) else [None]):
        key = f"supports[{i}]."
        if not isinstance(raw, dict):
            raise GfeInputError(where, "supports", "must be an array of tables ([[supports]])")
        no_unknown(raw, {"node", "type"}, where, key)
        node = _ident(raw, "node", where, key)
        if node not in nodes:
            raise GfeInputError(where, key + "node", f"no node {node!r}")
        if node in held:
            raise GfeInputError(where, key + "node", f"node {node!r} is supported twice")
        held.add(node)
        kind = raw.get("type")
        if kind not in SUPPORT_TYPES:
            raise GfeInputError(where, key + "type", f"unknown support {kind!r} (known: "
                                f"{', '.join(SUPPORT_TYPES)})")
        supports.append((node, kind))

    model = FrameModel(name=name, nodes=nodes, members=tuple(members),
                       supports=tuple(supports), source=where)
    from .model import pop_found

    effects = []
    for i, raw in enumerate(_array(data, "effects", where, required=False)):
        raw = dict(raw)   # (a table: _array checks)
        found = pop_found(raw, where, f"effects[{i}].")
        effects.append(replace(_effect(model, raw, where, f"effects[{i}]."), found=found))
    effects = tuple(effects)
    check_repeats(effects, where)
    return FrameModel(name=name, nodes=nodes, members=tuple(members),
                      supports=tuple(supports), effects=effects, source=where)


def _array(data, key, where, required=True) -> list:
    raw = data.get(key)
    if raw is None and not required:
        return []
    if not isinstance(raw, list) or not raw or not all(isinstance(r, dict) for r in raw):
        raise GfeInputError(where, key, f"{'missing: ' if raw is None else ''}must be an array "
                            f"of tables ([[{key}]])")
    return raw


def _ident(raw, key, where, prefix) -> str:
    value = raw.get(key)
    if not isinstance(value, str) or not value:
        raise GfeInputError(where, prefix + key, f"must be a name (a string), got {value!r}")
    return value


def _material(tbl, where, prefix, default):
    """(E, rho, nu), each missing key from ``default``; None if neither gives E and rho."""
    from .effects.base import no_unknown
    from .model import _number, check_poisson, check_stiffness_density

    if not isinstance(tbl, dict):
        raise GfeInputError(where, prefix.rstrip("."), "must be a table")
    no_unknown(tbl, {"E", "rho", "nu"}, where, prefix)
    base = dict(zip(("E", "rho", "nu"), default)) if default else {"nu": 0.3}
    if not tbl and default is None:
        return None
    out = {**base, **{k: _number(tbl, k, where, positive=k != "nu", prefix=prefix)
                      for k in tbl}}
    if "E" not in out or "rho" not in out:
        missing = "E" if "E" not in out else "rho"
        raise GfeInputError(where, prefix + missing, "missing")
    check_stiffness_density(out["E"], out["rho"], where, prefix)
    check_poisson(out["nu"], where, prefix + "nu")
    return out["E"], out["rho"], out["nu"]


def _section(tbl, where, prefix, default):
    """(A, I, h or None); a member's table replaces the default section whole."""
    from .effects.base import no_unknown
    from .model import _number

    if not isinstance(tbl, dict):
        raise GfeInputError(where, prefix.rstrip("."), "must be a table")
    if not tbl:
        return default
    shape = tbl.get("shape")
    if shape is not None:
        if shape != "rectangle":
            raise GfeInputError(where, prefix + "shape", f"unknown shape {shape!r} (known: "
                                "'rectangle', or give A and I)")
        no_unknown(tbl, {"shape", "b", "h"}, where, prefix)
        b = _number(tbl, "b", where, positive=True, prefix=prefix)
        h = _number(tbl, "h", where, positive=True, prefix=prefix)
        return b * h, b * h**3 / 12.0, h
    no_unknown(tbl, {"A", "I", "h"}, where, prefix)
    h = _number(tbl, "h", where, positive=True, prefix=prefix) if "h" in tbl else None
    return (_number(tbl, "A", where, positive=True, prefix=prefix),
            _number(tbl, "I", where, positive=True, prefix=prefix), h)


def _effect(model: FrameModel, raw: dict, where: str, prefix: str) -> dict:
    """One effect of a frame file, validated: a crack on a member, a joint spring."""
    from .effects.base import no_unknown
    from .model import _number

    name = raw.get("effect")
    if name not in FRAME_EFFECTS:
        raise GfeInputError(where, prefix + "effect", f"{name!r} is not an effect frames take "
                            f"yet (known: {', '.join(FRAME_EFFECTS)})")
    if name in ("support_spring", "support_translation"):
        return _support_effect(model, raw, where, prefix)
    if name == "material":   # every member's E scaled: E is the first member's new one
        no_unknown(raw, {"effect", "E"}, where, prefix)
        from .effects import effect_type

        E = _number(raw, "E", where, positive=True, prefix=prefix)
        effect_type(name).check(model, {"E": E}, where, prefix)   # the beams' range, one rule
        return _as_effect({"effect": name, "E": E})
    if name == "shear":   # every member Timoshenko: κGA is the first member's
        no_unknown(raw, {"effect", "shear_rigidity"}, where, prefix)
        return _as_effect({"effect": name, "shear_rigidity": _number(
            raw, "shear_rigidity", where, positive=True, prefix=prefix)})
    member_id = _ident(raw, "member", where, prefix)
    if member_id not in {m.id for m in model.members}:
        raise GfeInputError(where, prefix + "member", f"no member {member_id!r}")
    member = model.member(member_id)
    if name in ("point_mass", "attached_body", "rotary_inertia"):
        return _point_mass(model, member, raw, where, prefix, name)
    if name == "point_spring":
        return _point_spring(model, member, raw, where, prefix)
    if name == "axial_stiffness":
        no_unknown(raw, {"effect", "member", "ratio"}, where, prefix)
        ratio = _number(raw, "ratio", where, positive=True, prefix=prefix)
        if ratio > 10.0:
            raise GfeInputError(where, prefix + "ratio", f"must lie in (0, 10] (EA of the "
                                f"member over the modelled), got {ratio:g}")
        return _as_effect({"effect": name, "member": member_id, "ratio": ratio})
    if name == "section_loss":
        return _section_loss(model, member, raw, where, prefix)
    if name in ("stiffness_profile", "mass_profile"):   # EI(x) or ρA(x) along the member
        from .effects import effect_type

        no_unknown(raw, {"effect", "member", "x", "ratio"}, where, prefix)
        kind = effect_type(name)
        for key in ("x", "ratio"):
            if key not in raw:
                raise GfeInputError(where, prefix + key, f"missing (a {name} on a frame "
                                    "needs member, x and ratio)")
        x = kind.parameter("x").check(raw["x"], model, where, prefix + "x",
                                      length=model.member_length(member))
        ratio = kind.parameter("ratio").check(raw["ratio"], model, where, prefix + "ratio")
        kind.check(model, {"x": x, "ratio": ratio}, where, prefix)
        return _as_effect({"effect": name, "member": member_id, "x": x, "ratio": ratio})
    if name == "foundation":
        no_unknown(raw, {"effect", "member", "stiffness"}, where, prefix)
        return _as_effect({"effect": name, "member": member_id, "stiffness": _number(
            raw, "stiffness", where, positive=True, prefix=prefix)})
    if name == "member_shear":
        no_unknown(raw, {"effect", "member", "shear_rigidity"}, where, prefix)
        return _as_effect({"effect": name, "member": member_id, "shear_rigidity": _number(
            raw, "shear_rigidity", where, positive=True, prefix=prefix)})
    if name == "axial_load":
        no_unknown(raw, {"effect", "member", "tension"}, where, prefix)
        return _as_effect({"effect": name, "member": member_id,
                           "tension": _number(raw, "tension", where, prefix=prefix)})
    if name == "crack":
        no_unknown(raw, {"effect", "member", "position", "depth_ratio"}, where, prefix)
        length = model.member_length(member)
        x = _number(raw, "position", where, prefix=prefix)
        if not 0.0 < x < length:
            raise GfeInputError(where, prefix + "position", f"must lie inside the member "
                                f"(0, {length:g}) m, got {x:g}")
        ratio = _number(raw, "depth_ratio", where, prefix=prefix)
        if not 0.0 < ratio <= 0.95:
            raise GfeInputError(where, prefix + "depth_ratio", "must lie between 0 and 0.95 "
                                f"(a/d), got {ratio:g}")
        if member.depth is None:
            raise GfeInputError(where, prefix + "effect", "a crack needs the member's section "
                                "depth h")
        return _as_effect({"effect": name, "member": member_id, "position": x,
                           "depth_ratio": ratio})
    no_unknown(raw, {"effect", "member", "node", "stiffness"}, where, prefix)
    node = _ident(raw, "node", where, prefix)
    if node not in (member.start, member.end):
        raise GfeInputError(where, prefix + "node", f"member {member_id!r} does not end at "
                            f"node {node!r} (its ends: {member.start}, {member.end})")
    k = _number(raw, "stiffness", where, positive=True, prefix=prefix)
    return _as_effect({"effect": name, "member": member_id, "node": node, "stiffness": k})


def _section_loss(model: FrameModel, member: Member, raw: dict, where: str, prefix: str):
    """A zone of a member, ``position`` (its centre, m from the member's start) ± ``length``
    / 2, that lies on the member (it may reach a joint), with its EI and ρA ratios."""
    from .effects import effect_type
    from .effects.base import no_unknown
    from .model import _number

    keys = ("position", "length", "stiffness_ratio", "mass_ratio")
    no_unknown(raw, {"effect", "member", *keys}, where, prefix)
    span = model.member_length(member)
    c = _number(raw, "position", where, prefix=prefix)
    ell = _number(raw, "length", where, positive=True, prefix=prefix)
    if ell > span * (1 + 1e-12):
        raise GfeInputError(where, prefix + "length", f"{ell:g} m is longer than member "
                            f"{member.id!r} ({span:g} m)")
    # a fitted zone is cut to the member (to_physical), its edges there to rounding
    if c - ell / 2 < -1e-9 * span or c + ell / 2 > span * (1 + 1e-9):
        raise GfeInputError(where, prefix + "position", f"the zone {c - ell / 2:g} to "
                            f"{c + ell / 2:g} m must lie on member {member.id!r} (0 to "
                            f"{span:g} m)")
    kind = effect_type("section_loss")
    out = {"effect": "section_loss", "member": member.id, "position": c, "length": ell}
    for key in keys[2:]:   # the beams' ranges, one rule
        out[key] = kind.parameter(key).check(_number(raw, key, where, prefix=prefix), model,
                                             where, prefix + key)
    return _as_effect(out)


def _member_place(model: FrameModel, member: Member, raw: dict, where: str, prefix: str):
    """A point effect's ``position`` (m from the member's start), checked to lie on the
    member, and the node it sits on (an end: the joint there; None between them)."""
    from .model import _number

    length = model.member_length(member)
    x = _number(raw, "position", where, prefix=prefix)
    if not 0.0 <= x <= length:
        raise GfeInputError(where, prefix + "position", f"must lie on the member [0, "
                            f"{length:g}] m, got {x:g}")
    return x, (member.start if x == 0.0 else member.end if x == length else None)


def _point_mass(model: FrameModel, member: Member, raw: dict, where: str, prefix: str,
                name: str = "point_mass"):
    """A mass on a member at ``position`` (m from its start; an end is the joint there),
    held by neither support translation of its place; a body (``attached_body``: its mass
    and its rotary inertia) or a body's rotary inertia alone (``rotary_inertia``), held
    by no support of its rotation."""
    from .effects.base import no_unknown
    from .model import _number

    keys = {"mass"} if name == "point_mass" else {"inertia"} if name == "rotary_inertia" \
        else {"mass", "inertia"}
    no_unknown(raw, {"effect", "member", "position", *keys}, where, prefix)
    x, end = _member_place(model, member, raw, where, prefix)
    out = {"effect": name, "member": member.id, "position": x}
    for key in ("mass", "inertia"):
        if key in keys:
            out[key] = _number(raw, key, where, positive=True, prefix=prefix)
    support = dict(model.supports).get(end)
    held = set(SUPPORT_TYPES.get(support, ()))
    if "mass" in keys and {0, 1} <= held:
        raise GfeInputError(where, prefix + "position", f"node {end!r} is a {support} support "
                            "that holds the structure still: a mass there does nothing" + (
                                " (for the body's rotary inertia alone: rotary_inertia)"
                                if name == "attached_body" and 2 not in held else ""))
    if name == "rotary_inertia" and 2 in held:
        raise GfeInputError(where, prefix + "position", f"node {end!r} is a {support} support "
                            "that holds the rotation still: a rotary inertia there does "
                            "nothing")
    return _as_effect(out)


def _point_spring(model: FrameModel, member: Member, raw: dict, where: str, prefix: str):
    """A translational spring to ground on a member at ``position`` (m from its start; an
    end is the joint there) along ``direction`` x or y (a wall or a brace it leans on, an
    attachment), where no support holds that translation already."""
    from .effects.base import no_unknown
    from .model import _number

    no_unknown(raw, {"effect", "member", "position", "direction", "stiffness"}, where, prefix)
    x, end = _member_place(model, member, raw, where, prefix)
    d = raw.get("direction")
    if d not in ("x", "y"):
        raise GfeInputError(where, prefix + "direction", f"must be \"x\" or \"y\", got {d!r}")
    k = _number(raw, "stiffness", where, positive=True, prefix=prefix)
    support = dict(model.supports).get(end)
    if RELEASES[d] in SUPPORT_TYPES.get(support, ()):
        raise GfeInputError(where, prefix + "position", f"node {end!r} is a {support} support "
                            f"that holds its translation along {d}: a spring there does "
                            "nothing (a support that gives is a support_translation)")
    return _as_effect({"effect": "point_spring", "member": member.id, "position": x,
                       "direction": d, "stiffness": k})


def _support_effect(model: FrameModel, raw: dict, where: str, prefix: str) -> dict:
    """A support that gives: its rotation (``support_spring``, N m/rad) or its translation
    along ``direction`` x or y (``support_translation``, N/m) held by a spring instead of
    fixed; the node's support must fix that DOF."""
    from .effects.base import no_unknown
    from .model import _number

    name = raw["effect"]
    keys = {"effect", "node", "stiffness"} | ({"direction"} if name == "support_translation"
                                              else set())
    no_unknown(raw, keys, where, prefix)
    node = _ident(raw, "node", where, prefix)
    held = dict(model.supports).get(node)
    if held is None:
        raise GfeInputError(where, prefix + "node", f"node {node!r} has no support to give "
                            f"(supported: {', '.join(n for n, _ in model.supports) or 'none'})")
    out = {"effect": name, "node": node}
    if name == "support_translation":
        d = raw.get("direction")
        if d not in ("x", "y"):
            raise GfeInputError(where, prefix + "direction", f"must be \"x\" or \"y\", got "
                                f"{d!r}")
        out["direction"] = d
    dof = RELEASES[out.get("direction", name)]
    if dof not in SUPPORT_TYPES[held]:
        what = "rotation" if dof == 2 else f"translation along {out['direction']}"
        raise GfeInputError(where, prefix + "node", f"the {held} support at {node!r} does "
                            f"not fix its {what}")
    out["stiffness"] = _number(raw, "stiffness", where, positive=True, prefix=prefix)
    return _as_effect(out)


def _as_effect(raw: dict):
    from .model import Effect

    return Effect(raw["effect"], {k: v for k, v in raw.items() if k != "effect"})


def check_repeats(effects, where) -> None:
    """One joint spring a member end, one support effect a node and direction, one axial
    stiffness, one axial load and one foundation a member, one material."""
    seen = {}
    for i, e in enumerate(effects):
        key = _effect_key(e)
        if key is not None and key in seen:
            raise GfeInputError(where, f"effects[{i}]", f"repeats effects[{seen[key]}] (one "
                                f"{e.name} at one place)")
        seen.setdefault(key, i)


def _effect_key(effect) -> tuple | None:
    """What two instances of a frame effect may not share (a crack may repeat)."""
    e = {"effect": effect.name, **effect.parameters}
    if e["effect"] in ("crack", "point_mass", "point_spring", "section_loss", "attached_body",
                       "rotary_inertia"):
        return None
    if e["effect"] in ("material", "shear"):
        return (e["effect"],)
    if e["effect"] in ("axial_stiffness", "axial_load", "foundation", "stiffness_profile",
                       "member_shear", "mass_profile"):
        return (e["effect"], e["member"]) if "member" in e else None
    if "node" not in e:
        return None   # --add without a place: every place is tried
    if e["effect"] == "joint_spring":
        return ("joint_spring", e["member"], e["node"])
    return (e["effect"], e["node"], e.get("direction"))


def frame_to_dict(model: FrameModel) -> dict:
    """The TOML mapping of a frame (inverse of :func:`frame_from_dict`): every member with
    its own material and section (exactly as read, defaults resolved)."""
    def section(m):
        out = {"A": m.area, "I": m.inertia}
        if m.depth is not None:
            out["h"] = m.depth
        return out

    data = {"name": model.name, "kind": "frame",
            "nodes": [{"id": n, "x": x, "y": y} for n, (x, y) in model.nodes.items()],
            "members": [{"id": m.id, "from": m.start, "to": m.end, "elements": m.elements,
                         "material": {"E": m.E, "rho": m.rho, "nu": m.nu},
                         "section": section(m)} for m in model.members]}
    if model.supports:
        data["supports"] = [{"node": n, "type": t} for n, t in model.supports]
    if model.effects:
        from .model import effect_to_dict

        data["effects"] = [effect_to_dict(e) for e in model.effects]
    return data


# ------------------------------------------------------------------------------------------
# mesh and matrices
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FrameMesh:
    """Mesh nodes (global x, y), elements (member index, the DOFs of their two ends, length,
    direction cosines), the DOFs of each named node, rotational springs (dof, dof, k)."""

    xy: np.ndarray                  # (n_nodes, 2)
    element_member: np.ndarray      # (n_el,)
    element_dofs: np.ndarray        # (n_el, 6): u, v, θ at the start, then at the end
    element_length: np.ndarray      # (n_el,)
    cosines: np.ndarray             # (n_el, 2): c, s
    node_dofs: dict                 # node id -> (u, v, θ)
    member_nodes: tuple             # per member: mesh node indices along it
    springs: tuple                  # (θ dof, θ dof, k)
    grounded: tuple                 # (dof, k): a support that gives
    n_dof: int
    constrained: np.ndarray
    #: what depends on the mesh alone, computed once a mesh and shared by the copies that
    #: carry other spring values: the sparse patterns of K and M (:func:`_assemble`), the
    #: free DOFs (:attr:`free`), the supports' rigid motions (``rigid_body_count``)
    patterns: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def free(self) -> np.ndarray:
        """The DOFs the supports leave free (read-only; computed once a mesh)."""
        free = self.patterns.get("free")
        if free is None:
            free = np.setdiff1d(np.arange(self.n_dof), self.constrained)
            free.flags.writeable = False
            self.patterns["free"] = free
        return free


#: the meshes built, by what decides their nodes and numbering (:func:`_mesh_key`): a fit
#: changes only the spring values a mesh carries, and rebuilding it cost 3.9 s of the
#: three-storey frame's 52.7 s diagnosis under the profiler
_MESHES: dict = {}
_MESHES_KEPT = 64
_SPRING_EFFECTS = ("joint_spring", "support_spring", "support_translation")


def _mesh_key(model: FrameModel) -> tuple:
    return (tuple((k, tuple(v)) for k, v in model.nodes.items()), model.members,
            model.supports, tuple((e["effect"], e.get("node"), e.get("member"),
                                   e.get("direction")) for e in model.raw_effects
                                  if e["effect"] in _SPRING_EFFECTS))


def frame_mesh(model: FrameModel) -> FrameMesh:
    """The mesh: joints first (in file order), then each member's interior nodes; three DOFs
    a node, then one extra rotation per member end that a joint spring frees.  A mesh of
    the same nodes and numbering built before is reused with this model's spring values."""
    key = _mesh_key(model)
    kept = _MESHES.get(key)
    if kept is not None:
        joints = [float(e["stiffness"]) for e in model.raw_effects
                  if e["effect"] == "joint_spring"]
        grounds = [float(e["stiffness"]) for e in model.raw_effects
                   if e["effect"] in ("support_spring", "support_translation")]
        return replace(kept, springs=tuple((a, b, k) for (a, b, _), k in zip(kept.springs,
                                                                              joints)),
                       grounded=tuple((dof, k) for (dof, _), k in zip(kept.grounded, grounds)))
    mesh = _build_mesh(model)
    for array in (mesh.xy, mesh.element_member, mesh.element_dofs, mesh.element_length,
                  mesh.cosines, mesh.constrained):
        array.flags.writeable = False   # shared by every model of this key
    if len(_MESHES) >= _MESHES_KEPT:
        _MESHES.clear()
    _MESHES[key] = mesh
    return mesh


def _build_mesh(model: FrameModel) -> FrameMesh:
    ids = list(model.nodes)
    xy = [model.nodes[i] for i in ids]
    member_nodes = []
    for m in model.members:
        (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
        t = np.arange(1, m.elements) / m.elements
        first = len(xy)
        xy += [(x0 + s * (x1 - x0), y0 + s * (y1 - y0)) for s in t]
        member_nodes.append([ids.index(m.start), *range(first, first + m.elements - 1),
                             ids.index(m.end)])
    n_nodes = len(xy)
    dofs = np.arange(3 * n_nodes).reshape(n_nodes, 3)
    n_dof = 3 * n_nodes
    springs = []
    end_theta = {}
    for e in model.raw_effects:
        if e["effect"] == "joint_spring":
            joint = ids.index(e["node"])
            end_theta[(e["member"], e["node"])] = n_dof
            springs.append((int(dofs[joint, 2]), n_dof, float(e["stiffness"])))
            n_dof += 1
    el_member, el_dofs, el_len, cos = [], [], [], []
    for k, (m, nodes) in enumerate(zip(model.members, member_nodes)):
        (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
        length = math.hypot(x1 - x0, y1 - y0)
        c, s = (x1 - x0) / length, (y1 - y0) / length
        for j in range(m.elements):
            a, b = dofs[nodes[j]].copy(), dofs[nodes[j + 1]].copy()
            if j == 0 and (m.id, m.start) in end_theta:
                a[2] = end_theta[(m.id, m.start)]
            if j == m.elements - 1 and (m.id, m.end) in end_theta:
                b[2] = end_theta[(m.id, m.end)]
            el_member.append(k)
            el_dofs.append(np.concatenate([a, b]))
            el_len.append(length / m.elements)
            cos.append((c, s))
    fixed = {int(dofs[ids.index(node), d]) for node, kind in model.supports
             for d in SUPPORT_TYPES[kind]}
    grounded = []
    for e in model.raw_effects:
        if e["effect"] in ("support_spring", "support_translation"):
            dof = int(dofs[ids.index(e["node"]), RELEASES[e.get("direction", e["effect"])]])
            fixed.discard(dof)
            grounded.append((dof, float(e["stiffness"])))
    return FrameMesh(xy=np.array(xy, dtype=float), element_member=np.array(el_member),
                     element_dofs=np.array(el_dofs), element_length=np.array(el_len),
                     cosines=np.array(cos), node_dofs={i: tuple(int(d) for d in dofs[n])
                                                       for n, i in enumerate(ids)},
                     member_nodes=tuple(member_nodes), springs=tuple(springs),
                     grounded=tuple(grounded), n_dof=n_dof,
                     constrained=np.array(sorted(fixed), dtype=int))


#: the effects that change a member's elements (the others act at joints, supports and
#: places: springs, masses, applied in :func:`frame_matrices`)
_ELEMENT_EFFECTS = ("crack", "section_loss", "axial_stiffness", "axial_load", "foundation",
                    "member_shear", "stiffness_profile", "mass_profile")


@dataclass(frozen=True)
class MemberElements:
    """One member's elements: bending parameters k_ww, k_wθ, k_θθ (n, 3) [N m²], axial
    rigidity EA (n,) [N], stiffness and mass matrices (n, 6, 6) in global axes (the
    stiffness with the geometric stiffness of the member's ``tension``, N, > 0 pulling, and
    its ``foundation``'s k_f ∫ w² dx, N/m²); a Timoshenko member's (a ``shear`` effect)
    bending parameters are its shear-softened ones (eq. 18) and ``shear_g`` each element's
    g = 12 EI / (κGA L²) (None: Euler–Bernoulli)."""

    bending: np.ndarray
    axial: np.ndarray
    K: np.ndarray
    M: np.ndarray
    tension: float = 0.0
    foundation: float = 0.0
    shear_g: np.ndarray | None = None


#: members' elements computed, by everything that decides them (:func:`_member_key`): a fit
#: changes one member (a crack, a zone) or none (a spring, a mass), and recomputing every
#: member's elements at every evaluation was a third of a three-storey frame's diagnosis
_MEMBER_ELEMENTS: dict = {}
_MEMBER_ELEMENTS_KEPT = 256


def _member_key(model: FrameModel, k: int, raw: list) -> tuple:
    m = model.members[k]
    return (m, tuple(model.nodes[m.start]), tuple(model.nodes[m.end]), model.stiffness_factor,
            shear_rigidity(model), tuple(
                tuple((k, tuple(v) if isinstance(v, list) else v) for k, v in e.items())
                for e in raw if e["effect"] in _ELEMENT_EFFECTS and e["member"] == m.id))


def member_elements(model: FrameModel) -> list[MemberElements]:
    """Each member's :class:`MemberElements` (in member order; read-only arrays, shared by
    every model whose member is the same, with the same effects on it)."""
    raw = model.raw_effects
    out = []
    for k in range(len(model.members)):
        key = _member_key(model, k, raw)
        kept = _MEMBER_ELEMENTS.get(key)
        if kept is None:
            kept = _member_elements(model, k)
            for array in (kept.bending, kept.axial, kept.K, kept.M, kept.shear_g):
                if array is not None:
                    array.flags.writeable = False
            if len(_MEMBER_ELEMENTS) >= _MEMBER_ELEMENTS_KEPT:
                _MEMBER_ELEMENTS.clear()
            _MEMBER_ELEMENTS[key] = kept
        out.append(kept)
    return out


def member_lines(model: FrameModel, member: Member):
    """``member`` as a beam (its bending) and as a bar (its axial motion), each a
    :class:`~gfe_opt.model.Model` along the member (positions from its start node) carrying
    the member's element effects as that line's own effects: what each changes comes from
    the effect's ``contribute``, as on a beam or a bar (issue 24: one code path).  A crack,
    a stiffness profile, an axial load and a foundation act on the bending; a mass profile
    on both; a section loss on both, scaling the bar's EA by its mass ratio (the zone's
    area changes as its mass, the material stays); an ``axial_stiffness`` scales the bar's
    EA by its ratio (a loose brace); the member's κGA (a ``member_shear``, or a ``shear``)
    is the beam's ``shear``."""
    from .model import Effect, Model

    E = model.stiffness_factor * member.E
    bending, axial, ratio = [], [], 1.0
    for e in model.effects:
        if e.name not in _ELEMENT_EFFECTS or e.parameters.get("member") != member.id:
            continue
        p = {k: v for k, v in e.parameters.items() if k != "member"}
        if e.name == "axial_stiffness":
            ratio *= float(p["ratio"])
        elif e.name != "member_shear":   # (its κGA below)
            bending.append(Effect(e.name, p))
            if e.name == "section_loss":
                axial.append(Effect(e.name, {**p, "stiffness_ratio": p["mass_ratio"]}))
            elif e.name == "mass_profile":
                axial.append(Effect(e.name, p))
    kGA = member_shear_rigidity(model, member)
    if kGA is not None:
        bending.append(Effect("shear", {"shear_rigidity": kGA}))
    line = dict(name=member.id, length=model.member_length(member), elements=member.elements,
                rho=member.rho, nu=member.nu, area=member.area, inertia=member.inertia,
                depth=member.depth, supports=("free", "free"))
    return (Model(kind="beam", E=E, effects=tuple(bending), **line),
            Model(kind="bar", E=E * ratio, effects=tuple(axial), **line))


#: the axial (u) and bending (w, θ) rows and columns of a frame element's six local DOFs, as
#: index arrays (``A[_EACH_AXIAL]`` is each element's 2 x 2 axial block)
_EACH_AXIAL = (slice(None), *np.ix_([0, 3], [0, 3]))
_EACH_BENDING = (slice(None), *np.ix_([1, 2, 4, 5], [1, 2, 4, 5]))


@dataclass(frozen=True)
class _MemberStatic:
    """What a member's elements share whatever the effects that move in a fit (cracks,
    zones, profiles, tension, foundation, the material's stiffness): the rotation T and Tᵀ,
    and M in global axes of the member's lines with no effect on their mass (bar ⊕ beam,
    Timoshenko's when the member is)."""

    T: np.ndarray
    Tt: np.ndarray
    M: np.ndarray


_MEMBER_STATIC: dict = {}


def _member_static(model: FrameModel, member: Member, bending, axial) -> _MemberStatic:
    """``member``'s :class:`_MemberStatic` (``bending``, ``axial``: its
    :func:`member_lines`' builders), kept by what decides it (read-only arrays)."""
    (x0, y0), (x1, y1) = model.nodes[member.start], model.nodes[member.end]
    kGA = bending.shear_rigidity
    key = (member, x0, y0, x1, y1, kGA, None if kGA is None else model.stiffness_factor)
    kept = _MEMBER_STATIC.get(key)
    if kept is not None:
        return kept
    length = math.hypot(x1 - x0, y1 - y0)
    local_m = _local(_line_mass(axial, plain=True), _line_mass(bending, plain=True))
    T = rotations(np.tile([(x1 - x0) / length, (y1 - y0) / length], (member.elements, 1)))
    Tt = np.swapaxes(T, 1, 2)
    kept = _MemberStatic(T, Tt, Tt @ local_m @ T)
    for array in (kept.T, kept.Tt, kept.M):
        array.flags.writeable = False
    if len(_MEMBER_STATIC) >= _MEMBER_ELEMENTS_KEPT:
        _MEMBER_STATIC.clear()
    _MEMBER_STATIC[key] = kept
    return kept


def _line_mass(build, plain: bool = False) -> np.ndarray:
    """The element masses of a line's builder (``plain``: without its effects' changes,
    the numbers its elements no effect reaches have)."""
    from .assembly import Builder

    if plain:
        build = Builder(build.model, shear_rigidity=build.shear_rigidity)
    return build._mass(build.model.youngs_modulus)


def _local(axial, bending) -> np.ndarray:
    """(n, 6, 6): bar ⊕ beam in the member's six local DOFs [u, w, θ, u, w, θ]."""
    out = np.zeros((axial.shape[0], 6, 6))
    out[_EACH_AXIAL] = axial
    out[_EACH_BENDING] = bending
    return out


def _member_elements(model: FrameModel, k: int) -> MemberElements:
    """One member's elements: its :func:`member_lines` (the beam's and the bar's elements
    as :mod:`gfe_opt.assembly` builds them for a beam and a bar), bar ⊕ beam in the
    member's axes, rotated into global axes by T = diag(R, R)."""
    from .assembly import builder, stiffness_elements

    member = model.members[k]
    beam, bar = member_lines(model, member)
    bending, axial = builder(beam), builder(bar)
    static = _member_static(model, member, bending, axial)
    L = beam.element_length
    p, g = bending._stiffness(beam.youngs_modulus * beam.inertia)
    EA = axial._stiffness(bar.youngs_modulus * bar.area)[0]["k"]
    local_k = _local(stiffness_elements("bar", {"k": EA}, L),
                     stiffness_elements("beam", p, L) + bending._extra())
    M = static.M if not (bending.mass or axial.mass) else \
        static.Tt @ _local(_line_mass(axial), _line_mass(bending)) @ static.T
    return MemberElements(np.stack([p["k_ww"], p["k_wt"], p["k_tt"]], axis=1), EA,
                          static.Tt @ local_k @ static.T, M, _member_tension(model, member),
                          _member_value(model, member, "foundation", "stiffness"), g)


def shear_rigidity(model: FrameModel) -> float | None:
    """The ``shear`` effect's κGA (the first member's) [N], None without one."""
    return next((float(e.parameters["shear_rigidity"]) for e in model.effects
                 if e.name == "shear" and "shear_rigidity" in e.parameters), None)


def has_shear(model: FrameModel) -> bool:
    """Whether any member is Timoshenko (a ``shear`` or a ``member_shear``)."""
    return any(e.name in ("shear", "member_shear") for e in model.effects)


def member_shear_rigidity(model: FrameModel, member: Member) -> float | None:
    """``member``'s κGA: a ``member_shear``'s on it, else under a ``shear`` effect its shear
    rigidity times the member's GA over the first member's (G = E / (2 (1 + ν)): κ the
    same for every member), None without either (Euler–Bernoulli)."""
    own = next((float(e.parameters["shear_rigidity"]) for e in model.effects
                if e.name == "member_shear" and e.parameters.get("member") == member.id
                and "shear_rigidity" in e.parameters), None)
    if own is not None:
        return own
    value = shear_rigidity(model)
    if value is None:
        return None
    first = model.members[0]
    return value * (member.E / (1.0 + member.nu) * member.area) \
        / (first.E / (1.0 + first.nu) * first.area)


def _member_tension(model: FrameModel, member: Member) -> float:
    """The axial force of an ``axial_load`` on ``member`` [N] (tension > 0), else 0."""
    return _member_value(model, member, "axial_load", "tension")


def _member_value(model: FrameModel, member: Member, effect: str, key: str) -> float:
    """``key`` of the (one) ``effect`` on ``member``, else 0."""
    return float(next((e[key] for e in model.raw_effects
                       if e["effect"] == effect and e["member"] == member.id), 0.0))


def element_matrices(model: FrameModel):
    """(K_e, M_e), each (n_el, 6, 6) in global axes: bar ⊕ beam in the member's axes,
    rotated by T = diag(R, R)."""
    members = member_elements(model)
    return (np.concatenate([m.K for m in members]), np.concatenate([m.M for m in members]))


def rotations(cosines) -> np.ndarray:
    """(n, 6, 6): T = diag(R, R), R = [[c, s, 0], [-s, c, 0], [0, 0, 1]], from global to
    member axes, for each row (c, s) of ``cosines``."""
    c, s = cosines[:, 0], cosines[:, 1]
    T = np.zeros((len(cosines), 6, 6))
    for o in (0, 3):
        T[:, o, o], T[:, o, o + 1] = c, s
        T[:, o + 1, o], T[:, o + 1, o + 1] = -s, c
        T[:, o + 2, o + 2] = 1.0
    return T


def frame_matrices(model: FrameModel, mesh: FrameMesh | None = None):
    """Global (K, M), sparse, all DOFs (supports not applied)."""
    mesh = frame_mesh(model) if mesh is None else mesh
    Ke, Me = element_matrices(model)
    springs = [v for _, _, k in mesh.springs for v in (k, -k, -k, k)]
    K = _assemble(mesh, "K", np.concatenate([Ke.ravel(), springs,
                                             [k for _, k in mesh.grounded]]))
    M = _assemble(mesh, "M", Me.ravel())
    masses = _attached(model, mesh, "point_mass")
    if masses is not None:
        M = M + _outer_sum(*masses)
    turning = _turning(model, mesh)
    if turning is not None:
        M = M + _outer_sum(*turning)
    points = _attached(model, mesh, "point_spring")
    if points is not None:
        K = K + _outer_sum(*points)
    return K, M


def _attached(model: FrameModel, mesh: FrameMesh, name: str):
    """(C, values) of the frame's point masses (``name`` "point_mass": the x and the y
    displacement at each, its mass twice) or point springs ("point_spring": the displacement
    along its direction, its stiffness), None when it has none: each displacement read at
    its place by the element's shape functions, as a sensor reads it, so that the mass adds
    m (cx cxᵀ + cy cyᵀ) to M and the spring k c cᵀ to K.  The readings are kept a few at a
    time (:func:`~gfe_opt.frame_data.attached_reading`; a fitted place moves at every
    evaluation, the fits of other effects read the same place again)."""
    names = (name, "attached_body") if name == "point_mass" else (name,)
    found = [e for e in model.raw_effects if e["effect"] in names]
    if not found:
        return None
    from .frame_data import attached_reading  # as a sensor reads them, Timoshenko or not

    if name == "point_mass":
        places = [{"member": e["member"], "position": e["position"], "direction": d}
                  for e in found for d in ("x", "y")]
        values = np.repeat([e["mass"] for e in found], 2)
    else:
        places = [{"member": e["member"], "position": e["position"],
                   "direction": e["direction"]} for e in found]
        values = np.array([float(e["stiffness"]) for e in found])
    return attached_reading(model, mesh, places), values


#: the effects that add a rotary inertia J at a point of a frame (:func:`_turning`)
TURNING = ("attached_body", "rotary_inertia")


def _turning(model: FrameModel, mesh: FrameMesh, effects=None):
    """(C, J) of the rotary inertias of the frame's bodies (``attached_body``,
    ``rotary_inertia``; ``effects``: those raw effects instead): the rotation at each place
    (:func:`~gfe_opt.frame_data.rotation_reading`), so that each adds J c cᵀ to M; None
    when it has none."""
    found = [e for e in (model.raw_effects if effects is None else effects)
             if e["effect"] in TURNING]
    if not found:
        return None
    from .frame_data import rotation_reading

    return rotation_reading(model, mesh, [{"member": e["member"], "position": e["position"]}
                                          for e in found]), \
        np.array([float(e["inertia"]) for e in found])


def _outer_sum(C, values) -> sp.csr_matrix:
    """Cᵀ diag(values) C, CSR: the numbers of ``(C.T @ sp.diags(values) @ C).tocsr()`` (each
    entry Σ_r (c_ri v_r) c_rj, r ascending, its exact zeros left out) from the few columns
    that ``C`` reads, without the three sparse products (0.56 of the 1.7 ms a three-storey
    frame with a point mass took to assemble)."""
    C = sp.csr_matrix(C)
    if not C.has_canonical_format:
        C = C.copy()
        C.sum_duplicates()
    cols = np.unique(C.indices)
    block = np.zeros((C.shape[0], cols.size))
    block[np.repeat(np.arange(C.shape[0]), np.diff(C.indptr)),
          np.searchsorted(cols, C.indices)] = C.data
    out = np.zeros((cols.size, cols.size))
    for r in range(C.shape[0]):
        out += (block[r][:, None] * values[r]) * block[r][None, :]
    i, j = np.nonzero(out)
    return sp.csr_matrix((out[i, j], (cols[i], cols[j])), shape=(C.shape[1], C.shape[1]))


def local_difference(models, weights, index: int):
    """Σ wᵢ K(modelsᵢ) and Σ wᵢ M(modelsᵢ) (all DOFs, sparse) of frames that differ only in
    their effect ``index`` (a fit's Jacobian differencing one variable's matrices), from
    what that effect changes alone: the elements of its member (an element effect), or its
    own outer product (a point mass or spring).  :func:`frame_matrices`' other terms are the
    same numbers in every model and cancel (building them for each model was a tenth of a
    three-storey frame's diagnosis under the profiler; its wall time did not measurably
    change: the README's Speed section).  None where the effect changes the mesh's springs (a
    joint or a support), every member (the material, shear) or how the members read
    (Timoshenko members), or where the models' meshes differ: the caller then differences
    the whole matrices, as :func:`gfe_opt.assembly.local_difference` does on a beam."""
    first = models[0]
    name = first.effects[index].name
    local = name in _ELEMENT_EFFECTS or name in ("point_mass", "point_spring", *TURNING)
    if not local or name == "member_shear" or any(has_shear(m) for m in models):
        return None
    meshes = [frame_mesh(m) for m in models]
    mesh = meshes[0]
    if any(x.n_dof != mesh.n_dof or not np.array_equal(x.element_dofs, mesh.element_dofs)
           for x in meshes[1:]):
        return None
    n = mesh.n_dof

    from .assembly import weighted_difference

    def weighted(values):
        return weighted_difference(values, weights)

    if name in _ELEMENT_EFFECTS:
        member = first.effects[index].parameters["member"]
        k = next(i for i, m in enumerate(first.members) if m.id == member)
        start = sum(m.elements for m in first.members[:k])
        stop = start + first.members[k].elements
        if not np.all(mesh.element_member[start:stop] == k):
            return None
        along = _footprint(models, index, k)
        if along is None:   # (every element of the member)
            parts = [(p.K, p.M) for p in (member_elements(m)[k] for m in models)]
            along = np.arange(stop - start)
        else:
            parts = [_some_elements(m, k, along) for m in models]
        dofs = mesh.element_dofs[start + along]
        rows = np.repeat(dofs, 6, axis=1).ravel()
        cols = np.tile(dofs, (1, 6)).ravel()
        return tuple(sp.csr_matrix((weighted([p[which] for p in parts]).ravel(),
                                    (rows, cols)), shape=(n, n)) for which in (0, 1))
    from .frame_data import attached_reading

    parts = []
    for m, x in zip(models, meshes):
        e = m.raw_effects[index]
        part = sp.csr_matrix((n, n))
        if name in ("point_mass", "attached_body"):
            places = [{"member": e["member"], "position": e["position"], "direction": d}
                      for d in ("x", "y")]
            part = _outer_sum(attached_reading(m, x, places), np.repeat([e["mass"]], 2))
        elif name == "point_spring":
            places = [{"member": e["member"], "position": e["position"],
                       "direction": e["direction"]}]
            part = _outer_sum(attached_reading(m, x, places),
                              np.array([float(e["stiffness"])]))
        if name in TURNING:
            part = part + _outer_sum(*_turning(m, x, [e]))
        parts.append(part)
    change = sp.csr_matrix(weighted(parts))
    zero = sp.csr_matrix((n, n))
    return (change, zero) if name == "point_spring" else (zero, change)


def _footprint(models, index: int, k: int) -> np.ndarray | None:
    """The elements of member ``k`` (sorted, along it) that effect ``index`` changes in any
    of ``models`` (:meth:`~gfe_opt.assembly.Builder.footprint` of its member's two lines
    with that effect alone), or None when it changes all of them (a profile, a tension, a
    foundation, a looser member: its footprint is the member)."""
    from .assembly import builder

    out = []
    for m in models:
        effect = m.effects[index]
        if effect.name == "axial_stiffness":
            return None
        alone = replace(m, effects=(effect,))
        for line in member_lines(alone, alone.members[k]):
            part = builder(line).footprint()
            if part is None:
                return None
            out.append(part)
    return np.unique(np.concatenate(out)).astype(int) if out else np.zeros(0, dtype=int)


def _some_elements(model: FrameModel, k: int, along: np.ndarray):
    """(K, M) in global axes of the elements ``along`` member ``k``: the numbers
    :func:`_member_elements` gives them, without building the others."""
    from .assembly import builder

    member = model.members[k]
    beam, bar = member_lines(model, member)
    bending, axial = builder(beam), builder(bar)
    static = _member_static(model, member, bending, axial)
    k_beam, extra, m_beam = bending.element_matrices(along)
    k_bar, _, m_bar = axial.element_matrices(along)
    T, Tt = static.T[along], static.Tt[along]
    K = Tt @ _local(k_bar, k_beam + extra) @ T
    M = static.M[along] if not (bending.mass or axial.mass) else \
        Tt @ _local(m_bar, m_beam) @ T
    return K, M


def _assemble(mesh: FrameMesh, which: str, values) -> sp.csr_matrix:
    """The sparse sum of ``values`` over the mesh's entries (``"K"``: the elements' 36 a
    element, then each joint spring's four, then each ground spring's one; ``"M"``: the
    elements' alone), into a pattern computed once a mesh (kept with it): the entries added
    in their order, as a COO sum would, without sorting them at every evaluation."""
    pattern = mesh.patterns.get(which)
    if pattern is None:
        rows = [np.repeat(mesh.element_dofs, 6, axis=1).ravel()]
        cols = [np.tile(mesh.element_dofs, (1, 6)).ravel()]
        if which == "K":
            for a, b, _ in mesh.springs:
                rows.append(np.array([a, a, b, b]))
                cols.append(np.array([a, b, a, b]))
            rows.append(np.array([dof for dof, _ in mesh.grounded], dtype=int))
            cols.append(rows[-1])
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        n = mesh.n_dof
        unique, slot = np.unique(rows * n + cols, return_inverse=True)
        indptr = np.searchsorted(unique // n, np.arange(n + 1))
        # the index type scipy keeps them in (int32 below 2³¹ entries): it then neither
        # scans nor copies them at every evaluation (the same matrix)
        index = np.int32 if unique.size < 2**31 - 1 and n < 2**31 - 1 else np.int64
        pattern = (indptr.astype(index), (unique % n).astype(index), slot, unique.size)
        mesh.patterns[which] = pattern
    indptr, indices, slot, size = pattern
    data = np.bincount(slot, weights=values, minlength=size)
    return sp.csr_matrix((data, indices, indptr), shape=(mesh.n_dof, mesh.n_dof))


#: free DOFs up to which a frame's modes come from the dense solve: a speed choice, not a
#: result (measured side by side, ``python scripts/bench.py --parts frames``: dense is
#: faster on the portal's 180 free DOFs, the sparse solve 2-4x faster on the
#: three-storey frame's 351)
DENSE_SOLVE_DOFS = 250


class FrameDiscretisation:
    """A frame's mesh and matrices behind the interface the modal solve and the fits use
    (:class:`~gfe_opt.assembly.Discretisation`'s: ``kind``, ``free``, ``constrained``,
    ``eigenvalue_scale``, :meth:`global_matrices`, :meth:`strain_energy`), so that a frame
    goes through :func:`~gfe_opt.modal.discretisation_modes` and
    :func:`~gfe_opt.fitting.fit_effects` as a beam does."""

    kind = "frame"
    shear_g = None
    #: the eigenvalue derivatives by Nelson's sparse form: a frame's DOFs are numbered
    #: joints first, so its matrices are sparse but not banded, and the dense bordered
    #: solve of :mod:`gfe_opt.sensitivity` cost 6x (portal, 183 DOFs) to 38x (three-storey,
    #: 357) more (``python scripts/bench.py --parts frames``); the same derivatives to 1e-10
    dense_derivatives = False

    def __init__(self, model: FrameModel):
        self.model = model
        self.mesh = frame_mesh(model)
        self.n_elements = model.n_elements
        self.n_dof = self.mesh.n_dof
        self.constrained = self.mesh.constrained
        self.free = self.mesh.free
        #: LAPACK's dense solve up to :data:`DENSE_SOLVE_DOFS` free DOFs, shift-invert
        #: Lanczos on the sparse pencil above (the modes agree to 1e-9, the Rayleigh
        #: quotients to rounding)
        self.dense_solve = self.free.size <= DENSE_SOLVE_DOFS
        #: EI/(ρA L⁴) of the most flexible member: the eigenvalue scale of the frame
        self.eigenvalue_scale = min(m.E * m.inertia / (m.rho * m.area
                                                       * model.member_length(m) ** 4)
                                    for m in model.members)
        self._matrices = None
        if has_shear(model):
            #: Timoshenko members: each element's g, 0 on an Euler–Bernoulli member (a fit
            #: then differentiates the sensors' reading too: it interpolates with the shear
            #: strains)
            self.shear_g = np.concatenate([
                m.shear_g if m.shear_g is not None else np.zeros(len(m.axial))
                for m in member_elements(model)])

    def global_matrices(self, params=None):
        """(K, M) over all DOFs, supports not applied (``params`` must be None: a frame's
        generic parameters are not replaced yet)."""
        if params is not None:
            raise ValueError("replaced generic parameters are for beams and bars")
        if self._matrices is None:
            self._matrices = frame_matrices(self.model, self.mesh)
        return self._matrices

    def strain_energy(self, shapes, params=None) -> np.ndarray:
        return strain_energy(self.model, self.mesh, shapes)

    def observation(self, measured) -> sp.csr_matrix:
        """The sensors of ``measured`` read through the mesh
        (:func:`gfe_opt.frame_data.observation`: a joint spring gives a member's end its own
        rotation, so the matrix follows the effects)."""
        from .frame_data import observation

        return observation(self.model, self.mesh, measured.sensors)

    def rigid_body_count(self) -> int:
        """Rigid-body modes the supports and springs leave: the plane motions
        (u = a − θ y, v = b + θ x, every rotation θ) that vanish at the fixed DOFs and store
        no energy (a spring to ground takes one away)."""
        import scipy.linalg as sla

        motions = self.mesh.patterns.get("rigid")   # the supports' own, once a mesh
        if motions is None:
            xy = self.mesh.xy
            n = xy.shape[0]
            basis = np.zeros((self.n_dof, 3))
            basis[0:3 * n:3, 0] = 1.0
            basis[1:3 * n:3, 1] = 1.0
            basis[0:3 * n:3, 2], basis[1:3 * n:3, 2] = -xy[:, 1], xy[:, 0]
            basis[2:3 * n:3, 2] = 1.0
            basis[3 * n:, 2] = 1.0                      # members' own end rotations
            fixed = basis[self.constrained]
            null = sla.null_space(fixed) if fixed.size else np.eye(3)
            motions = basis @ null
            motions.flags.writeable = False
            self.mesh.patterns["rigid"] = motions
        if motions.shape[1] == 0:
            return 0
        k = motions.shape[1]
        pairs = np.stack([motions[:, i] + motions[:, j] for i in range(k) for j in range(k)],
                         1)
        energy = self.strain_energy(np.hstack([motions, pairs]))
        single, both = energy[:k], energy[k:].reshape(k, k)
        E = 0.5 * (both - single[:, None] - single[None, :])
        _, M = self.global_matrices()
        Mr = motions.T @ (M @ motions)
        lam = sla.eigh(0.5 * (E + E.T), Mr, eigvals_only=True)
        return int(np.sum(lam <= 1e-9 * self.eigenvalue_scale))


def frame_modes(model: FrameModel, n_modes: int, disc: FrameDiscretisation | None = None):
    """The lowest ``n_modes`` modes (:class:`~gfe_opt.modal.Modes`; shapes over all DOFs,
    zero at the supports), rigid-body modes (0 Hz) included: the beam's direct route
    (:func:`~gfe_opt.modal.discretisation_modes`: eigenvalues as Rayleigh quotients from
    the element deformations, every elastic mode's residual checked); ``disc`` may pass the
    model's discretisation already built."""
    from .modal import discretisation_modes

    disc = FrameDiscretisation(model) if disc is None else disc
    if not 1 <= n_modes <= disc.free.size - 1:
        raise GfeInputError(model.source, "modes", f"the frame has {disc.free.size} free "
                            f"DOFs: ask for 1 to {disc.free.size - 1} modes, got {n_modes}")
    return discretisation_modes(disc, n_modes)


def strain_energy(model: FrameModel, mesh: FrameMesh, shapes) -> np.ndarray:
    """2 × the strain energy of each shape (columns), summed element by element from the
    element deformations in the member's axes (axial u₂ − u₁; bending d = H [v₁, Lθ₁, v₂,
    Lθ₂]), so that no large stiffness entries cancel (as the beam's Rayleigh quotients,
    :mod:`gfe_opt.modal`): the axial stiffness of a fine mesh is (A L²/I) N² times the
    bending one, and eigenvalues from the solver alone lose that factor times eps."""
    u = shapes[mesh.element_dofs]                         # (n_el, 6, modes)
    c, s = mesh.cosines[:, 0, None], mesh.cosines[:, 1, None]
    L = mesh.element_length[:, None]
    axial = (c * (u[:, 3] - u[:, 0]) + s * (u[:, 4] - u[:, 1]))
    v1, v2 = -s * u[:, 0] + c * u[:, 1], -s * u[:, 3] + c * u[:, 4]
    d1 = v1 - v2 + L * u[:, 5]                            # d = H [w1, Lθ1, w2, Lθ2]
    d2 = L * (u[:, 2] - u[:, 5])
    members = member_elements(model)
    p = np.concatenate([m.bending for m in members])
    EA = np.concatenate([m.axial for m in members])
    energy = (EA[:, None] / L) * axial**2 + (p[:, 0, None] * d1**2 + 2 * p[:, 1, None] * d1 * d2
                                             + p[:, 2, None] * d2**2) / L**3
    T = np.concatenate([np.full(m.axial.size, m.tension) for m in members])
    kf = np.concatenate([np.full(m.axial.size, m.foundation) for m in members])
    if np.any(T) or np.any(kf):   # transverse motion [v₁, Lθ₁, v₂, Lθ₂] of each element
        q = np.stack([v1, L * u[:, 2], v2, L * u[:, 5]], axis=1)      # (n_el, 4, modes)
    if np.any(T):   # a member's axial load: T ∫ w'² dx
        gram = slope_gram(1.0) * 30.0                                  # 30 L ∫ N'ᵀN' (scaled)
        energy = energy + (T[:, None] / (30.0 * L)) * np.einsum("eim,ij,ejm->em", q, gram, q)
    if np.any(kf):   # a member's foundation: k_f ∫ w² dx
        energy = energy + (kf[:, None] * L) * np.einsum("eim,ij,ejm->em", q, el.HERMITE_GRAM,
                                                        q)
    total = energy.sum(axis=0)
    for a, b, k in mesh.springs:
        total = total + k * (shapes[a] - shapes[b]) ** 2
    for dof, k in mesh.grounded:
        total = total + k * shapes[dof] ** 2
    points = _attached(model, mesh, "point_spring")
    if points is not None:   # k (cᵀ φ)² each
        C, k = points
        total = total + k @ np.asarray(C @ shapes) ** 2
    return total


def mesh_sensors(model: FrameModel, mesh: FrameMesh) -> list[tuple[dict, int]]:
    """Every free translation of the mesh as a sensor of the frame measured-data contract
    (``{"node": id, "direction": "x"}`` at named nodes, ``{"member": id, "position": m,
    "direction": "y"}`` between them) with its DOF."""
    out = []
    fixed = set(mesh.constrained.tolist())
    for node, (u, v, _) in mesh.node_dofs.items():
        out += [({"node": node, "direction": d}, dof) for d, dof in (("x", u), ("y", v))
                if dof not in fixed]
    for member, nodes in zip(model.members, mesh.member_nodes):
        step = model.member_length(member) / member.elements
        for j, n in enumerate(nodes[1:-1], start=1):
            out += [({"member": member.id, "position": round(j * step, 12), "direction": d},
                     3 * n + k) for k, d in ((0, "x"), (1, "y"))]
    return out


def write_frame_modes(model: FrameModel, n_modes: int, path, *, force: bool = False,
                      protect=()) -> tuple[int, int, int]:
    """The frame's elastic modes at every free mesh translation, written as frame measured
    data (JSON: ``{"sensors": [...], "modes": [{"frequency": Hz, "shape": [...]}]}``),
    atomically.  Returns (elastic modes written, sensors, rigid-body modes left out)."""
    import json

    from .outputs import atomic_write, check_output_path

    path = check_output_path(path, force, protect, kind="modes")
    suffix = path.suffix.lower()
    if suffix not in (".json", ".csv", ".uff", ".unv"):
        raise GfeInputError(str(path), None, "a frame's modes are written as .json, .csv or "
                            ".uff/.unv")
    disc = FrameDiscretisation(model)
    mesh = disc.mesh
    modes = frame_modes(model, min(n_modes + 3, disc.free.size - 1), disc)
    elastic = np.flatnonzero(modes.frequencies_hz > 0)[:n_modes]
    sensors = mesh_sensors(model, mesh)
    doc = {"sensors": [s for s, _ in sensors],
           "modes": [{"frequency": float(modes.frequencies_hz[j]),
                      "shape": [float(modes.shapes[dof, j]) for _, dof in sensors]}
                     for j in elastic]}
    if suffix == ".json":
        text = json.dumps(doc, indent=1)
        atomic_write(path, lambda p: p.write_text(text + "\n", encoding="utf-8"),
                     replace=force)
    elif suffix == ".csv":
        atomic_write(path, lambda p: _write_csv(mesh, modes, elastic, sensors, p),
                     replace=force)
    else:
        atomic_write(path, lambda p: _write_uff(mesh, modes, elastic, p), replace=force)
    rigid = int(np.sum(modes.frequencies_hz[:elastic[0]] == 0)) if elastic.size else 0
    return elastic.size, len(sensors), rigid


def _write_csv(mesh: FrameMesh, modes, columns, sensors, path) -> None:
    """The frame CSV (gfe_opt.frame_data): each sensor's mesh node's x, y and direction,
    then its value in each mode."""
    import csv

    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["x", "y", "direction"] + [repr(float(modes.frequencies_hz[j]))
                                              for j in columns])
        for sensor, dof in sensors:
            x, y = mesh.xy[dof // 3]
            w.writerow([repr(float(x)), repr(float(y)), sensor["direction"]]
                       + [repr(float(modes.shapes[dof, j])) for j in columns])


def _write_uff(mesh: FrameMesh, modes, columns, path) -> None:
    """Dataset 2411 (every mesh node's x, y) and one dataset 55 per mode (u, v in r1, r2;
    zero at a support's fixed translation)."""
    import pyuff

    n = mesh.xy.shape[0]
    nodes = np.arange(1, n + 1)
    zeros = np.zeros(n)
    sets = [pyuff.prepare_2411(node_nums=nodes, def_cs=np.zeros(n, int),
                               disp_cs=np.zeros(n, int), color=np.ones(n, int),
                               x=mesh.xy[:, 0], y=mesh.xy[:, 1], z=zeros,
                               return_full_dict=True)]
    for j in columns:
        shape = modes.shapes[:3 * n, j]
        sets.append(pyuff.prepare_55(
            id1=f"gfe-opt mode {j + 1}", id2="NONE", id3="NONE", id4="NONE", id5="NONE",
            model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2,
            n_data_per_node=3, load_case=1, mode_n=int(j) + 1,
            freq=float(modes.frequencies_hz[j]), modal_m=0.0, modal_damp_vis=0.0,
            modal_damp_his=0.0, node_nums=nodes, r1=shape[0::3].astype(float),
            r2=shape[1::3].astype(float), r3=zeros))
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
