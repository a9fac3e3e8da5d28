"""Diagnosis targets: each effect, hidden in independent synthetic data (5 modes, 45 sensors,
0.3 % shape noise, 0.05 % frequency noise), is ranked first, recovered and removes the error."""

import numpy as np
import pytest

from gfe_opt.diagnosis import diagnose, update
from gfe_opt.model import Effect
from gfe_opt.synthetic import closed_form_measurement, interior_sensors, synthetic_measurement

from .conftest import make_model

NOISE = {"shape_noise": 0.003, "freq_noise": 0.0005}


def _data(model, effect, seed=11):
    sensors = interior_sensors(model.length, 45)
    if effect.name in ("material", "axial_load", "foundation", "shear"):
        return closed_form_measurement(model, effect, 5, sensors, seed=seed, **NOISE)
    return synthetic_measurement(model.with_effects([effect]), 5, sensors, seed=seed, **NOISE)


def _close(name, key, got, want):
    if key == "position":
        return abs(got - want) <= 0.015
    if key == "depth_ratio":
        return abs(got - want) <= 0.05
    if key == "side":
        return got == want
    return abs(got / want - 1) <= 0.05


def _effects(model):
    ei, length = model.bending_rigidity, model.length
    return {
        "crack": {"position": 0.19, "depth_ratio": 0.5},
        "axial_load": {"tension": 0.3 * np.pi**2 * ei / length**2},
        "foundation": {"stiffness": 0.5 * ei * (np.pi / length) ** 4},
        "support_spring": {"stiffness": 2.0 * ei / length, "side": "both"},
        "point_mass": {"position": 0.4, "mass": 0.15 * model.mass_per_length * length},
        "material": {"E": 0.97 * model.E},
    }


@pytest.mark.parametrize("name", ["crack", "axial_load", "foundation", "support_spring",
                                  "point_mass", "material"])
def test_hidden_effect_is_found_fitted_and_removes_the_error(name):
    model = make_model()
    truth = Effect(name, _effects(model)[name])
    measured = _data(model, truth)
    result = diagnose(model, measured, **NOISE)
    first = result.fits[0]
    assert first.effect == name and first.significant, [(f.effect, f.significant)
                                                          for f in result.fits]
    for key, want in truth.parameters.items():
        assert _close(name, key, first.parameters[key], want), (key, first.parameters, want)
    outcome = update(model, measured, [name], **NOISE)
    assert outcome.before.freq_error_rms_pct > 0.5
    assert outcome.after.freq_error_rms_pct < 0.1  # the noise is 0.05 %


def test_material_only_reports_nothing_else():
    model = make_model()
    measured = _data(model, Effect("material", {"E": 1.03 * model.E}), seed=5)
    result = diagnose(model, measured, **NOISE)
    significant = [f.effect for f in result.fits if f.significant]
    assert significant == ["material"]


def test_deep_beam_is_diagnosed_as_shear():
    # length / depth = 6: Timoshenko shear deformation and rotary inertia matter
    depth = 0.575 / 6
    model = make_model(section={"b": 0.02, "h": depth})
    kga = 5 / 6 * model.E / (2 * (1 + model.nu)) * model.area
    measured = closed_form_measurement(model, Effect("shear", {"shear_rigidity": kga}), 5,
                                       interior_sensors(model.length, 45), seed=3, **NOISE)
    result = diagnose(model, measured, **NOISE)
    assert result.fits[0].effect == "shear" and result.fits[0].significant
    assert abs(result.fits[0].parameters["shear_rigidity"] / kga - 1) < 0.10


def test_two_effects_are_found_by_iterating():
    model = make_model()
    ei, length = model.bending_rigidity, model.length
    truth = model.with_effects([Effect("crack", {"position": 0.4, "depth_ratio": 0.5}),
                                Effect("axial_load", {"tension": 0.3 * np.pi**2 * ei
                                                      / length**2})])
    measured = synthetic_measurement(truth, 5, interior_sensors(length, 45), seed=8, **NOISE)
    found = []
    current = model
    for _ in range(3):
        best = diagnose(current, measured, **NOISE).best
        if best is None:
            break
        found.append(best.effect)
        current = update(current, measured, [best.effect], **NOISE).model
    assert sorted(found) == ["axial_load", "crack"]
    fitted = {e.name: e.parameters for e in current.effects}
    assert abs(fitted["crack"]["position"] - 0.4) <= 0.015
    assert abs(fitted["axial_load"]["tension"] / (0.3 * np.pi**2 * ei / length**2) - 1) < 0.05
