"""``mass_profile``: any distributed change of ρA, piecewise linear between knots."""

from __future__ import annotations

from .base import Parameter
from .profile import KNOT_COUNTS, ProfileEffect


class MassProfile(ProfileEffect):
    name = "mass_profile"
    physics = ("ρA(x) = ρA · ratio(x), piecewise linear between the knots x (a frame: along "
               "one member, x from its start node: a floor's non-structural mass, a cladding)")
    signature = "a distributed change of the coefficient of ẅ (ü) along the structure"
    quantity = "mass"
    knot_counts = KNOT_COUNTS[:3]
    kinds = ("beam", "bar", "frame")
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame)"),)
    #: on a frame only when named (``update --add mass_profile:member=ID``,
    #: ``--candidates``): no campaign has judged it among the frames' candidates
    frame_candidate = False


EFFECT = MassProfile()
