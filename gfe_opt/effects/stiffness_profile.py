"""``stiffness_profile``: any distributed change of EI (bar: EA), piecewise linear between
knots: the paper's generic update made into an effect a user can keep."""

from __future__ import annotations

import numpy as np

from .base import Parameter
from .profile import KNOT_COUNTS, ProfileEffect


class StiffnessProfile(ProfileEffect):
    name = "stiffness_profile"
    physics = ("EI(x) = EI · ratio(x), piecewise linear between the knots x (bar: EA; a "
               "frame: along one member, x from its start node)")
    signature = "a distributed change of k along the structure (a taper, a soft region)"
    quantity = "rigidity"
    kinds = ("beam", "bar", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame)"),)

    def fixed_keys(self, model=None) -> tuple:
        """The knots are chosen (a frame: with the member)."""
        if model is not None and model.kind == "frame":
            return ("member", "x")
        return super().fixed_keys(model)

    def starts(self, model, hint):
        """Every knot count (on a frame: along each member)."""
        if model.kind == "frame":
            return [{"member": m.id, "x": [float(v) for v in np.linspace(
                0.0, model.member_length(m), k)]} for m in model.members for k in KNOT_COUNTS]
        return super().starts(model, hint)

    def frame_placeholders(self, model, params):
        known = {m.id: m for m in model.members}
        if params["member"] not in known:   # the frame file's rule says which
            return {"x": [0.0, 1.0], "ratio": [1.0, 1.0]}
        length = model.member_length(known[params["member"]])
        x = params.get("x", [0.0, length])
        return {"x": x, "ratio": [1.0] * (len(x) if isinstance(x, (list, tuple)) else 2)}

    def start_ratio(self, band, model, x, member=None):
        """The paper's generic update (its nodal k_i / k_i0 against its null profile,
        ``band``; on a frame ``member``'s EI reading) fitted by a piecewise-linear function
        with knots x (least squares)."""
        if band is None:
            return None
        if member is None:
            nodes, ratio = model.nodes, band.ratio
        else:   # a frame's band: the member's bending reading
            part = next(b for m, _, b, what in band.members if m == member and what == "EI")
            nodes, ratio = part.x, part.ratio
        hats = np.stack([np.interp(nodes, x, np.eye(len(x))[i])
                         for i in range(len(x))], 1)
        values = np.linalg.lstsq(hats, ratio, rcond=None)[0]
        return [float(v) for v in np.clip(values, 0.06, 2.9)]


EFFECT = StiffnessProfile()
