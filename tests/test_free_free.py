"""A free–free beam measured with shapes (a roving-hammer test hung on soft cords): the
model's rigid-body modes never enter a measured set, neither the user's nor the ones the
realisation builds from the model's own modes (issue 21: `gfe-opt diagnose` exited 2 blaming
the user's file for "modes[0].frequency: must be > 0 Hz, got 0").

The truth is the closed-form free–free Euler–Bernoulli beam (β_n L = 4.7300, 7.8532,
10.9956, 14.1372): the model is right, so the diagnosis must say so; with the section 2 %
thinner than modelled it must find a uniform change, not a local one.
"""

from __future__ import annotations

import json

import numpy as np
import tomli_w

from gfe_opt.cli import main
from gfe_opt.diagnosis import diagnose
from gfe_opt.measured import make_measured, save_measured

from .conftest import STEEL_BEAM, make_model
from .reference import add_noise

BETA_L = np.array([4.730040745, 7.853204624, 10.99560784, 14.13716549])
FREE = {"left": "free", "right": "free"}
POINTS = np.linspace(0.0, STEEL_BEAM["length"], 9)   # the hammer at 9 points, ends included


def free_free(EI_factor=1.0, seed=3):
    s = STEEL_BEAM["section"]
    length = STEEL_BEAM["length"]
    EI = STEEL_BEAM["material"]["E"] * s["b"] * s["h"] ** 3 / 12 * EI_factor
    rho_a = STEEL_BEAM["material"]["rho"] * s["b"] * s["h"]
    beta = BETA_L / length
    freqs = beta**2 * np.sqrt(EI / rho_a) / (2 * np.pi)
    bx = np.outer(POINTS, beta)
    sigma = (np.cosh(BETA_L) - np.cos(BETA_L)) / (np.sinh(BETA_L) - np.sin(BETA_L))
    shapes = np.cosh(bx) + np.cos(bx) - sigma * (np.sinh(bx) + np.sin(bx))
    f, y = add_noise(freqs, shapes, 0.003, 0.0005, seed)
    return make_measured(POINTS, "w", f, y, "free-free.json")


def test_free_free_beam_with_shapes_is_consistent_and_realised():
    model = make_model(supports=FREE)
    d = diagnose(model, free_free(), realise=True)
    assert d.verdict == "consistent", (d.verdict, d.notes)
    assert d.generic_update is not None and d.profile_band is not None
    assert np.all(np.isfinite(d.profile_band.ratio))


def test_free_free_thinner_section_is_found_uniform():
    model = make_model(supports=FREE)
    d = diagnose(model, free_free(EI_factor=0.96), realise=True)
    assert d.verdict == "effect_found" and d.suggested[0] == "material", (d.suggested, d.notes)
    E = d.best.parameters["E"] / STEEL_BEAM["material"]["E"]
    assert abs(E - 0.96) < 3 * d.best.uncertainty["E"] / STEEL_BEAM["material"]["E"] + 1e-4


def test_cli_diagnoses_a_free_free_test(tmp_path, capsys):
    model_path = tmp_path / "free.toml"
    model_path.write_text(tomli_w.dumps({**STEEL_BEAM, "supports": FREE}))
    save_measured(free_free(), tmp_path / "measured.json")
    code = main(["diagnose", str(model_path), str(tmp_path / "measured.json"), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["verdict"] == "consistent", out
