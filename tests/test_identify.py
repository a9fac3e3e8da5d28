"""From FRFs to modes: ``gfe-opt identify`` against FRFs synthesised from a closed form.

The truth is the free-free Euler–Bernoulli beam (β_n L = 4.7300, 7.8532, 10.9956; shapes
cosh + cos − σ (sinh + sin)), with modal damping, FRFs built as a modal sum in
``tests/reference.py`` (no gfe-opt code), complex noise relative to each FRF's peak.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from gfe_opt.cli import main
from gfe_opt.correlation import mac
from gfe_opt.identify import FRFs, identify, load_frfs
from gfe_opt.measured import load_measured
from tests.reference import STEEL, synthesise_frfs, write_uff58

pytest.importorskip("sdypy.EMA")

BETA_L = np.array([4.730040745, 7.853204624, 10.99560784])
LENGTH = STEEL["length"]
EI = STEEL["E"] * STEEL["b"] * STEEL["h"] ** 3 / 12
RHO_A = STEEL["rho"] * STEEL["b"] * STEEL["h"]
DAMPING = np.array([0.004, 0.007, 0.012])
POINTS = np.linspace(0.02, LENGTH - 0.02, 9)


def free_free(x):
    """Natural frequencies [Hz] and shapes (len(x), 3) of the free-free beam."""
    beta = BETA_L / LENGTH
    freqs = beta**2 * np.sqrt(EI / RHO_A) / (2 * np.pi)
    bx = np.outer(x, beta)
    sigma = (np.cosh(BETA_L) - np.cos(BETA_L)) / (np.sinh(BETA_L) - np.sin(BETA_L))
    shapes = np.cosh(bx) + np.cos(bx) - sigma * (np.sinh(bx) + np.sin(bx))
    return freqs, shapes


def frf_set(noise, seed=0, form="accelerance", reference=0):
    """Frequency lines, truth and FRFs at POINTS (reference = driving point index)."""
    freqs, shapes = free_free(POINTS)
    lines = np.linspace(20.0, 1.25 * freqs[-1], 2400)
    H = synthesise_frfs(freqs, shapes, DAMPING, lines, reference, form=form, noise=noise,
                        seed=seed)
    return lines, freqs, shapes, H


def _errors(result, freqs, shapes):
    found = result.measured
    assert found.n_modes == 3, found.frequencies_hz
    freq_error = np.max(np.abs(found.frequencies_hz / freqs - 1))
    damping_error = np.max(np.abs(found.damping / DAMPING - 1))
    macs = np.diag(mac(found.shapes, shapes))
    return freq_error, damping_error, macs


@pytest.mark.parametrize("roving", ["hammer", "accelerometer"])
def test_low_noise_uff_gives_the_modes_back(tmp_path, roving):
    lines, freqs, shapes, H = frf_set(noise=0.001, reference=8)
    write_uff58(tmp_path / "frf.uff", POINTS, lines, H, 8, roving=roving)
    frfs = load_frfs([tmp_path / "frf.uff"])
    assert frfs.form == "accelerance" and frfs.driving_point == 8
    np.testing.assert_allclose(frfs.x, POINTS)
    freq_error, damping_error, macs = _errors(identify(frfs), freqs, shapes)
    assert freq_error < 1e-3
    assert damping_error < 0.05
    assert np.all(macs > 0.999), macs


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_one_percent_noise_meets_the_targets(tmp_path, seed):
    """Issue 11: frequencies within 0.2 %, damping within 20 %, MAC > 0.99."""
    lines, freqs, shapes, H = frf_set(noise=0.01, seed=seed, reference=0)
    write_uff58(tmp_path / "frf.uff", POINTS, lines, H, 0)
    result = identify(load_frfs([tmp_path / "frf.uff"]))
    freq_error, damping_error, macs = _errors(result, freqs, shapes)
    assert freq_error < 2e-3
    assert damping_error < 0.2
    assert np.all(macs > 0.99), macs
    # the reconstruction misses the FRFs by about the noise, no more
    clean = frf_set(noise=0.0, reference=0)[3]
    band = (lines >= result.band[0]) & (lines <= result.band[1])
    noise_ratio = np.sqrt(np.mean(np.abs(H - clean)[:, band] ** 2)
                          / np.mean(np.abs(H)[:, band] ** 2))
    assert 0.8 * noise_ratio < result.fit_error < 1.2 * noise_ratio


def test_noise_and_errors_grow_together():
    """More noise in the FRFs, larger errors: the identification is not hiding the noise."""
    errors = []
    for noise in (0.001, 0.03):
        lines, freqs, shapes, H = frf_set(noise=noise, seed=5)
        result = identify(FRFs(POINTS, lines, H, "accelerance", 0, "synthetic"))
        errors.append(_errors(result, freqs, shapes))
    assert errors[1][1] > errors[0][1]
    assert np.min(errors[1][2]) < np.min(errors[0][2])


@pytest.mark.parametrize("layout", ["complex", "re-im"])
def test_csv_tables_read_like_uff(tmp_path, layout):
    lines, freqs, shapes, H = frf_set(noise=0.002, form="mobility")
    if layout == "complex":
        header = "f," + ",".join(f"{x:.6f}" for x in POINTS)
        rows = [f"{f:.6f}," + ",".join(f"{v.real:.9e}{v.imag:+.9e}j" for v in H[:, k])
                for k, f in enumerate(lines)]
    else:
        header = "f," + ",".join(f"{x:.6f},{x:.6f}" for x in POINTS)
        rows = [f"{f:.6f}," + ",".join(f"{v.real:.9e},{v.imag:.9e}" for v in H[:, k])
                for k, f in enumerate(lines)]
    path = tmp_path / "frf.csv"
    path.write_text("\n".join(["# mobility, roving hammer, reference at x = 0.02", header,
                               *rows]) + "\n")
    frfs = load_frfs([path], form="mobility")
    np.testing.assert_allclose(frfs.x, np.round(POINTS, 6))
    np.testing.assert_allclose(frfs.frf, H, rtol=1e-8, atol=1e-9 * np.abs(H).max())
    freq_error, damping_error, macs = _errors(identify(frfs), freqs, shapes)
    assert freq_error < 1e-3 and damping_error < 0.1 and np.all(macs > 0.999)


def test_cli_writes_measured_json_with_damping(tmp_path, capsys):
    lines, freqs, shapes, H = frf_set(noise=0.005, seed=7)
    write_uff58(tmp_path / "frf.uff", POINTS, lines, H, 0)
    out = tmp_path / "measured.json"
    argv = ["identify", str(tmp_path / "frf.uff"), "--out", str(out), "--plot",
            str(tmp_path / "figs")]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "ζ [%]" in text and str(out) in text
    assert (tmp_path / "figs" / "stabilisation.png").stat().st_size > 10_000
    data = json.loads(out.read_text())
    assert [set(m) for m in data["modes"]] == [{"frequency", "shape", "damping"}] * 3
    measured = load_measured(out)
    np.testing.assert_allclose(measured.frequencies_hz, freqs, rtol=2e-3)
    np.testing.assert_allclose(measured.damping, DAMPING, rtol=0.2)
    # nothing overwritten without asking; --force does
    assert main(argv) == 2
    assert "exists" in capsys.readouterr().err
    assert main([*argv, "--force", "--json", "--modes", "2", "--band", "30:2000"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert len(printed["modes"]) == 2 == len(load_measured(out).frequencies_hz)


def _fails(capsys, argv, match):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert match in err, err


def test_bad_frf_inputs_are_one_line(tmp_path, capsys):
    lines, freqs, shapes, H = frf_set(noise=0.0)
    write_uff58(tmp_path / "frf.uff", POINTS, lines, H, 0)
    out = str(tmp_path / "m.json")
    (tmp_path / "frf.txt").write_text("1,2\n")
    _fails(capsys, ["identify", str(tmp_path / "frf.txt"), "--out", out], "unknown FRF format")
    _fails(capsys, ["identify", str(tmp_path / "frf.uff"), "--out", out, "--band", "5:9000"],
           "must lie within")
    _fails(capsys, ["identify", str(tmp_path / "frf.uff"), "--out", out, "--band", "900"],
           "LOW:HIGH")
    _fails(capsys, ["identify", str(tmp_path / "frf.uff"), "--out", out, "--order", "2"],
           "--order")
    main(["modes", "problems/ss-steel-beam.toml", "--out", str(tmp_path / "modes.uff")])
    capsys.readouterr()
    _fails(capsys, ["identify", str(tmp_path / "modes.uff"), "--out", out], "dataset 58")
    (tmp_path / "bad.csv").write_text("f,a,b\n1,1+1j,2\n2,1,2\n")
    _fails(capsys, ["identify", str(tmp_path / "bad.csv"), "--out", out], "header")
    (tmp_path / "short.csv").write_text("f,0.1,0.2\n1,1+1j,2\n2,1\n")
    _fails(capsys, ["identify", str(tmp_path / "short.csv"), "--out", out], "row 3")
    assert not (tmp_path / "m.json").exists()


def test_shipped_frfs_identify_and_diagnose_to_the_crack(tmp_path, capsys):
    """The README's loop on problems/demo-frf.uff: FRFs of the cracked beam simulated on the
    independent reference beam (crack at 0.19 m, a/d 0.5; scripts/make_examples.py) ->
    identify -> diagnose finds that crack, within 3σ and within 2 mm."""
    from gfe_opt.diagnosis import diagnose
    from gfe_opt.model import load_model
    from gfe_opt.problems import problem_file

    out = tmp_path / "modes.json"
    assert main(["identify", str(problem_file("demo-frf.uff")), "--out", str(out)]) == 0
    capsys.readouterr()
    measured = load_measured(out)
    assert measured.n_modes == 3 and measured.n_sensors == 9
    result = diagnose(load_model(problem_file("ss-steel-beam.toml")), measured,
                      candidates=("material", "crack", "point_mass"))
    assert result.verdict == "effect_found" and result.best.name == "crack"
    fit, sigma = result.best.parameters, result.best.uncertainty
    for key, truth, tolerance in (("position", 0.19, 0.002), ("depth_ratio", 0.5, 0.02)):
        assert abs(fit[key] - truth) < min(3 * sigma[key], tolerance), (key, fit, sigma)
