"""``crack``: a symmetric (double-edged) crack, Christides–Barr EI(x) = EI Q(x) (eq. 25)."""

from __future__ import annotations

import numpy as np

from .. import elements as el
from ..errors import GfeInputError
from .base import (
    FREE_MOMENT,
    EffectType,
    Parameter,
    Variable,
    check_not_on_support,
    frame_position_variable,
    position_variable,
)

#: Q(x) differs from 1 by less than 26 e^-36 (~1e-14) beyond 18 decay lengths
CRACK_REACH = 18.0


class Crack(EffectType):
    name = "crack"
    physics = ("EI(x) = EI Q(x), Christides–Barr disturbance with Shen–Pierre γ = 1.936; "
               "exact-flexibility elements integrated through the crack zone")
    signature = "a local drop of k, a few half-depths wide, and a rise of |k'| beside it"
    local = True
    kinds = ("beam", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame; position "
                                  "from its start node)"),)
    parameters = (
        Parameter("position", "m", "position", "distance of the crack from the left end"),
        Parameter("depth_ratio", "-", "fraction", "a/d: depth of each cut over the "
                  "half-depth d (Christides–Barr)", null=0.0),
    )

    def check(self, model, params, where, prefix):
        if model.depth is None:
            raise GfeInputError(where, f"{prefix}effect", "a crack needs the section depth "
                                "(section.h or shape = 'rectangle')")
        check_not_on_support(model, params, where, prefix, "crack", FREE_MOMENT,
                             "the bending moment is zero")
        if params.get("depth_ratio", 0.0) > 0.95:
            raise GfeInputError(where, f"{prefix}depth_ratio", "must lie between 0 and 0.95 "
                                f"(a/d), got {params['depth_ratio']:g}")

    def contribute(self, model, params, build):
        x_c, ratio = params["position"], params["depth_ratio"]
        half_depth = model.depth / 2.0
        decay = half_depth / (2.0 * el.SHEN_PIERRE_GAMMA)

        def q(x):
            return el.christides_barr_q(x, x_c, ratio, half_depth)

        build.scale_rigidity(q, breakpoints=(x_c,), refine_scale=decay,
                             support=(x_c - CRACK_REACH * decay, x_c + CRACK_REACH * decay))

    def variables(self, model, fixed):
        if model.kind == "frame":   # inside the member
            return [frame_position_variable(model, model.member(fixed["member"])),
                    Variable("depth_ratio", 0.01, 0.9, (0.2, 0.45, 0.7))]
        return [position_variable(),
                Variable("depth_ratio", 0.01, 0.9, (0.2, 0.45, 0.7))]

    def starts(self, model, hint):
        if model.kind == "frame":   # every member whose section has a depth
            return [{"member": m.id} for m in model.members if m.depth is not None]
        return [{}, {"position": hint * model.length, "depth_ratio": 0.45}]

    def frame_placeholders(self, model, params):
        return {"position": 0.5 * model.member_length(model.member(params["member"])),
                "depth_ratio": 0.1}

    def figures(self, model, params, band):
        if band is None or model.depth is None:
            return {}
        return {"disturbance.png": _disturbance_figure(model, params, band)}

    def mark(self, ax, model, params, sigma, y, bounds=None):
        x = params["position"]
        ax.plot([x], [y], marker="v", color="tab:red", ms=9, zorder=5)
        s = (sigma or {}).get("position")
        if s is not None and np.isfinite(s):
            ax.errorbar([x], [y], xerr=[2 * s], color="tab:red", capsize=3, lw=1)
        ax.annotate(f"crack a/d {params['depth_ratio']:.2f} at {x:.3f} m", (x, y),
                    textcoords="offset points", xytext=(0, 9), ha="center", fontsize=7,
                    color="tab:red")


EFFECT = Crack()


def _disturbance_figure(model, params, band):
    """The paper's Fig. 5: identified Q_i = k_i / k_i0 against Christides–Barr Q(x)."""
    from .. import plots

    fine = np.linspace(0, model.length, 2000)
    q = el.christides_barr_q(fine, params["position"], params["depth_ratio"], model.depth / 2)
    return plots.disturbance_function(band.x, band.ratio, fine, q,
                                      label_exact=f"Q(x), fitted a/d = "
                                                  f"{params['depth_ratio']:.2f}")
