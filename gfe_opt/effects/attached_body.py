"""``attached_body``: a body attached at one point, its mass and its rotary inertia (a tip
block, a fixture, a shaker's armature): a ``point_mass`` that also turns with the beam."""

from __future__ import annotations

import numpy as np

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    check_not_on_support,
    inward,
)
from .point_mass import EFFECT as POINT_MASS
from .rotary_inertia import inertia_variable


class AttachedBody(EffectType):
    name = "attached_body"
    physics = ("a body attached at one point: its mass m moves with the beam's deflection "
               "and its rotary inertia J turns with the slope there (a point_mass with J)")
    signature = ("a local rise of the coefficients of ẅ and θ̈ at one node (a force m ẅ and "
                 "a moment J ẅ′ there)")
    kinds = ("beam", "frame")
    local = True
    point_moment = True
    frame_parameters = POINT_MASS.frame_parameters
    #: not tried by default as a candidate of its own: ``diagnose`` reads a significant
    #: point mass again as a body where nothing explains the data (selection step 6)
    candidate = False
    present_at_null = ("inertia",)
    simpler = "point_mass"
    parameters = (
        Parameter("position", "m", "position", "where the body is attached"),
        Parameter("mass", "kg", "positive", "the body's mass", null=0.0),
        Parameter("inertia", "kg m^2", "positive", "its rotary inertia about the beam's "
                  "neutral axis at that point", null=0.0),
    )

    def check(self, model, params, where, prefix):
        # on a pinned end the body's J still acts, its mass not: that is a rotary_inertia
        check_not_on_support(model, params, where, prefix, "body's mass", FIXED_TRANSLATION,
                             "the support holds the translation still (for the body's "
                             "rotary inertia alone: rotary_inertia)")

    def contribute(self, model, params, build):
        build.add_point_mass(params["position"], params["mass"])
        build.add_point_inertia(params["position"], params["inertia"])

    def variables(self, model, fixed):
        # the point mass's place and mass (a beam's; a frame member's), and J
        member = model.member(fixed["member"]) if model.kind == "frame" else None
        return [*POINT_MASS.variables(model, fixed), inertia_variable(member)]

    def starts(self, model, hint):
        """A beam's: the point mass's.  A frame's: on every member, its grid and the grid
        with each J of the J grid given (:meth:`every_start`: each run to its end)."""
        if model.kind != "frame":
            return POINT_MASS.starts(model, hint)
        return [s for start in POINT_MASS.starts(model, hint)
                for s in (start, *self.with_each_inertia(model, start))]

    def with_each_inertia(self, model, start: dict) -> list[dict]:
        """``start`` (on a frame: its member given) with each J of the J grid given."""
        J = inertia_variable(model.member(start["member"]))
        return [{**start, "inertia": J.physical(model, z)} for z in J.grid]

    def every_start(self, model) -> bool:
        # on a frame: from the grid's best point alone the fit stayed where a point mass
        # stands for a small J by sliding off the joint (a 0.31 kg block of r 1.6 cm at the
        # portal's corner C: the mass 1.5 cm inside the beam, J 0.1 σ from 0, χ²/n 4.6
        # against 0.96 with the body on C; scripts/study_frame_body.py).  A beam's fits are
        # as they were (scripts/study_tip_body.py, not run again for this)
        return model.kind == "frame"

    def frame_placeholders(self, model, params):
        return {**POINT_MASS.frame_placeholders(model, params), "inertia": 1.0}

    def size_in_sigmas(self, model, params, sigma):
        """How far from a point mass, not from nothing: the inertia's distance from 0 in
        σ (a body whose J the data do not tell is the point mass, which has a parameter
        fewer)."""
        value, sig = params.get("inertia", 0.0), sigma.get("inertia", np.inf)
        z = value / sig if sig and np.isfinite(sig) else 0.0
        return float(z) if np.isfinite(z) else 0.0

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="s", color="tab:purple", ms=8, zorder=5)
        ax.plot([x], [y], marker="$\\circlearrowright$", color="tab:purple", ms=16, zorder=5)
        ax.annotate(f"{1000 * params['mass']:.3g} g, J {params['inertia']:.3g} kg m²",
                    (x, y), textcoords="offset points", xytext=(0, 10), ha=inward(model, x),
                    fontsize=7, color="tab:purple")


EFFECT = AttachedBody()
