"""gfe-opt: finite-element model updating with generic elements and physical realisation.

The stages are separate calls with plain data between them::

    model = load_model("beam.toml")
    measured = load_measured("test.json")
    result = compare(model, measured)
    diagnosis = diagnose(model, measured)
    outcome = update(model, measured, ["crack"])
"""

from importlib import import_module

from .errors import GfeInputError, GfeSolverError  # noqa: F401 (public, light)

#: public names and the module each lives in, imported on first use (PEP 562): the command
#: line starts without numerical libraries, so even an early Ctrl-C is one line
_LAZY = {
    "Comparison": "correlation", "compare": "correlation", "mac": "correlation",
    "Diagnosis": "diagnosis", "UpdateOutcome": "diagnosis", "diagnose": "diagnosis",
    "update": "diagnosis", "follow": "diagnosis",
    "EFFECTS": "effects", "EffectType": "effects", "register_effect": "effects",
    "MeasuredModes": "measured", "load_measured": "measured", "save_measured": "measured",
    "Modes": "modal", "model_modes": "modal",
    "Effect": "model", "Model": "model", "load_model": "model", "save_model": "model",
}

__all__ = sorted([*_LAZY, "GfeInputError", "GfeSolverError"])


def __getattr__(name):
    if name in _LAZY:
        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'gfe_opt' has no attribute {name!r}")


def __dir__():
    return __all__
