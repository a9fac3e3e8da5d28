"""``stiffness_profile``: any distributed change of EI (bar: EA), piecewise linear between
knots: the paper's generic update made into an effect a user can keep."""

from __future__ import annotations

import numpy as np

from .base import Parameter
from .profile import ProfileEffect


class StiffnessProfile(ProfileEffect):
    name = "stiffness_profile"
    physics = ("EI(x) = EI · ratio(x), piecewise linear between the knots x (bar: EA; a "
               "frame: along one member, x from its start node)")
    signature = "a distributed change of k along the structure (a taper, a soft region)"
    quantity = "rigidity"
    kinds = ("beam", "bar", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame)"),)

    def start_ratio(self, band, model, x, member=None):
        """The paper's generic update (its nodal k_i / k_i0 against its null profile,
        ``band``; on a frame ``member``'s EI reading) fitted by a piecewise-linear function
        with knots x (least squares)."""
        if band is None:
            return None
        if member is None:   # (where the band reads: a beam's nodes, a bar's elements)
            nodes, ratio = band.x, band.ratio
        else:   # a frame's band: the member's bending reading
            part = next(b for m, _, b, what in band.members if m == member and what == "EI")
            nodes, ratio = part.x, part.ratio
        hats = np.stack([np.interp(nodes, x, np.eye(len(x))[i])
                         for i in range(len(x))], 1)
        values = np.linalg.lstsq(hats, ratio, rcond=None)[0]
        return [float(v) for v in np.clip(values, 0.06, 2.9)]


EFFECT = StiffnessProfile()
