"""Measured modes: the JSON contract, CSV and UFF round trips, sensors mapped onto a model."""

import json

import numpy as np
import pytest

from gfe_opt.assembly import discretise
from gfe_opt.errors import GfeInputError
from gfe_opt.measured import load_measured, make_measured, save_measured, sensor_matrix
from gfe_opt.modal import model_modes

from .conftest import STEEL_BAR, make_model

CONTRACT = {"sensors": {"x": [0.0125, 0.025], "dof": "w"},
            "modes": [{"frequency": 223.4, "shape": [0.068, 0.136]}]}


def _sample():
    rng = np.random.default_rng(0)
    return make_measured(np.linspace(0.01, 0.5, 7), "w", [210.5, 850.25, 1999.0],
                         rng.standard_normal((7, 3)), "sample")


def test_json_contract_loads(tmp_path):
    p = tmp_path / "m.json"
    p.write_text(json.dumps(CONTRACT))
    m = load_measured(p)
    assert m.dof == "w" and np.allclose(m.x, [0.0125, 0.025])
    # shapes are kept with each mode's largest amplitude at 1 (their scale means nothing)
    assert np.allclose(m.frequencies_hz, [223.4]) and np.allclose(m.shapes[:, 0], [0.5, 1.0])


@pytest.mark.parametrize("suffix", [".json", ".csv"])
def test_exact_round_trips(tmp_path, suffix):
    m = _sample()
    save_measured(m, tmp_path / f"m{suffix}")
    back = load_measured(tmp_path / f"m{suffix}")
    assert np.array_equal(back.x, m.x)
    assert np.array_equal(back.frequencies_hz, m.frequencies_hz)
    assert np.array_equal(back.shapes, m.shapes)


def test_uff_round_trip_with_pyuff(tmp_path):
    import pyuff

    m = _sample()
    save_measured(m, tmp_path / "m.uff")
    sets = pyuff.UFF(str(tmp_path / "m.uff")).read_sets()
    assert [s["type"] for s in sets] == [2411, 55, 55, 55]
    assert np.allclose([s["freq"] for s in sets[1:]], m.frequencies_hz, rtol=1e-5)
    back = load_measured(tmp_path / "m.uff")
    assert back.dof == "w"
    assert np.allclose(back.shapes, m.shapes, rtol=1e-5, atol=1e-5)
    assert np.allclose(back.x, m.x, rtol=1e-5)
    # what we read from our own UFF is written back unchanged
    save_measured(back, tmp_path / "again.uff")
    again = load_measured(tmp_path / "again.uff")
    assert np.array_equal(again.shapes, back.shapes)
    assert np.array_equal(again.frequencies_hz, back.frequencies_hz)


def test_uff_with_dataset_15_nodes(tmp_path):
    import pyuff

    n = 4
    x = np.array([0.1, 0.2, 0.3, 0.4])
    sets = [pyuff.prepare_15(node_nums=np.arange(1, n + 1), def_cs=np.zeros(n, int),
                             disp_cs=np.zeros(n, int), color=np.ones(n, int), x=x,
                             y=np.zeros(n), z=np.zeros(n), return_full_dict=True),
            pyuff.prepare_55(id1="m1", model_type=1, analysis_type=2, data_ch=2,
                             spec_data_type=8, data_type=2, n_data_per_node=3,
                             r1=np.zeros(n), r2=np.sin(x), r3=np.zeros(n), load_case=1,
                             mode_n=1, freq=12.5, modal_m=0.0, modal_damp_vis=0.0,
                             modal_damp_his=0.0, node_nums=np.arange(1, n + 1))]
    pyuff.UFF(str(tmp_path / "t.unv")).write_sets(sets, mode="overwrite")
    for dof in (None, "w"):  # w read from y when every z is zero
        m = load_measured(tmp_path / "t.unv", dof=dof)
        assert m.dof == "w" and np.allclose(m.x, x)
        assert np.allclose(m.shapes[:, 0], np.sin(x) / np.max(np.abs(np.sin(x))), atol=1e-5)


@pytest.mark.parametrize("change,match", [
    (lambda d: d["modes"][0].update(shape=[0.1]), "has 1 values but there are 2 sensors"),
    (lambda d: d["modes"][0].update(shape=[0.0, 0.0]), "all values are zero"),
    (lambda d: d["modes"][0].update(frequency=-3.0), "must be > 0 Hz"),
    (lambda d: d["modes"].append({"frequency": 223.4, "shape": [1, 2]}), "appears twice"),
    (lambda d: d["sensors"].update(dof="z"), "unknown dof"),
    (lambda d: d.update(extra=1), "extra: unknown key"),
    (lambda d: d["sensors"].update(x=[0.1, 0.1]), "appears twice"),
])
def test_bad_json(tmp_path, change, match):
    data = json.loads(json.dumps(CONTRACT))
    change(data)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(data))
    with pytest.raises(GfeInputError, match=match):
        load_measured(p)


def test_nan_in_json_is_rejected(tmp_path):
    p = tmp_path / "nan.json"
    p.write_text(json.dumps(CONTRACT).replace("0.136", "NaN"))
    with pytest.raises(GfeInputError, match="NaN"):
        load_measured(p)


def test_modes_are_sorted_by_frequency():
    m = make_measured([0.1, 0.2], "w", [900.0, 200.0], [[1.0, 2.0], [3.0, 4.0]])
    assert np.array_equal(m.frequencies_hz, [200.0, 900.0])
    assert np.allclose(m.shapes, [[0.5, 1 / 3], [1.0, 1.0]])  # each mode's peak at 1


def test_sensor_between_nodes_is_interpolated_by_hermite_functions():
    beam = make_model(elements=10)
    modes = model_modes(beam, 2)
    x = np.array([0.0, 0.0575, 0.08, 0.3111, 0.575])  # nodes and points between them
    C = sensor_matrix(discretise(beam).nodes, "beam", x, "w")
    at = C @ modes.shapes
    exact = np.sin(np.pi * x[:, None] * np.array([1, 2]) / beam.length)
    scale = at[np.argmax(np.abs(at), axis=0), [0, 1]] / np.max(np.abs(exact), axis=0)
    assert np.allclose(at / scale, exact, atol=2e-3)
    assert np.allclose(C[1].toarray().ravel()[2], 1.0)  # a sensor on a node reads that node


def test_bar_sensor_matrix_is_linear():
    bar = make_model(STEEL_BAR, elements=4)
    C = sensor_matrix(discretise(bar).nodes, "bar", [0.25], "u").toarray()
    assert np.allclose(C[0, :2], [0.5, 0.5])


def test_sensor_outside_structure_is_an_error():
    with pytest.raises(GfeInputError, match=r"sensors.x\[1\]: 0.6 m lies outside"):
        sensor_matrix(np.linspace(0, 0.575, 5), "beam", [0.1, 0.6], "w", "f.json")
    with pytest.raises(GfeInputError, match="does not fit a beam"):
        sensor_matrix(np.linspace(0, 0.575, 5), "beam", [0.1], "u", "f.json")
