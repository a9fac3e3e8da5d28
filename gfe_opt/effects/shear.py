"""``shear``: Timoshenko shear deformation and rotary inertia (eq. 18)."""

from __future__ import annotations

from .base import EffectType, Parameter, Variable, nominal_rigidity


class Shear(EffectType):
    name = "shear"
    physics = "Timoshenko shear deformation and rotary inertia (deep beams)"
    signature = ("none in the translational row at 4th order: the frequencies fall more "
                 "the higher the mode (∝ n² h²/L²)")
    parameters = (Parameter("shear_rigidity", "N", "positive", "κGA", null="inf"),)

    def contribute(self, model, params, build):
        build.shear_rigidity = params["shear_rigidity"]

    def variables(self, model, fixed):
        return [Variable("shear_rigidity", -1.0, 6.0, (0.0, 1.0, 2.0, 3.0, 5.0), log=True,
                         scale=lambda m: 100.0 * nominal_rigidity(m) / m.length**2)]


EFFECT = Shear()
