"""``shear``: Timoshenko shear deformation and rotary inertia (eq. 18); on a frame every
member Timoshenko, ``shear_rigidity`` the first member's κGA (each member's its GA over the
first's times it)."""

from __future__ import annotations

from .base import EffectType, Parameter, Variable, nominal_rigidity


class Shear(EffectType):
    name = "shear"
    physics = "Timoshenko shear deformation and rotary inertia (deep beams)"
    signature = ("none in the translational row at 4th order: the frequencies fall more "
                 "the higher the mode (∝ n² h²/L²)")
    kinds = ("beam", "frame")
    parameters = (Parameter("shear_rigidity", "N", "positive", "κGA", null="inf"),)

    def contribute(self, model, params, build):
        build.shear_rigidity = params["shear_rigidity"]

    def variables(self, model, fixed):
        """log₁₀ of κGA over 100 EI/ℓ² (the beam's; on a frame the first member's EI and
        length): from a g of 0.12 over the whole length (grid 0) to none (6)."""
        if model.kind == "frame":
            first = model.members[0]
            own = 100.0 * first.E * first.inertia / model.member_length(first) ** 2

            def scale(m):
                return own
        else:
            def scale(m):
                return 100.0 * nominal_rigidity(m) / m.length**2
        return [Variable("shear_rigidity", -1.0, 6.0, (0.0, 1.0, 2.0, 3.0, 5.0), log=True,
                         scale=scale)]

    def frame_placeholders(self, model, params):
        return {"shear_rigidity": 1.0}


EFFECT = Shear()
