"""``point_mass``: an attached mass."""

from __future__ import annotations

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    position_variable,
)


class PointMass(EffectType):
    name = "point_mass"
    physics = "a mass attached at one point (a sensor, a fixture)"
    signature = "a local rise of the coefficient of ẅ (ü) at one node"
    kinds = ("beam", "bar")
    local = True
    parameters = (
        Parameter("position", "m", "position", "distance from the left end"),
        Parameter("mass", "kg", "positive", "attached mass", null=0.0),
    )

    def check(self, model, params, where, prefix):
        check_not_on_support(model, params, where, prefix, "point mass", FIXED_TRANSLATION,
                             "the support holds the structure still")

    def contribute(self, model, params, build):
        build.add_point_mass(params["position"], params["mass"])

    def variables(self, model, fixed):
        return [position_variable(model),
                Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5),
                         scale=lambda m: m.rho * m.area * m.length)]

    def starts(self, model, hint):
        return [{}, {"position": hint * model.length,
                     "mass": 0.2 * model.rho * model.area * model.length}]

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="s", color="tab:purple", ms=8, zorder=5)
        ax.annotate(f"{1000 * params['mass']:.3g} g", (x, y), textcoords="offset points",
                    xytext=(0, 9), ha="center", fontsize=7, color="tab:purple")


EFFECT = PointMass()
