"""``section_loss``: stiffness and mass lost together over a zone (corrosion, thinning,
a wide notch)."""

from __future__ import annotations

import numpy as np

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable, frame_position_variable, position_variable


def zone(centre: float, length: float, ratio: float):
    """The multiplier ``ratio`` inside [centre − length/2, centre + length/2], 1 outside."""
    a, b = centre - length / 2.0, centre + length / 2.0

    def f(x):
        return np.where((x >= a) & (x <= b), ratio, 1.0)

    return f


def _on_ends(variables, z):
    """(i, j, at_left, at_right): the indices of the fitted centre and length among the
    variables and whether the zone reaches each end (z in fractions of the length), or None
    when either is held."""
    keys = [v.key for v in variables]
    if "position" not in keys or "length" not in keys:
        return None
    i, j = keys.index("position"), keys.index("length")
    return i, j, z[i] - z[j] / 2 <= 1e-12, z[i] + z[j] / 2 >= 1 - 1e-12


#: how far past an end (fraction of the length) a zone with an edge on that end starts a fit:
#: any distance does (the zone on the structure is the same); one start grid step of the
#: zone's length
PAST_END = 0.05


#: on a frame, a zone from each end of a member (a haunch, a corroded foot) is one more
#: start, this fraction of the member long: the grid's zones (0.05 of it) lie inside, and
#: IPOPT stopped short of an end when the zone reaches it (the residual's kink there)
END_ZONE = 0.2


class SectionLoss(EffectType):
    name = "section_loss"
    physics = "EI and ρA multiplied by stiffness_ratio and mass_ratio over a zone"
    signature = "a local drop of k over the zone's width and of the coefficient of ẅ"
    kinds = ("beam", "bar", "frame")
    local = True
    #: on a frame: EI × stiffness_ratio, ρA and EA × mass_ratio (the zone's area changes as
    #: its mass, the material stays), over a zone of one member that may reach its joints
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame; position "
                                  "of the zone's centre from its start node)"),)
    parameters = (
        Parameter("position", "m", "position", "centre of the zone"),
        Parameter("length", "m", "positive", "length of the zone"),
        Parameter("stiffness_ratio", "-", "range", "EI (bar: EA) inside over outside",
                  lower=0.01, upper=10.0, null=1.0),
        Parameter("mass_ratio", "-", "range", "ρA inside over outside", lower=0.01,
                  upper=10.0, null=1.0),
    )

    def told_trades(self, model):
        """On a frame, a zone shorter than the modes resolve is told by its place, its added
        compliance ℓ (1/r − 1) and its added mass ℓ (m − 1): its length against its ratios
        is a finding, not a failure (a stiffer zone has no two-parameter equivalent, as a
        crack is of a short softer one; found on the frame campaign's zone-3107, a 4 cm
        stiffer zone that otherwise left a crack on the wrong column).  Beams keep the
        stricter rule their campaign judged."""
        if model.kind != "frame":
            return ()
        keys = ("length", "stiffness_ratio", "mass_ratio")
        return tuple(frozenset((a, b)) for i, a in enumerate(keys) for b in keys[i + 1:])

    def told_values(self, model, params):
        """On a frame, what a zone's trade leaves told: its added bending compliance
        ∫ (1/EI − 1/EI₀) dx = ℓ (1/r − 1)/EI₀ [rad/(N m)] and its added mass
        ρA ℓ (m − 1) [kg] (EI₀, ρA its member's)."""
        if model.kind != "frame" or "member" not in params:
            return {}
        member = model.member(params["member"])
        ell = params["length"]
        ei0 = model.stiffness_factor * member.E * member.inertia
        return {"compliance": ("added bending compliance ℓ (1/r − 1)/EI", "rad/(N m)",
                               ell * (1.0 / params["stiffness_ratio"] - 1.0) / ei0),
                "mass": ("added mass ρA ℓ (m − 1)", "kg",
                         member.rho * member.area * ell * (params["mass_ratio"] - 1.0))}

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
        # a zone may span any part of the structure, up to an end (a step in the section
        # over the outer half): no bound below the structure's length
        span = _span(model, fixed)
        return [frame_position_variable(model, model.member(fixed["member"]))
                if model.kind == "frame" else position_variable(),
                Variable("length", 0.004, 1.0, (0.05,), scale=lambda m: span),
                # softer and stiffer alike (1/0.7): a start on one side only never found a
                # stiffer zone, and which side a valley of frequencies alone ends on then
                # hinged on rounding
                Variable("stiffness_ratio", 0.05, 3.0, (0.7, 1 / 0.7)),
                # lighter and heavier alike: corrosion (EI and ρA × 0.7) is no better than
                # nothing with ρA held at 1, so a start at 1 alone never found it
                Variable("mass_ratio", 0.05, 3.0, (0.7, 1.0, 1 / 0.7))]

    def to_physical(self, model, variables, z, fixed):
        """The zone as it lies on the structure: a zone fitted past an end is the part of it
        on the structure (its centre and length), so that every fit of one zone has one
        set of parameters (past the end, centre and length trade exactly)."""
        out = super().to_physical(model, variables, z, fixed)
        if "position" in out and "length" in out:
            L = _span(model, fixed)
            a = max(out["position"] - out["length"] / 2.0, 0.0)
            b = min(out["position"] + out["length"] / 2.0, L)
            if b > a:
                out["position"], out["length"] = (a + b) / 2.0, b - a
        return out

    def tie(self, model, variables, z):
        """A zone that reaches an end has one edge there: its centre and length move
        together as its inner edge moves (the outer edge stays on the end).  Returns the
        columns that move the slot's variables (one for the inner edge, one per other
        variable) and their labels, or None when the zone lies inside the structure.  A zone
        over the whole structure has no inner edge: its centre and length are held (σ
        infinite: it is a change of E and ρA, not a zone)."""
        ends = _on_ends(variables, z)
        if ends is None or not (ends[2] or ends[3]):
            return None
        i, j, at_left, at_right = ends
        keys = [v.key for v in variables]
        columns, labels = [], []
        if not (at_left and at_right):   # the whole structure: centre and length are held
            edge = np.zeros(len(keys))
            edge[i], edge[j] = 0.5, (-1.0 if at_right else 1.0)
            columns.append(edge)
            labels.append("inner edge")
        for k, key in enumerate(keys):
            if k not in (i, j):
                unit = np.zeros(len(keys))
                unit[k] = 1.0
                columns.append(unit)
                labels.append(key)
        return np.array(columns).T.reshape(len(keys), len(columns)), labels

    def untie(self, model, variables, z):
        """A zone with an edge on an end, with that edge moved past the end by
        :data:`PAST_END` of the length (the zone on the structure is the same; on the end
        itself the residual has a kink: moving the edge inwards changes it, outwards not)."""
        ends = _on_ends(variables, z)
        if ends is None or ends[2] == ends[3]:
            return z    # held, inside, or the whole structure
        i, j, _, at_right = ends
        z = np.array(z, dtype=float)
        a, b = z[i] - z[j] / 2, z[i] + z[j] / 2
        if at_right:
            b = 1 + PAST_END
        else:
            a = -PAST_END
        if b - a > 1.0:   # the length's bound: the zone cannot reach that far past the end
            return z
        z[i], z[j] = (a + b) / 2, b - a
        return z

    def snap(self, model, variables, z):
        """A zone inside the structure whose nearer edge is closer to its end than the zone
        is long: the zone from its inner edge to past that end (:data:`PAST_END`).  Damped
        steps stop where the data no longer move an edge (near a pinned end a zone's last
        millimetres carry almost no strain energy); on the end the zone is one parameter
        fewer."""
        ends = _on_ends(variables, z)
        if ends is None or ends[2] or ends[3]:
            return None
        i, j = ends[:2]
        a, b = z[i] - z[j] / 2, z[i] + z[j] / 2
        if min(a, 1 - b) >= z[j]:
            return None
        if a < 1 - b:
            a = -PAST_END
        else:
            b = 1 + PAST_END
        if b - a > 1.0:
            return None
        z = np.array(z, dtype=float)
        z[i], z[j] = (a + b) / 2, b - a
        return z

    def frame_placeholders(self, model, params):
        span = model.member_length(model.member(params["member"]))
        return {"position": 0.5 * span, "length": 0.05 * span, "stiffness_ratio": 0.7,
                "mass_ratio": 1.0}

    def starts(self, model, hint):
        if model.kind == "frame":   # along every member; and from each of its ends
            out = []
            for m in model.members:
                span = model.member_length(m)
                out += [{"member": m.id}, *({"member": m.id, "position": c * span,
                                             "length": END_ZONE * span} for c in
                                            (END_ZONE / 2, 1 - END_ZONE / 2))]
            return out
        return [{}, *({"position": hint * model.length, "length": 0.05 * model.length,
                       "stiffness_ratio": ratio, "mass_ratio": 1.0} for ratio in (0.7, 1 / 0.7))]

    def mark(self, ax, model, params, sigma, y, bounds=None):
        c, ell = params["position"], params["length"]
        ax.plot([c - ell / 2, c + ell / 2], [0.0, 0.0], lw=9, color="tab:orange",
                solid_capstyle="butt", zorder=4)  # the zone on the beam
        rigidity = "EA" if getattr(model, "kind", None) == "bar" else "EI"
        ax.annotate(f"{rigidity}×{params['stiffness_ratio']:.2f}, "
                    f"ρA×{params['mass_ratio']:.2f}",
                    (c, y), textcoords="offset points", xytext=(0, 9), ha="center",
                    fontsize=7, color="tab:orange")


def _span(model, fixed) -> float:
    """The length a zone lies along: the structure's, or on a frame its member's."""
    if model.kind == "frame":
        return model.member_length(model.member(fixed["member"]))
    return model.length


EFFECT = SectionLoss()
