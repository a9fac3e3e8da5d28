"""``point_spring``: a translational spring to ground (an intermediate support, an
attachment)."""

from __future__ import annotations

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    frame_free_ends,
    frame_position_variable,
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
    kinds = ("beam", "bar", "frame")
    local = True
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame; position "
                                  "from its start node, an end is the joint)"),
                        Parameter("direction", "", "choice", "x or y (a frame)",
                                  choices=("x", "y")))
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
        if model.kind == "frame":
            return _frame_variables(model, model.member(fixed["member"]), fixed["direction"])
        return [position_variable(model),
                Variable("stiffness", -3.0, 5.0, (0.0, 1.0, 2.0, 3.0, 4.0), log=True,
                         scale=_scale)]

    def starts(self, model, hint):
        if model.kind == "frame":   # along every member, across it (x and y if inclined)
            return [{"member": m.id, "direction": d} for m in model.members
                    for d in across_directions(model, m)]
        return [{}, {"position": hint * model.length, "stiffness": 10.0 * _scale(model)}]

    def frame_placeholders(self, model, params):
        return {"position": 0.5 * model.member_length(model.member(params["member"])),
                "stiffness": 1.0}

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="$\\wedge\\!\\!\\vee$", color="tab:green", ms=12, zorder=5)
        at_least = "≥ " if (bounds or {}).get("stiffness") == "at least" else ""
        ax.annotate(f"{at_least}{params['stiffness']:.3g} N/m", (x, y),
                    textcoords="offset points",
                    xytext=(0, 9), ha="center", fontsize=7, color="tab:green")


def across_directions(model, member) -> tuple[str, ...]:
    """The directions of ``x`` and ``y`` not along ``member``'s axis (both on an inclined
    member).  A spring along a member's axis at a place inside it moves with the member's
    axial motion, uniform along it to within the spring's k/(EA/ℓ): it cannot be told from
    the same spring at the member's end joint, where the members meeting it at an angle
    hold it across their axes.  Such a spring is fitted when asked for by name
    (``--add point_spring:member=beam,direction=x``)."""
    (x0, y0), (x1, y1) = model.nodes[member.start], model.nodes[member.end]
    along = {"x": abs(y1 - y0) <= 1e-12 * abs(x1 - x0),
             "y": abs(x1 - x0) <= 1e-12 * abs(y1 - y0)}
    return tuple(d for d in ("x", "y") if not along[d])


def _frame_variables(model, member, direction):
    """x / member length (the grid's 19 interior places and each end whose node no support
    holds along ``direction``) and the stiffness in units of the member's EI/ℓ³, the same
    range and grid as on a beam."""
    from ..frame import RELEASES

    ends = frame_free_ends(model, member, (RELEASES[direction],))
    own = member.E * member.inertia / model.member_length(member) ** 3
    return [frame_position_variable(model, member, ends),
            Variable("stiffness", -3.0, 5.0, (0.0, 1.0, 2.0, 3.0, 4.0), log=True,
                     scale=lambda m: own)]


EFFECT = PointSpring()
