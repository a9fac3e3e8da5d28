"""``section_loss``: stiffness and mass lost together over a zone (corrosion, thinning,
a wide notch)."""

from __future__ import annotations

import numpy as np

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable, position_variable


def zone(centre: float, length: float, ratio: float):
    """The multiplier ``ratio`` inside [centre − length/2, centre + length/2], 1 outside."""
    a, b = centre - length / 2.0, centre + length / 2.0

    def f(x):
        return np.where((x >= a) & (x <= b), ratio, 1.0)

    return f


class SectionLoss(EffectType):
    name = "section_loss"
    physics = "EI and ρA multiplied by stiffness_ratio and mass_ratio over a zone"
    signature = "a local drop of k over the zone's width and of the coefficient of ẅ"
    kinds = ("beam", "bar")
    local = True
    parameters = (
        Parameter("position", "m", "position", "centre of the zone"),
        Parameter("length", "m", "positive", "length of the zone"),
        Parameter("stiffness_ratio", "-", "range", "EI (bar: EA) inside over outside",
                  lower=0.01, upper=10.0, null=1.0),
        Parameter("mass_ratio", "-", "range", "ρA inside over outside", lower=0.01,
                  upper=10.0, null=1.0),
    )

    def check(self, model, params, where, prefix):
        if "length" in params and params["length"] > model.length:
            raise GfeInputError(where, f"{prefix}length", f"{params['length']:g} m is longer "
                                f"than the structure ({model.length:g} m)")

    def contribute(self, model, params, build):
        c, ell = params["position"], params["length"]
        edges = (c - ell / 2.0, c + ell / 2.0)
        build.scale_rigidity(zone(c, ell, params["stiffness_ratio"]), breakpoints=edges,
                             support=edges)
        build.scale_mass(zone(c, ell, params["mass_ratio"]), breakpoints=edges, support=edges)

    def variables(self, model, fixed):
        return [position_variable(),
                Variable("length", 0.004, 0.3, (0.05,), scale=lambda m: m.length),
                # softer and stiffer alike (1/0.7): a start on one side only never found a
                # stiffer zone, and which side a valley of frequencies alone ends on then
                # hinged on rounding
                Variable("stiffness_ratio", 0.05, 3.0, (0.7, 1 / 0.7)),
                # lighter and heavier alike: corrosion (EI and ρA × 0.7) is no better than
                # nothing with ρA held at 1, so a start at 1 alone never found it
                Variable("mass_ratio", 0.05, 3.0, (0.7, 1.0, 1 / 0.7))]

    def starts(self, model, hint):
        return [{}, *({"position": hint * model.length, "length": 0.05 * model.length,
                       "stiffness_ratio": ratio, "mass_ratio": 1.0} for ratio in (0.7, 1 / 0.7))]

    def mark(self, ax, model, params, sigma, y):
        c, ell = params["position"], params["length"]
        ax.plot([c - ell / 2, c + ell / 2], [0.0, 0.0], lw=9, color="tab:orange",
                solid_capstyle="butt", zorder=4)  # the zone on the beam
        ax.annotate(f"EI×{params['stiffness_ratio']:.2f}, ρA×{params['mass_ratio']:.2f}",
                    (c, y), textcoords="offset points", xytext=(0, 9), ha="center",
                    fontsize=7, color="tab:orange")


EFFECT = SectionLoss()
