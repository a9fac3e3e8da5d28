"""``stiffness_profile``: any distributed change of EI (bar: EA), piecewise linear between
knots: the paper's generic update made into an effect a user can keep."""

from __future__ import annotations

import numpy as np

from .profile import ProfileEffect


class StiffnessProfile(ProfileEffect):
    name = "stiffness_profile"
    physics = "EI(x) = EI · ratio(x), piecewise linear between the knots x (bar: EA)"
    signature = "a distributed change of k along the structure (a taper, a soft region)"
    quantity = "rigidity"

    def start_ratio(self, band, model, x):
        """The paper's generic update (its nodal k_i / k_i0 against its null profile,
        ``band``) fitted by a piecewise-linear function with knots x (least squares)."""
        if band is None:
            return None
        hats = np.stack([np.interp(model.nodes, x, np.eye(len(x))[i])
                         for i in range(len(x))], 1)
        values = np.linalg.lstsq(hats, band.ratio, rcond=None)[0]
        return list(np.clip(values, 0.06, 2.9))


EFFECT = StiffnessProfile()
