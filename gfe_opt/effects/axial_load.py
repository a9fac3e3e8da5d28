"""``axial_load``: a constant axial force (geometric stiffness): of the whole beam, or of one
member of a frame (a tie rod's or a brace's pretension, a column's share of a floor's
weight)."""

from __future__ import annotations

import numpy as np

from .. import elements as el
from .base import EffectType, Parameter, Variable, nominal_rigidity


def slope_gram(L: float) -> np.ndarray:
    r""":math:`\int N' N'^T dx` of the Hermite element in scaled DOFs (geometric stiffness)."""
    return el.timoshenko_rotary_inertia(1.0, L, 0.0)


class AxialLoad(EffectType):
    name = "axial_load"
    physics = "geometric stiffness of a constant axial force T (tension > 0)"
    signature = "a uniform −T w'' term at every node"
    kinds = ("beam", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member that carries it (a "
                                  "frame)"),)
    parameters = (Parameter("tension", "N", "real", "axial force, positive in tension",
                            null=0.0),)

    def is_local(self, model) -> bool:
        """One force on a beam; on a frame one a member, any number of members."""
        return model.kind == "frame"

    def contribute(self, model, params, build):
        tension = params["tension"]
        build.add_element_stiffness(lambda L: tension * slope_gram(L))

    def variables(self, model, fixed):
        """T over the Euler load π²EI/L² of the beam, or of the member (pinned at both ends):
        −0.95 to 50 of it."""
        if model.kind == "frame":
            member = model.member(fixed["member"])
            euler = np.pi**2 * member.E * member.inertia / model.member_length(member) ** 2

            def scale(m):
                return euler
        else:
            def scale(m):
                return np.pi**2 * nominal_rigidity(m) / m.length**2
        return [Variable("tension", -0.95, 50.0, (-0.5, 0.0, 0.5, 2.0, 8.0), scale=scale)]

    def starts(self, model, hint):
        """On a frame every member; a beam's force is one."""
        if model.kind == "frame":
            return [{"member": m.id} for m in model.members]
        return [{}]

    def frame_placeholders(self, model, params):
        return {"tension": 0.0}


EFFECT = AxialLoad()
