"""The gfe-opt command: compare table and JSON contract, exit codes, the demo."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from gfe_opt.cli import main
from gfe_opt.demo import check_demo_folder
from gfe_opt.measured import save_measured
from gfe_opt.model import Effect, load_model
from gfe_opt.problems import problem_file
from gfe_opt.synthetic import interior_sensors, synthetic_measurement


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cli")
    model_path = problem_file("ss-steel-beam.toml")
    model = load_model(model_path)
    truth = model.with_effects([Effect("crack", {"position": 0.4, "depth_ratio": 0.5})])
    measured = synthetic_measurement(truth, 4, interior_sensors(model.length, 30),
                                     shape_noise=0.003, seed=3)
    save_measured(measured, tmp / "measured.json")
    return model_path, tmp / "measured.json", tmp


def test_compare_table(files, capsys):
    model, measured, _ = files
    assert main(["compare", str(model), str(measured)]) == 0
    out = capsys.readouterr().out
    assert "f_test [Hz]" in out and "MAC" in out
    assert len([ln for ln in out.splitlines() if ln.strip()[:1].isdigit()]) >= 4
    assert "the model fails most near x = 0.4" in out


def test_compare_json_contract(files, capsys):
    model, measured, _ = files
    assert main(["compare", str(model), str(measured), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"pairs", "freq_error_rms_pct", "mac_mean", "localisation", "pairing"}
    assert data["pairing"] == "mac"
    assert set(data["pairs"][0]) == {"test_mode", "model_mode", "test_hz", "model_hz",
                                     "error_pct", "mac"}
    assert len(data["pairs"]) == 4 and data["freq_error_rms_pct"] > 1.0
    assert set(data["localisation"][0]) == {"x", "residual"} and len(data["localisation"]) == 30


def test_bad_input_exits_2_with_one_line_and_no_traceback(files, tmp_path):
    model, _, _ = files
    bad = tmp_path / "bad.json"
    bad.write_text('{"sensors": {"x": [0.1, 0.9]}, "modes": [{"frequency": 1, "shape": [1, 2]}]}')
    run = subprocess.run([sys.executable, "-m", "gfe_opt.cli", "compare", str(model), str(bad)],
                         capture_output=True, text=True)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr
    assert run.stderr.strip().count("\n") == 0
    assert "sensors.x[1]: 0.9 m lies outside" in run.stderr


def test_missing_file_exits_2(files, capsys):
    model, _, tmp = files
    assert main(["compare", str(model), str(tmp / "none.json")]) == 2
    assert "no such file" in capsys.readouterr().err


def readme_demo_lines() -> list[str]:
    """The lines of the README's two demo blocks (step 3, steps 4-6) except "..."."""
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    top = text.split("## Using it")[0]
    blocks = [b.split("```")[0] for b in top.split("```\n")[1:] if b.startswith("   ")]
    lines = [line for b in blocks[:2] for line in b.splitlines()
             if line.strip() and line.strip() != "..."]
    assert len(lines) > 25, lines
    return lines


def test_demo_tells_the_whole_story_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert (out / "model.toml").exists() and (out / "measured.json").exists()
    assert "the model fails most near x = 0.1" in text
    found = re.search(r"verdict: an effect is missing\n     crack: position = ([0-9.]+)", text)
    assert found and abs(float(found.group(1)) - 0.19) < 0.015
    assert "nothing significant is left: consistent" in text
    # issue 20: the README's demo blocks are what the demo prints, under every BLAS kernel
    # (.ci/run runs this test under several), every line but the abbreviations
    for line in readme_demo_lines():
        assert line in text.splitlines(), line
    updated = load_model(out / "updated.toml")
    assert [e.name for e in updated.effects] == ["crack"]
    assert abs(updated.effects[0].parameters["position"] - 0.19) < 0.015
    # a second demo rewrites its own files; one changed since, or not the demo's, is kept
    check_demo_folder(out)
    with open(out / "model.toml", "a") as handle:
        handle.write("# my note\n")
    assert main(["demo", "--out", str(out)]) == 2
    assert "model.toml: exists and is not as the demo wrote it" in capsys.readouterr().err
    assert (out / "model.toml").read_text().endswith("# my note\n")


def test_diagnose_json_contract(files, capsys):
    model, measured, _ = files
    assert main(["diagnose", str(model), str(measured), "--json",
                 "--candidates", "material,crack"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"verdict", "baseline", "noise", "effects", "failed", "skipped",
                         "indistinguishable", "suggested", "together", "realisation",
                         "notes", "remaining", "offered", "replace", "not_needed", "add",
                         "caveats", "withheld", "moved"}
    assert data["add"] == data["suggested"]   # on a beam the names themselves
    # each caveat is one of the notes, with its kind and the effect sets that fit as well
    assert all(c["note"] in data["notes"] and set(c) == {"kind", "note", "alternatives", "present"}
               for c in data["caveats"])
    assert data["indistinguishable"] == [] and data["suggested"] == ["crack"]
    assert data["replace"] is None   # the model holds no effect to replace
    assert data["not_needed"] == []  # nor one to take out
    assert data["withheld"] is None  # nor one whose form a further effect might be
    assert data["moved"] == []       # nor one the user modelled that the data move
    assert data["together"] is None
    assert data["verdict"] == "effect_found"
    # 4 noisy modes of a Christides-Barr crack: the library's crack brings them to the noise
    assert data["remaining"] is None and data["offered"] == []
    assert set(data["baseline"]) == {"freq_error_rms_pct", "mac_mean", "chi2_per_residual"}
    assert set(data["noise"]) == {"freq", "shape", "given", "implied_freq", "implied_shape"}
    assert [e["effect"] for e in data["effects"]][0] == "crack"
    for entry in data["effects"]:
        assert set(entry) == {"effect", "parameters", "uncertainty", "freq_error_rms_pct",
                              "mac_mean", "chi2_per_residual", "significant",
                              "mirror_position", "equivalent", "not_estimable", "traded",
                              "told", "bounds"}
        assert entry["traded"] == []   # a beam's parameters never trade as a finding
        assert entry["told"] == {}     # nor does a beam's effect declare told values
        assert all(v in ("at_least", "at_most") for v in entry["bounds"].values())
        assert set(entry["uncertainty"]) <= set(entry["parameters"])
    first = data["effects"][0]
    assert first["significant"] and abs(first["parameters"]["position"] - 0.4) < 0.015
    # the truth lies within a few standard deviations, which are small but not zero
    assert 0 < first["uncertainty"]["position"] < 0.005


def test_update_writes_a_model_that_diagnose_continues_from(files, capsys, tmp_path):
    model, measured, _ = files
    out = tmp_path / "new.toml"
    assert main(["update", str(model), str(measured), "--add", "crack:position=0.39",
                 "--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"before", "after", "effects", "notes", "caveats"}
    assert data["caveats"] == []   # with shapes a crack's mirror place does not fit as well
    assert set(data["before"]) == set(data["after"]) == {"freq_error_rms_pct", "mac_mean",
                                                         "chi2_per_residual"}
    assert data["after"]["chi2_per_residual"] < 2.0 < data["before"]["chi2_per_residual"]
    assert set(data["effects"][0]) == {"effect", "parameters", "uncertainty", "bounds"}
    assert data["after"]["freq_error_rms_pct"] < 0.1 * data["before"]["freq_error_rms_pct"]
    assert data["effects"][0]["effect"] == "crack"
    assert [(e.name, e.found) for e in load_model(out).effects] == [("crack", True)]
    # --out never overwrites its input, nor an existing file without --force
    assert main(["update", str(model), str(measured), "--add", "crack", "--out",
                 str(model)]) == 2
    assert "input" in capsys.readouterr().err
    assert main(["update", str(model), str(measured), "--add", "crack", "--out",
                 str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    # --drop takes a present effect out before the added one goes in (a diagnosis's
    # "replace"): by name or by index, never more than the model holds
    again = tmp_path / "again.toml"
    assert main(["update", str(out), str(measured), "--drop", "crack", "--add",
                 "section_loss:position=0.39", "--out", str(again), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [e["effect"] for e in data["effects"]] == ["section_loss"]
    assert [e.name for e in load_model(again).effects] == ["section_loss"]
    for drop, match in (("crack", "--drop: crack: the model has no such effect (it has: "
                                  "section_loss)"),
                        ("1", "--drop: 1: the model has 1 effect (indices from 0)")):
        assert main(["update", str(again), str(measured), "--drop", drop, "--add",
                     "crack"]) == 2
        err = capsys.readouterr().err
        assert match in err and err.count("\n") == 1
    # --drop alone takes an effect out (a diagnosis's "not_needed"); neither is an error
    bare = tmp_path / "bare.toml"
    assert main(["update", str(again), str(measured), "--drop", "0", "--out", str(bare),
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["effects"] == [] and not load_model(bare).effects
    # the zone stood for the crack: without it the misfit is the model's without effects
    assert data["after"]["chi2_per_residual"] > 10 * data["before"]["chi2_per_residual"]
    assert main(["update", str(bare), str(measured)]) == 2
    err = capsys.readouterr().err
    assert "nothing to do" in err and err.count("\n") == 1
    # neither --add nor --drop: the present effects re-estimated (what a diagnosis's note
    # says to run when an effect the user modelled is not as the data read it)
    assert main(["update", str(again), str(measured), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [e["effect"] for e in data["effects"]] == ["section_loss"]
    assert data["after"]["chi2_per_residual"] <= data["before"]["chi2_per_residual"]


@pytest.mark.parametrize("add,match", [("rust", "unknown effect 'rust'"),
                                       ("crack:depth=0.2", "did you mean 'depth_ratio'"),
                                       ("crack:position=abc", "must be a number")])
def test_bad_add_exits_2(files, capsys, add, match):
    model, measured, _ = files
    assert main(["update", str(model), str(measured), "--add", add]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


HEAVY = ("casadi", "cvxpy", "matplotlib")


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["diagnose", "--help"],
                                  ["compare"], ["diagnose", "missing.toml", "missing.json"],
                                  ["update", "MODEL", "MEASURED", "--add", "rust"]])
def test_startup_and_input_errors_load_no_solver_nor_plotting(files, argv):
    """Issue 22: --version, --help and input errors import neither CasADi, cvxpy nor
    matplotlib (each run in a fresh interpreter, which then lists what it imported)."""
    model, measured, _ = files
    argv = [str(model) if a == "MODEL" else str(measured) if a == "MEASURED" else a
            for a in argv]
    code = ("import sys; from gfe_opt.entry import main; sys.argv[1:] = %r; rc = main(); "
            "print('loaded', sorted(m for m in %r if m in sys.modules), rc)") % (argv, HEAVY)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert "Traceback" not in out.stderr and out.returncode == 0
    last = out.stdout.strip().splitlines()[-1]
    assert last.startswith("loaded [] "), last
    if "--help" in argv or "--version" in argv:
        assert last.endswith(" 0") and len(out.stdout.splitlines()) > 1
    else:   # usage errors print their usage line first
        assert last.endswith(" 2") and out.stderr.strip().splitlines()[-1].startswith(
            "gfe-opt")


BLAS_THREADS_CODE = """import sys
from gfe_opt.entry import main
sys.argv[1:] = ['--version']
main()
import numpy, scipy.linalg, threadpoolctl
print(sorted({i['num_threads'] for i in threadpoolctl.threadpool_info()
              if i['user_api'] == 'blas'}))"""


@pytest.mark.parametrize("told", [None, "2"])
def test_the_command_loads_blas_with_one_thread_unless_the_user_set_a_count(told):
    """The `gfe-opt` command sets the BLAS libraries' thread counts to one before numpy
    loads (every fit runs under one BLAS thread; a BLAS loaded with a pool of threads made
    the forked fit workers slower at the same work), and a count the user set stands."""
    if told is not None and (os.cpu_count() or 1) < 2:
        pytest.skip("OpenBLAS takes at most one thread a core")
    env = {k: v for k, v in os.environ.items() if not k.endswith(("NUM_THREADS", "THREADS"))}
    if told is not None:
        env["OPENBLAS_NUM_THREADS"] = told
    run = subprocess.run([sys.executable, "-c", BLAS_THREADS_CODE], capture_output=True,
                         text=True, timeout=120, env=env)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip().splitlines()[-1] == f"[{told or 1}]"


def test_an_effect_fit_loads_no_casadi_and_ends_where_ipopt_first_did(files):
    """Issue 22: `update --add crack` fits by damped Newton steps from the grid's start,
    without loading CasADi (nor cvxpy, matplotlib); the old path (IPOPT to the valley, then
    the same steps, ``GFE_OPT_FIT_SOLVER=ipopt``) ends at the same crack: both within their
    stopping rule's 3e-5 σ of one optimum, so within 1e-3 σ of each other."""
    model, measured, _ = files
    code = ("import sys; from gfe_opt.entry import main; sys.argv[1:] = %r; rc = main(); "
            "print('loaded', sorted(m for m in %r if m in sys.modules), rc)") % (
        ["update", str(model), str(measured), "--add", "crack", "--json"], HEAVY)
    out = {}
    for solver in ("newton", "ipopt"):
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=300, env={**os.environ, "GFE_OPT_FIT_SOLVER": solver})
        assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
        *body, last = run.stdout.strip().splitlines()
        out[solver] = (json.loads("\n".join(body)), last)
    assert out["newton"][1] == "loaded [] 0"
    assert "casadi" in out["ipopt"][1]
    new, old = (out[s][0]["effects"][-1] for s in ("newton", "ipopt"))
    for key in ("position", "depth_ratio"):
        sigma = new["uncertainty"][key]
        assert abs(new["parameters"][key] - old["parameters"][key]) < 1e-3 * sigma, key
    assert abs(new["parameters"]["position"] - 0.4) < 3 * new["uncertainty"]["position"]


def test_builtin_effect_names_are_the_registered_ones():
    from gfe_opt.effects import EFFECTS
    from gfe_opt.names import BUILTIN_EFFECTS

    assert BUILTIN_EFFECTS == tuple(EFFECTS)
