"""``material``: a uniform Young's modulus other than the model file's."""

from __future__ import annotations

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable


class Material(EffectType):
    name = "material"
    physics = "uniform Young's modulus (wrong material data, temperature)"
    signature = "a uniform change of the coefficient k of w'''' (bar: of u'') at every node"
    kinds = ("beam", "bar", "frame")
    parameters = (Parameter("E", "Pa", "positive", "Young's modulus", null="E"),)
    #: E and a stiffness profile are one parameter: E is held when a profile is fitted
    redundant_with = ("stiffness_profile",)
    uniform_reference = True

    def check(self, model, params, where, prefix):
        if "E" in params and not 1e7 <= params["E"] <= 1e13:
            raise GfeInputError(where, f"{prefix}E", f"{params['E']:g} Pa is outside "
                                "1e7..1e13 Pa: give E in Pa")

    def youngs_modulus(self, params, E):
        return float(params["E"])

    def contribute(self, model, params, build):
        """E enters through :attr:`Model.youngs_modulus`; nothing else changes."""

    def variables(self, model, fixed):
        return [Variable("E", 0.5, 2.0, (0.9, 1.0, 1.1), scale=lambda m: m.E)]


EFFECT = Material()
