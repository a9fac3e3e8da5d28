"""``support_translation``: a support that gives in translation (a pin on a soft bearing, a
clamp whose block moves, a bar's fixed end on an elastic seat)."""

from __future__ import annotations

from ..errors import GfeInputError
from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    effect_sides,
    frame_member_scale,
    nominal_rigidity,
)

SIDES = ("left", "right", "both")


def _scale(model):
    """EI/ℓ³ (beam) or EA/ℓ (bar) [N/m]."""
    power = 3 if model.kind == "beam" else 1
    return nominal_rigidity(model) / model.length**power


class SupportTranslation(EffectType):
    name = "support_translation"
    physics = ("translational spring at a pinned, clamped or fixed end that replaces the "
               "fixity of the deflection (beam w, bar u): a support that gives")
    signature = "only at the end nodes: the deflection there is no longer zero"
    kinds = ("beam", "bar", "frame")
    #: the support's translation is no longer held (sensors there read the structure)
    releases_translation = True
    parameters = (
        Parameter("stiffness", "N/m", "positive", "translational support stiffness",
                  null="inf"),
        Parameter("side", "", "choice", "which end", choices=SIDES),
    )
    frame_parameters = (Parameter("node", "", "choice", "the supported node (a frame)"),
                        Parameter("direction", "", "choice", "x or y (a frame)",
                                  choices=("x", "y")))

    def is_local(self, model) -> bool:
        """One at a beam's end (``side`` "both" for the two); on a frame one a supported
        node, any number of nodes (two bases that give are two instances)."""
        return model.kind == "frame"

    def check(self, model, params, where, prefix):
        for side in effect_sides(params):
            end = ("left", "right").index(side)
            if model.supports[end] not in FIXED_TRANSLATION:
                raise GfeInputError(where, f"{prefix}side", f"the {side} end is "
                                    f"{model.supports[end]}: its translation is not held, a "
                                    "support that gives needs a pinned, clamped or fixed end "
                                    "(a spring at a free end is a point_spring)")

    def contribute(self, model, params, build):
        for side in effect_sides(params):
            build.add_end_spring(side, params["stiffness"], translation=True)

    def variables(self, model, fixed):
        if model.kind == "frame":   # in units of EI/L³ of the first member at the node
            scale = frame_member_scale(model, fixed["node"], 3)
            return [Variable("stiffness", -1.0, 8.0, (1.0, 2.0, 3.0, 4.0), log=True,
                             scale=lambda m: scale)]
        return [Variable("stiffness", -1.0, 8.0, (1.0, 2.0, 3.0, 4.0), log=True,
                         scale=_scale)]

    def starts(self, model, hint):
        if model.kind == "frame":   # every translation a support holds
            from ..frame import RELEASES, SUPPORT_TYPES

            return [{"node": n, "direction": d} for n, kind in model.supports
                    for d in ("x", "y") if RELEASES[d] in SUPPORT_TYPES[kind]]
        ok = [s for s, end in (("left", 0), ("right", 1))
              if model.supports[end] in FIXED_TRANSLATION]
        return [{"side": s} for s in ok + (["both"] if len(ok) == 2 else [])]

    def position(self, params):
        return None

    def mark(self, ax, model, params, sigma, y, bounds=None):
        for side in effect_sides(params):
            x = 0.0 if side == "left" else model.length
            ax.plot([x], [y], marker="$\\updownarrow$", color="tab:red", ms=12)


EFFECT = SupportTranslation()
