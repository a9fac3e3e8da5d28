"""``axial_stiffness``: a frame member whose axial stiffness differs from the model's (a
loose brace: slip at its bolted ends acts in series with the member)."""

from __future__ import annotations

from .base import EffectType, Parameter, Variable


class AxialStiffness(EffectType):
    name = "axial_stiffness"
    physics = ("a member's axial stiffness EA times a ratio, its bending and mass unchanged: a "
               "loose brace (slip at bolted ends in series with the member), a bar that is "
               "not what the drawing says")
    signature = "along one member only: the axial force per unit stretch changes"
    kinds = ("frame",)
    local = True
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame)"),)
    parameters = (Parameter("ratio", "-", "positive", "EA over the modelled EA", null=1.0),)

    def variables(self, model, fixed):
        # log10 of the ratio: 1/1000 to 10 times the modelled EA
        return [Variable("ratio", -3.0, 1.0, (-1.0, -0.5, -0.2, 0.2), log=True)]

    def starts(self, model, hint):
        """Every member."""
        return [{"member": m.id} for m in model.members]

    def frame_placeholders(self, model, params):
        return {"ratio": 1.0}

    def position(self, params):
        return None


EFFECT = AxialStiffness()
