"""``stiffness_profile``: any distributed change of EI (bar: EA), piecewise linear between
knots: the paper's generic update made into an effect a user can keep."""

from __future__ import annotations

from .profile import ProfileEffect


class StiffnessProfile(ProfileEffect):
    name = "stiffness_profile"
    physics = "EI(x) = EI · ratio(x), piecewise linear between the knots x (bar: EA)"
    signature = "a distributed change of k along the structure (a taper, a soft region)"
    quantity = "rigidity"


EFFECT = StiffnessProfile()
