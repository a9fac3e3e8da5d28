"""Shared form of the two profile effects (``stiffness_profile``, ``mass_profile``)."""

from __future__ import annotations

import numpy as np

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable

#: knot counts diagnose tries, coarse to fine (each set contains the previous one)
KNOT_COUNTS = (2, 3, 5, 9)


def piecewise_linear(x_knots, ratios):
    xk, rk = np.asarray(x_knots, float), np.asarray(ratios, float)

    def f(x):
        return np.interp(x, xk, rk)

    return f


class ProfileEffect(EffectType):
    kinds = ("beam", "bar")
    #: diagnose offers profiles when no named effect explains the data
    fallback = True
    #: "rigidity" or "mass": which distribution the ratio multiplies
    quantity = ""
    parameters = (
        Parameter("x", "m", "knots", "knot positions, increasing, from one end to the other"),
        Parameter("ratio", "-", "ratios", "value over the model's at each knot", null=1.0),
    )

    def check(self, model, params, where, prefix):
        if "x" in params and "ratio" in params and len(params["x"]) != len(params["ratio"]):
            raise GfeInputError(where, f"{prefix}ratio", f"has {len(params['ratio'])} values "
                                f"for {len(params['x'])} knots")

    def contribute(self, model, params, build):
        f = piecewise_linear(params["x"], params["ratio"])
        scale = build.scale_rigidity if self.quantity == "rigidity" else build.scale_mass
        scale(f, breakpoints=tuple(params["x"][1:-1]))

    #: knot counts diagnose tries, coarse to fine (each set contains the previous one)
    knot_counts = KNOT_COUNTS

    def variables(self, model, fixed):
        return [Variable("ratio", 0.05, 3.0, (1.0,), index=i) for i in range(len(fixed["x"]))]

    def start_ratio(self, band, model, x, member=None):
        """Starting ratios at knots x (on a frame along ``member``; None: 1 everywhere)."""
        return None

    def starts(self, model, hint):
        """Every knot count (on a frame: along each member)."""
        if model.kind == "frame":
            return [{"member": m.id, "x": [float(v) for v in np.linspace(
                0.0, model.member_length(m), k)]} for m in model.members for k in KNOT_COUNTS]
        return [{"x": list(np.linspace(0.0, model.length, k))} for k in KNOT_COUNTS]

    def fixed_keys(self, model=None) -> tuple:
        """The knots are chosen (a frame: with the member)."""
        if model is not None and model.kind == "frame":
            return ("member", "x")
        return super().fixed_keys(model)

    def frame_placeholders(self, model, params):
        known = {m.id: m for m in model.members}
        if params["member"] not in known:   # the frame file's rule says which
            return {"x": [0.0, 1.0], "ratio": [1.0, 1.0]}
        length = model.member_length(known[params["member"]])
        x = params.get("x", [0.0, length])
        return {"x": x, "ratio": [1.0] * (len(x) if isinstance(x, (list, tuple)) else 2)}

    def position(self, params):
        return None

    def mark(self, ax, model, params, sigma, y, bounds=None):
        ax.plot(params["x"], [y] * len(params["x"]), "|", color="tab:brown", ms=8)
