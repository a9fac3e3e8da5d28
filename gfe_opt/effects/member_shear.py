"""``member_shear``: one frame member Timoshenko (shear deformation and rotary inertia,
eq. 18) with its own κGA: a deep member among slender ones, or beside a ``shear`` (every
member Timoshenko with one κ) a member whose κ is not the others' (an I-section among
rectangles), its κGA then this one.  Not tried by ``diagnose`` unless named
(``--candidates member_shear``): its ``shear`` covers a frame of deep members."""

from __future__ import annotations

from .base import EffectType, Parameter, Variable


class MemberShear(EffectType):
    name = "member_shear"
    physics = ("Timoshenko shear deformation and rotary inertia of one member, its own κGA "
               "(a deep member among slender ones)")
    signature = ("along one member only: its frequencies fall more the higher the mode "
                 "(∝ n² h²/ℓ²)")
    kinds = ("frame",)
    local = True
    candidate = False
    frame_parameters = (Parameter("member", "", "choice", "the member (a frame)"),)
    parameters = (Parameter("shear_rigidity", "N", "positive", "κGA of the member",
                            null="inf"),)

    def variables(self, model, fixed):
        """log₁₀ of κGA over 100 EI/ℓ² of the member (``shear``'s range on its member)."""
        member = model.member(fixed["member"])
        own = 100.0 * member.E * member.inertia / model.member_length(member) ** 2
        return [Variable("shear_rigidity", -1.0, 6.0, (0.0, 1.0, 2.0, 3.0, 5.0), log=True,
                         scale=lambda m: own)]

    def starts(self, model, hint):
        """Every member."""
        return [{"member": m.id} for m in model.members]

    def frame_placeholders(self, model, params):
        return {"shear_rigidity": 1.0}

    def position(self, params):
        return None


EFFECT = MemberShear()
