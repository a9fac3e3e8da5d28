"""``support_spring``: rotational restraint at a support (a pin that binds, a clamp that
gives)."""

from __future__ import annotations

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable, frame_member_scale, nominal_rigidity

SIDES = ("left", "right", "both")
#: supports whose rotation a spring can restrain or, for a clamp, replace
SPRING_SUPPORTS = ("pinned", "clamped", "free")


class SupportSpring(EffectType):
    name = "support_spring"
    physics = ("rotational spring at an end: on a pinned or free end it restrains the "
               "rotation, on a clamped end it replaces the fixity (clamp compliance)")
    signature = "only at the end nodes: the moment there is no longer zero (pinned) or the "\
        "slope no longer zero (clamped)"
    kinds = ("beam", "frame")
    parameters = (
        Parameter("stiffness", "N m/rad", "positive", "rotational stiffness", null=0.0),
        Parameter("side", "", "choice", "which end", choices=SIDES),
    )
    frame_parameters = (Parameter("node", "", "choice", "the supported node (a frame)"),)

    def is_local(self, model) -> bool:
        """One at a beam's end (``side`` "both" for the two); on a frame one a supported
        node, any number of nodes (two bases that give are two instances)."""
        return model.kind == "frame"

    def check(self, model, params, where, prefix):
        side = params.get("side")
        if side is None:
            return
        ends = {"left": [0], "right": [1], "both": [0, 1]}[side]
        for end in ends:
            if model.supports[end] not in SPRING_SUPPORTS:
                raise GfeInputError(where, f"{prefix}side", f"the {('left', 'right')[end]} end "
                                    f"is {model.supports[end]}: its rotation is fixed, a "
                                    "rotational spring there does nothing")

    def contribute(self, model, params, build):
        sides = ("left", "right") if params["side"] == "both" else (params["side"],)
        for side in sides:
            build.add_end_spring(side, params["stiffness"])

    def variables(self, model, fixed):
        if model.kind == "frame":   # in units of EI/L of the first member at the node
            scale = frame_member_scale(model, fixed["node"], 1)
            return [Variable("stiffness", -3.0, 6.0, (-1.0, 0.0, 1.0, 2.0), log=True,
                             scale=lambda m: scale)]
        return [Variable("stiffness", -3.0, 6.0, (-1.0, 0.0, 1.0, 2.0), log=True,
                         scale=lambda m: nominal_rigidity(m) / m.length)]

    def starts(self, model, hint):
        if model.kind == "frame":   # every support that holds its node's rotation
            from ..frame import RELEASES, SUPPORT_TYPES

            return [{"node": n} for n, kind in model.supports
                    if RELEASES["support_spring"] in SUPPORT_TYPES[kind]]
        ok = [s for s, end in (("left", 0), ("right", 1))
              if model.supports[end] in SPRING_SUPPORTS]
        sides = ok + (["both"] if len(ok) == 2 else [])
        return [{"side": s} for s in sides]

    def position(self, params):
        return None

    def mark(self, ax, model, params, sigma, y, bounds=None):
        sides = ("left", "right") if params["side"] == "both" else (params["side"],)
        for side in sides:
            x = 0.0 if side == "left" else model.length
            ax.plot([x], [y], marker="$\\circlearrowleft$", color="tab:red", ms=12)


EFFECT = SupportSpring()
