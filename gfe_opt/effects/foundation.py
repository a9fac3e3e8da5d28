"""``foundation``: a Winkler elastic foundation."""

from __future__ import annotations

import numpy as np

from .. import elements as el
from .base import EffectType, Parameter, Variable, nominal_rigidity


class Foundation(EffectType):
    name = "foundation"
    physics = "Winkler foundation: a distributed spring k_f per unit length"
    signature = "a uniform k_f w term at every node"
    parameters = (Parameter("stiffness", "N/m^2", "positive", "foundation modulus k_f",
                            null=0.0),)

    def contribute(self, model, params, build):
        k = params["stiffness"]
        shape = el.symmetric_beam_mass(**el.CONSISTENT_BEAM_MASS)  # ∫ N Nᵀ dx / L
        build.add_element_stiffness(lambda L: k * L * shape)

    def variables(self, model, fixed):
        return [Variable("stiffness", 1e-4, 100.0, (0.05, 0.5, 2.0, 10.0),
                         scale=lambda m: nominal_rigidity(m) * (np.pi / m.length) ** 4)]


EFFECT = Foundation()
