"""What measurement would tell two alike models apart (:mod:`gfe_opt.decide`), checked
against the χ² the diagnosis itself would compute with that measurement added: the σ the
caveat says is the gap one more sensor (or the next mode) opens between the two models'
χ², on a beam and on a frame, with data from independent generators."""

from dataclasses import replace

import numpy as np
import pytest

from gfe_opt.decide import deciding_measurement
from gfe_opt.fitting import Noise, evaluate, misfit
from gfe_opt.frame_data import frame_measured_from_dict
from gfe_opt.measured import make_measured
from gfe_opt.model import Effect, load_model
from gfe_opt.problems import portal_frame, problem_file
from gfe_opt.synthetic import synthetic_measurement

from .test_frame_diagnosis import _exact_with_body, _guess, _measured, _sensors

NOISE = Noise(freq=0.0005, shape=0.003, given=True)


def _reading(model, measured, sensor_measured):
    """The model's mode shapes at the sensors of ``sensor_measured``, scaled as the
    residual scales them against ``measured`` (unit length at its sensors, its sign), in
    the measured shapes' own units: what a sensor there would read if the model were
    right; paired modes only (measured row -> reading)."""
    p = evaluate(model, measured, NOISE)
    c = p.disc.observation(sensor_measured)
    return {int(t): p.sign[i] * (c @ p.modes.shapes[:, j]) / p.norm[i]
            * np.linalg.norm(measured.shapes[:, t])
            for i, (t, j) in enumerate(zip(p.rows, p.cols))}


def _gap(a, b, measured):
    return misfit(a, measured, NOISE).chi2 - misfit(b, measured, NOISE).chi2


def _check_sensor(a, b, measured, extended):
    """One more sensor that reads model b's prediction: the χ² gap between the two models
    grows by the decision's σ² (the data are not b's shapes at the other sensors: 5 %)."""
    d = deciding_measurement(a, b, measured, NOISE, threshold=2.0)
    assert d is not None and d.sensor is not None
    with_sensor, probe = extended(measured, d.sensor)
    reading = _reading(b, measured, probe)
    shapes = np.vstack([measured.shapes, np.array(
        [[reading[t][0] if t in reading else 0.0 for t in range(measured.n_modes)]])])
    more = replace(with_sensor, shapes=shapes)
    grown = _gap(a, b, more) - _gap(a, b, measured)
    assert grown == pytest.approx(d.sensor_sigma**2, rel=0.05), (d, grown)
    return d


def test_one_more_sensor_on_a_beam_opens_the_gap_the_decision_says():
    """Pinned–pinned steel beam, 5 modes at 6 sensors, all left of mid-span, from a finer
    mesh with a crack at 0.62 L (the data); the two models: a crack at 0.6 L and a point
    mass of 3 % of the beam's at 0.6 L.  Their readings differ most right of mid-span,
    where no sensor is; the sensor the decision places there opens the χ² gap it says,
    and the next modes' frequencies differ as the two models' own do."""
    model = load_model(problem_file("ss-steel-beam.toml"))
    L = model.length
    data_model = model.with_effects([Effect("crack", {"position": 0.62 * L,
                                                      "depth_ratio": 0.4})])
    x = np.linspace(0.05, 0.45, 6) * model.length
    measured = synthetic_measurement(data_model, 5, x, shape_noise=0.003, freq_noise=0.0005,
                                     seed=11, reference_elements=4 * model.elements)
    a = model.with_effects([Effect("crack", {"position": 0.6 * L, "depth_ratio": 0.4})])
    b = model.with_effects([Effect("point_mass", {"position": 0.6 * L,
                                                  "mass": 0.03 * model.rho * model.area * L})])

    def extended(m, sensor):
        x = np.append(m.x, sensor["x"])
        probe = replace(m, x=np.array([sensor["x"]]), shapes=np.zeros((1, m.n_modes)))
        return replace(m, x=x, shapes=np.zeros((x.size, m.n_modes))), probe

    d = _check_sensor(a, b, measured, extended)
    assert d.sensor["x"] > 0.5 * model.length   # where the test has no sensor
    # the next modes: their frequencies in each model, in σ of the frequency noise
    fa, fb = evaluate(a, measured, NOISE).modes, evaluate(b, measured, NOISE).modes
    k = d.mode - 1
    assert d.mode > measured.n_modes
    assert d.mode_sigma == pytest.approx(
        abs(fa.frequencies_hz[k] / fb.frequencies_hz[k] - 1) / NOISE.freq, rel=1e-9)


def test_the_same_model_twice_is_told_apart_by_nothing():
    model = load_model(problem_file("ss-steel-beam.toml"))
    x = np.linspace(0.1, 0.9, 9) * model.length
    measured = synthetic_measurement(model, 4, x, shape_noise=0.003, freq_noise=0.0005,
                                     seed=2, reference_elements=4 * model.elements)
    d = deciding_measurement(model, model, measured, NOISE, threshold=2.0)
    assert d.sensor_sigma == 0.0 and d.mode_sigma == 0.0 and not d.decides
    assert d.words().startswith("no one more sensor and none of the next")


def test_one_more_sensor_on_a_frame_opens_the_gap_the_decision_says():
    """The portal with a block (0.12 kg, J 2.1e-4 kg m²) 6.75 cm up its left column, from
    the exact frame split at the block (the data); the two models: a point mass 1.6 cm above
    the block and the block itself, which the test cannot tell apart
    (``test_frame_diagnosis``'s case).  A sensor where the decision says opens the χ² gap
    it says."""
    model = portal_frame()
    at, mass, inertia = 0.0675, 0.12, 0.12 * 0.042**2
    exact, where = _exact_with_body(model, "left-column", at, mass, inertia)
    body = [Effect("attached_body", {"member": "left-column", "position": at, "mass": mass,
                                     "inertia": inertia})]
    measured = _measured(model, exact, _guess(model, body), _sensors(model), 3, where=where)
    a = model.with_effects([Effect("point_mass", {"member": "left-column", "position": 0.0836,
                                                  "mass": 0.125})])
    b = model.with_effects(body)

    def extended(m, sensor):
        data = {"sensors": [*m.sensors, sensor],
                "modes": [{"frequency": float(f), "shape": [1.0] * (len(m.sensors) + 1)}
                          for f in m.frequencies_hz]}   # (readings replaced below)
        grown = frame_measured_from_dict(data, model, "probe")
        probe = replace(grown, sensors=[sensor], shapes=np.zeros((1, m.n_modes)))
        return grown, probe

    d = _check_sensor(a, b, measured, extended)
    assert d.sensor["member"] == "left-column"


def test_from_frequencies_alone_the_next_mode_opens_the_gap_the_decision_says():
    """A test of five frequencies (no shapes) of the pinned–pinned steel beam with a crack at
    0.62 L, from a finer mesh; the two models: a crack at 0.6 L and a point mass at 0.6 L.
    No sensor is proposed (there are no shapes to add one to); the next mode said, measured
    as model b has it, opens the χ² gap between the two models by the σ² said, and the words
    name only modes."""
    model = load_model(problem_file("ss-steel-beam.toml"))
    L = model.length
    data_model = model.with_effects([Effect("crack", {"position": 0.62 * L,
                                                      "depth_ratio": 0.4})])
    shaped = synthetic_measurement(data_model, 5, np.linspace(0.1, 0.9, 9) * L,
                                   shape_noise=0.003, freq_noise=0.0005, seed=12,
                                   reference_elements=4 * model.elements)
    measured = make_measured([], "w", shaped.frequencies_hz, None, "frequencies")
    assert measured.frequency_only
    a = model.with_effects([Effect("crack", {"position": 0.6 * L, "depth_ratio": 0.4})])
    b = model.with_effects([Effect("point_mass", {"position": 0.6 * L,
                                                  "mass": 0.03 * model.rho * model.area * L})])
    d = deciding_measurement(a, b, measured, NOISE, threshold=2.0)
    assert d is not None and d.sensor is None and d.sensor_sigma == 0.0
    assert d.mode > measured.n_modes
    fb = evaluate(b, measured, NOISE).modes.frequencies_hz
    more = make_measured([], "w", np.append(measured.frequencies_hz, fb[d.mode - 1]),
                         None, "one more mode")
    grown = _gap(a, b, more) - _gap(a, b, measured)
    assert grown == pytest.approx(d.mode_sigma**2, rel=1e-6), (d, grown)
    assert "sensor" not in d.words()
    never = deciding_measurement(a, a, measured, NOISE, threshold=2.0)
    assert not never.decides
    assert never.words().startswith("none of the next 3 modes' frequencies would tell")
