"""``joint_spring``: a semi-rigid connection of a plane frame — a member's end turns
relative to its joint through a rotational spring (k → ∞ rigid, k → 0 a pin)."""

from __future__ import annotations

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable, no_unknown


class JointSpring(EffectType):
    name = "joint_spring"
    physics = ("rotational spring between a frame member's end and its joint: a bolted or "
               "loose connection (the member keeps its own end rotation)")
    signature = "only at the joint: the members' end rotations differ by moment / stiffness"
    kinds = ("frame",)
    local = True
    parameters = (
        Parameter("node", "", "choice", "the joint (a node id of the frame)"),
        Parameter("member", "", "choice", "the member whose end it holds"),
        Parameter("stiffness", "N m/rad", "positive", "rotational stiffness", null="inf"),
    )

    def validate(self, model, params, where, prefix="", partial=False):
        """The frame file's rules (:func:`gfe_opt.frame._effect`): the member ends at the
        node; with ``partial`` (``--add``) only what is given is checked."""
        if model.kind != "frame":
            raise GfeInputError(where, f"{prefix}effect", "effect 'joint_spring' needs kind "
                                "= 'frame'")
        no_unknown(params, set(self.keys), where, prefix)
        missing = [k for k in ("node", "member") if k not in params]
        if partial and len(missing) == 2:
            return dict(params)   # --add joint_spring: every joint end is tried
        if missing:
            raise GfeInputError(where, f"{prefix}{missing[0]}", "missing (a joint spring "
                                "needs node and member)")
        from ..frame import _effect

        full = {"effect": self.name, **params}
        if "stiffness" not in full and partial:
            full["stiffness"] = 1.0
        checked = _effect(model, full, where, prefix).parameters
        return {k: checked[k] for k in self.keys if k in params}

    def fixed_keys(self, model=None):
        return ("node", "member")

    def variables(self, model, fixed):
        member = model.member(fixed["member"])
        scale = 4.0 * member.E * member.inertia / model.member_length(member)
        # in units of the member's own end stiffness 4EI/L: 10⁻³ (a pin) to 10⁶ (rigid)
        return [Variable("stiffness", -3.0, 6.0, (-1.0, 0.0, 1.0, 2.0), log=True,
                         scale=lambda m: scale)]

    def starts(self, model, hint):
        """Every member end at a joint where two or more members meet; where exactly two
        meet and no support holds the joint's rotation, the first member's end only: a
        spring at either end is the same structure (two rotations joined by one spring)."""
        from ..frame import SUPPORT_TYPES

        ends = {}
        for m in model.members:
            for node in (m.start, m.end):
                ends.setdefault(node, []).append(m.id)
        held = {node for node, kind in model.supports if 2 in SUPPORT_TYPES[kind]}
        return [{"node": node, "member": member} for node, members in ends.items()
                if len(members) > 1
                for member in (members[:1] if len(members) == 2 and node not in held
                               else members)]

    def position(self, params):
        return None


EFFECT = JointSpring()
