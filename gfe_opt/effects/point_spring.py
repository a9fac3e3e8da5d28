"""``point_spring``: a translational spring to ground (an intermediate support, an
attachment)."""

from __future__ import annotations

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    nominal_rigidity,
    position_variable,
)


def _scale(model):
    """EI/ℓ³ (beam) or EA/ℓ (bar) [N/m]."""
    power = 3 if model.kind == "beam" else 1
    return nominal_rigidity(model) / model.length**power


class PointSpring(EffectType):
    name = "point_spring"
    physics = "a translational spring to ground at one point"
    signature = "a local rise of the coefficient of w (u) at one node"
    kinds = ("beam", "bar")
    local = True
    parameters = (
        Parameter("position", "m", "position", "distance from the left end"),
        Parameter("stiffness", "N/m", "positive", "spring stiffness", null=0.0),
    )

    def check(self, model, params, where, prefix):
        check_not_on_support(model, params, where, prefix, "point spring", FIXED_TRANSLATION,
                             "the support holds the structure still")

    def contribute(self, model, params, build):
        build.add_point_stiffness(params["position"], params["stiffness"])

    def variables(self, model, fixed):
        return [position_variable(model),
                Variable("stiffness", -3.0, 5.0, (0.0, 1.0, 2.0, 3.0, 4.0), log=True,
                         scale=_scale)]

    def starts(self, model, hint):
        return [{}, {"position": hint * model.length, "stiffness": 10.0 * _scale(model)}]

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="$\\wedge\\!\\!\\vee$", color="tab:green", ms=12, zorder=5)
        at_least = "≥ " if (bounds or {}).get("stiffness") == "at least" else ""
        ax.annotate(f"{at_least}{params['stiffness']:.3g} N/m", (x, y),
                    textcoords="offset points",
                    xytext=(0, 9), ha="center", fontsize=7, color="tab:green")


EFFECT = PointSpring()
