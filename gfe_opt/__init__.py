"""gfe-opt: finite-element model updating with generic elements and physical realisation.

The stages are separate calls with plain data between them::

    model = load_model("beam.toml")
    measured = load_measured("test.json")
    result = compare(model, measured)
    diagnosis = diagnose(model, measured)
    outcome = update(model, measured, ["crack"])
"""

from .correlation import Comparison, compare, mac
from .diagnosis import Diagnosis, UpdateOutcome, diagnose, update
from .effects import EFFECTS, EffectType, register_effect
from .errors import GfeInputError, GfeSolverError
from .measured import MeasuredModes, load_measured, save_measured
from .modal import Modes, model_modes
from .model import Effect, Model, load_model, save_model

__all__ = ["Comparison", "Diagnosis", "EFFECTS", "Effect", "EffectType", "GfeInputError",
           "GfeSolverError", "MeasuredModes", "Model", "Modes", "UpdateOutcome", "compare",
           "diagnose", "load_measured", "load_model", "mac", "model_modes", "register_effect",
           "save_measured", "save_model", "update"]
