"""``mass_profile``: any distributed change of ρA, piecewise linear between knots."""

from __future__ import annotations

from .profile import KNOT_COUNTS, ProfileEffect


class MassProfile(ProfileEffect):
    name = "mass_profile"
    physics = "ρA(x) = ρA · ratio(x), piecewise linear between the knots x"
    signature = "a distributed change of the coefficient of ẅ (ü) along the structure"
    quantity = "mass"
    knot_counts = KNOT_COUNTS[:3]


EFFECT = MassProfile()
