"""Physical effects, one object each, in a registry that user code may extend.

Every effect is an :class:`EffectType` (see :mod:`gfe_opt.effects.base`); the built-in ones
live one per file in this package.  :func:`register_effect` adds an effect of your own, which
``diagnose`` and ``update`` (and ``--add`` on the command line of a program that registers
it) then use like the built-in ones::

    import gfe_opt
    from gfe_opt.effects import EffectType, Parameter, Variable

    class TipMass(EffectType):
        name = "tip_mass"
        physics = "a mass at the right end"
        kinds = ("beam", "bar")
        parameters = (Parameter("mass", "kg", "positive", "attached mass", null=0.0),)

        def contribute(self, model, params, build):
            build.add_point_mass(model.length, params["mass"])

        def variables(self, model, fixed):
            return [Variable("mass", 1e-4, 3.0, (0.05, 0.2),
                             scale=lambda m: m.rho * m.area * m.length)]

    gfe_opt.register_effect(TipMass())
"""

from __future__ import annotations

import difflib

from ..errors import GfeInputError
from .base import EffectType, Parameter, Variable, format_value, nominal_rigidity

#: name -> effect, in the order users see them
EFFECTS: dict[str, EffectType] = {}


def register_effect(effect: EffectType, *, replace: bool = False) -> EffectType:
    """Add ``effect`` (an :class:`EffectType` instance) to the registry; a name already
    taken is an error unless ``replace``."""
    if not isinstance(effect, EffectType):
        raise TypeError("register_effect needs an EffectType instance")
    if not effect.name or not effect.name.isidentifier():
        raise ValueError(f"effect name must be an identifier, got {effect.name!r}")
    if effect.name in EFFECTS and not replace:
        raise ValueError(f"effect {effect.name!r} is registered already (replace=True)")
    if not effect.parameters:
        raise ValueError(f"effect {effect.name!r} declares no parameters")
    EFFECTS[effect.name] = effect
    return effect


def effect_type(name: str, where: str | None = None, field: str | None = "effect"
                ) -> EffectType:
    """The registered effect called ``name``; an unknown name is a
    :class:`GfeInputError` with a "did you mean"."""
    try:
        return EFFECTS[name]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(name), list(EFFECTS), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise GfeInputError(where, field, f"unknown effect {name!r} ({hint}known: "
                            f"{', '.join(EFFECTS)})") from None


def candidate_names(kind: str) -> tuple:
    """Effects ``diagnose`` tries by default on a ``kind`` ("beam" or "bar")."""
    return tuple(n for n, e in EFFECTS.items() if e.candidate and kind in e.kinds
                 and (kind != "frame" or e.frame_candidate))


def _register_builtins():
    from . import (
        attached_body,
        axial_load,
        axial_stiffness,
        crack,
        foundation,
        joint_spring,
        mass_profile,
        material,
        member_shear,
        point_mass,
        point_spring,
        rotary_inertia,
        section_loss,
        shear,
        stiffness_profile,
        support_spring,
        support_translation,
    )

    for module in (material, crack, section_loss, shear, axial_load, foundation,
                   support_spring, support_translation, point_spring, point_mass,
                   stiffness_profile, mass_profile, joint_spring, axial_stiffness,
                   member_shear, rotary_inertia, attached_body):
        register_effect(module.EFFECT)


_register_builtins()

__all__ = ["EFFECTS", "EffectType", "Parameter", "Variable", "candidate_names",
           "effect_type", "format_value", "nominal_rigidity", "register_effect"]
