"""``attached_body``: a body attached at one point, its mass and its rotary inertia (a tip
block, a fixture, a shaker's armature): a ``point_mass`` that also turns with the beam."""

from __future__ import annotations

import numpy as np

from .base import (
    FIXED_TRANSLATION,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    position_variable,
)


class AttachedBody(EffectType):
    name = "attached_body"
    physics = ("a body attached at one point: its mass m moves with the beam's deflection "
               "and its rotary inertia J turns with the slope there (a point_mass with J)")
    signature = ("a local rise of the coefficients of ẅ and θ̈ at one node (a force m ẅ and "
                 "a moment J ẅ′ there)")
    kinds = ("beam",)
    local = True
    point_moment = True
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
        # the point mass's place and mass; J in units of ρA L³ from 1e-8 (an accelerometer:
        # nothing the modes tell) to 1 (a body as heavy as the beam, its radius of
        # gyration as long)
        return [position_variable(model),
                Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5),
                         scale=lambda m: m.rho * m.area * m.length),
                Variable("inertia", -8.0, 0.0, (-5.0, -4.0, -3.0, -2.0), log=True,
                         scale=lambda m: m.rho * m.area * m.length**3)]

    def starts(self, model, hint):
        return [{}, {"position": hint * model.length,
                     "mass": 0.2 * model.rho * model.area * model.length}]

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
        # the label runs inwards from an end (centred, a tip body's was cut off)
        side = x / model.length
        ha = "right" if side > 0.7 else "left" if side < 0.3 else "center"
        ax.annotate(f"{1000 * params['mass']:.3g} g, J {params['inertia']:.3g} kg m²",
                    (x, y), textcoords="offset points", xytext=(0, 10), ha=ha,
                    fontsize=7, color="tab:purple")


EFFECT = AttachedBody()
