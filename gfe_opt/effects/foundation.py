"""``foundation``: a Winkler elastic foundation, under the whole beam or under one member of
a frame (a ground beam on soil, a member resting along a wall or an infill)."""

from __future__ import annotations

import numpy as np

from .. import elements as el
from .base import EffectType, Parameter, Variable, nominal_rigidity


class Foundation(EffectType):
    name = "foundation"
    physics = "Winkler foundation: a distributed spring k_f per unit length"
    signature = "a uniform k_f w term at every node"
    kinds = ("beam", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member it lies under (a "
                                  "frame)"),)
    parameters = (Parameter("stiffness", "N/m^2", "positive", "foundation modulus k_f",
                            null=0.0),)

    def is_local(self, model) -> bool:
        """One foundation under a beam; on a frame one a member, any number of members."""
        return model.kind == "frame"

    def contribute(self, model, params, build):
        k = params["stiffness"]
        build.add_element_stiffness(lambda L: k * L * el.HERMITE_GRAM)

    def variables(self, model, fixed):
        """k_f over EI (π/ℓ)⁴ of the beam or of the member (its first pinned-pinned mode's
        stiffness per unit length): 1e-4 to 100 of it."""
        if model.kind == "frame":
            member = model.member(fixed["member"])
            own = member.E * member.inertia * (np.pi / model.member_length(member)) ** 4

            def scale(m):
                return own
        else:
            def scale(m):
                return nominal_rigidity(m) * (np.pi / m.length) ** 4
        return [Variable("stiffness", 1e-4, 100.0, (0.05, 0.5, 2.0, 10.0), scale=scale)]

    def starts(self, model, hint):
        """On a frame under every member; a beam's foundation is one."""
        if model.kind == "frame":
            return [{"member": m.id} for m in model.members]
        return [{}]

    def frame_placeholders(self, model, params):
        return {"stiffness": 1.0}


EFFECT = Foundation()
