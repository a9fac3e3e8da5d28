"""``rotary_inertia``: the rotary inertia of an attached body (a tip block, a shaker's
armature, a bolted fixture) that turns with the beam."""

from __future__ import annotations

import numpy as np

from .base import (
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    frame_free_ends,
    frame_position_variable,
    inward,
)

#: supports that hold the rotation still: a rotary inertia there does nothing
FIXED_ROTATION = ("clamped", "sliding")


def inertia_variable(member=None) -> Variable:
    """A body's J in units of ρA L³, from 1e-8 (an accelerometer on a long beam: nothing
    the modes tell) to 1 (a body as heavy as the beam with a radius of gyration as long);
    ``attached_body``'s too.  On a frame, ``member``'s own ρA L³."""
    scale = (lambda m: m.rho * m.area * m.length**3) if member is None else \
        (lambda m: member.rho * member.area * m.member_length(member)**3)
    return Variable("inertia", -8.0, 0.0, (-5.0, -4.0, -3.0, -2.0), log=True, scale=scale)


class RotaryInertia(EffectType):
    name = "rotary_inertia"
    physics = ("the rotary inertia J of a body attached at one point, which turns with the "
               "beam's slope there (kinetic energy J θ̇²/2); its mass is a point_mass")
    signature = "a local rise of the coefficient of θ̈ at one node (a moment J ẅ′ there)"
    kinds = ("beam", "frame")
    local = True
    point_moment = True
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame; position "
                                  "from its start node, an end is the joint)"),)
    parameters = (
        Parameter("position", "m", "position", "where the body is attached"),
        Parameter("inertia", "kg m^2", "positive", "rotary inertia about the beam's "
                  "neutral axis at that point", null=0.0),
    )

    def candidate_for(self, model) -> bool:
        """Tried by ``diagnose`` only on a model that holds an attached mass: a body's
        rotary inertia comes with its mass, and a point mass alone leaves a body of some
        size a difference near it (the ends of the moment J ω² θ)."""
        return any(e.name == "point_mass" for e in model.effects)

    def check(self, model, params, where, prefix):
        check_not_on_support(model, params, where, prefix, "rotary inertia", FIXED_ROTATION,
                             "the support holds the rotation still")

    def contribute(self, model, params, build):
        build.add_point_inertia(params["position"], params["inertia"])

    def variables(self, model, fixed):
        # its place along the beam (each end whose rotation is free: the tip of a
        # cantilever) and J
        if model.kind == "frame":
            member = model.member(fixed["member"])
            # its 19 interior places and each end no support holds in rotation
            place = frame_position_variable(model, member, frame_free_ends(model, member, (2,)))
            return [place, inertia_variable(member)]
        ends = tuple(float(end) for end in (0, 1) if model.supports[end] not in FIXED_ROTATION)
        return [Variable("position", 0.0, 1.0, tuple(np.linspace(0.05, 0.95, 19)) + ends,
                         scale=lambda m: m.length), inertia_variable()]

    def starts(self, model, hint):
        """At each attached mass of the model (the body whose inertia it is); else from
        the grid along the beam."""
        if model.kind == "frame":
            places = [{"member": e.parameters["member"],
                       "position": float(e.parameters["position"])}
                      for e in model.effects if e.name == "point_mass"]
            return places or [{"member": m.id} for m in model.members]
        places = sorted({float(e.parameters["position"]) for e in model.effects
                         if e.name == "point_mass" and "position" in e.parameters})
        return [{"position": x} for x in places] or [{}]

    def frame_placeholders(self, model, params):
        return {"position": 0.5 * model.member_length(model.member(params["member"])),
                "inertia": 1.0}

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="$\\circlearrowright$", color="tab:purple", ms=11, zorder=5)
        ax.annotate(f"J {params['inertia']:.3g} kg m²", (x, y), textcoords="offset points",
                    xytext=(0, -14), ha=inward(model, x), fontsize=7, color="tab:purple")


EFFECT = RotaryInertia()
