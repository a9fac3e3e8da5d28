"""``axial_load``: a constant axial force (geometric stiffness)."""

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
    parameters = (Parameter("tension", "N", "real", "axial force, positive in tension",
                            null=0.0),)

    def contribute(self, model, params, build):
        tension = params["tension"]
        build.add_element_stiffness(lambda L: tension * slope_gram(L))

    def variables(self, model, fixed):
        return [Variable("tension", -0.95, 50.0, (-0.5, 0.0, 0.5, 2.0, 8.0),
                         scale=lambda m: np.pi**2 * nominal_rigidity(m) / m.length**2)]


EFFECT = AxialLoad()
