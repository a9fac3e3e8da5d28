"""``point_mass``: an attached mass."""

from __future__ import annotations

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    frame_free_ends,
    frame_position_variable,
    position_variable,
)


class PointMass(EffectType):
    name = "point_mass"
    physics = "a mass attached at one point (a sensor, a fixture)"
    signature = "a local rise of the coefficient of ẅ (ü) at one node"
    kinds = ("beam", "bar", "frame")
    local = True
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame; position "
                                  "from its start node, an end is the joint)"),)
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
        if model.kind == "frame":
            return _frame_variables(model, model.member(fixed["member"]))
        return [position_variable(model),
                Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5),
                         scale=lambda m: m.rho * m.area * m.length)]

    def starts(self, model, hint):
        if model.kind == "frame":   # along every member, its free ends included
            return [{"member": m.id} for m in model.members]
        return [{}, {"position": hint * model.length,
                     "mass": 0.2 * model.rho * model.area * model.length}]

    def frame_placeholders(self, model, params):
        return {"position": 0.5 * model.member_length(model.member(params["member"])),
                "mass": 1.0}

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="s", color="tab:purple", ms=8, zorder=5)
        ax.annotate(f"{1000 * params['mass']:.3g} g", (x, y), textcoords="offset points",
                    xytext=(0, 9), ha="center", fontsize=7, color="tab:purple")


def _frame_variables(model, member):
    """x / member length (the grid's 19 interior places and each end whose node no
    support holds in both translations) and the mass in units of the member's own."""
    ends = frame_free_ends(model, member, (0, 1))
    own = member.rho * member.area * model.member_length(member)
    return [frame_position_variable(model, member, ends),
            Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5), scale=lambda m: own)]


EFFECT = PointMass()
