"""Outputs only to ordinary files, the modes command's round trip for every support, and
the data edge cases: a UFF file cut short, shapes at any finite scale, zero noise, tiny
models."""

import json
import os

import numpy as np
import pytest

from gfe_opt.cli import main
from gfe_opt.problems import problem_file

from .conftest import STEEL_BAR, STEEL_BEAM

BEAM_SUPPORTS = ("pinned", "clamped", "free", "sliding")
BAR_SUPPORTS = ("fixed", "free")


def _model_file(tmp_path, base, left, right, elements=30):
    lines = ['name = "m"', f'kind = "{base["kind"]}"', f"length = {base['length']}",
             f"elements = {elements}", "[material]"]
    lines += [f"{k} = {v}" for k, v in base["material"].items()]
    lines.append("[section]")
    lines += [f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v}"
              for k, v in base["section"].items()]
    lines += ["[supports]", f'left = "{left}"', f'right = "{right}"']
    path = tmp_path / f"{left}-{right}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("base,left,right", [
    *[(STEEL_BEAM, a, b) for a in BEAM_SUPPORTS for b in BEAM_SUPPORTS],
    *[(STEEL_BAR, a, b) for a in BAR_SUPPORTS for b in BAR_SUPPORTS],
])
def test_modes_then_compare_on_its_own_output_is_exact(tmp_path, capsys, base, left, right):
    """Rigid-body modes are left out with a note, what `modes` writes reads back, and an
    elastic test mode never pairs with a rigid-body model mode."""
    model = _model_file(tmp_path, base, left, right)
    out = tmp_path / "own.json"
    assert main(["modes", str(model), "--out", str(out), "--modes", "4"]) == 0
    said = capsys.readouterr().out
    if (left, right) == ("free", "free"):
        assert "rigid-body mode" in said and "(0 Hz) left out" in said
    assert main(["compare", str(model), str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["pairs"]) == 4
    assert all(abs(p["error_pct"]) < 1e-9 and p["mac"] > 1 - 1e-9 for p in data["pairs"])
    assert all(p["model_hz"] > 0 for p in data["pairs"])


@pytest.fixture
def files(tmp_path):
    model = problem_file("ss-steel-beam.toml")
    out = tmp_path / "m.json"
    assert main(["modes", str(model), "--out", str(out), "--modes", "4"]) == 0
    return model, out, tmp_path


def _err(capsys):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("args,match", [
    (["--out", "/dev/null", "--force"], "system tree"),
    (["--out", ""], "empty path"),
    (["--out", "{tmp}/u.json"], "a model is written as .toml"),
    (["--out", "{tmp}/same.toml", "--report", "{tmp}/same.toml"],
     "a report is written as .html"),
    (["--out", "{tmp}/r.html", "--report", "{tmp}/r.html"], "a model is written as .toml"),
    (["--out", "{tmp}", "--force"], "is a directory, not an ordinary file"),
    (["--out", "{tmp}/adir.toml", "--force"], "is a directory, not an ordinary file"),
    (["--out", "{tmp}/fifo.toml", "--force"], "is a FIFO, not an ordinary file"),
    (["--out", "/proc/self/x.toml"], "system tree"),
    (["--out", "{tmp}/afile.json/x.toml"], "is a file, not a folder"),
    (["--plot", "{tmp}/afile.json"], "not a folder"),
])
def test_outputs_only_to_ordinary_files(files, capsys, args, match):
    model, measured, tmp = files
    (tmp / "adir.toml").mkdir()
    os.mkfifo(tmp / "fifo.toml")
    (tmp / "afile.json").write_text("{}")
    argv = ["update", str(model), str(measured), "--add", "crack",
            *[a.format(tmp=tmp) for a in args]]
    assert main(argv) == 2
    assert match in _err(capsys)
    assert (tmp / "fifo.toml").is_fifo() and (tmp / "adir.toml").is_dir()


def test_two_outputs_may_not_share_a_path(files, capsys):
    model, measured, tmp = files
    argv = ["diagnose", str(model), str(measured), "--candidates", "material",
            "--plot", str(tmp / "figs"), "--report", str(tmp / "figs" / "candidates.png")]
    assert main(argv) == 2
    assert "a report is written as .html" in _err(capsys)


def test_missing_folders_are_created(files, capsys):
    model, measured, tmp = files
    out = tmp / "new" / "deeper" / "u.toml"
    assert main(["update", str(model), str(measured), "--add", "material",
                 "--out", str(out)]) == 0
    assert out.is_file()


def test_a_uff_file_cut_short_is_an_error(files, capsys):
    model, _, tmp = files
    full = tmp / "m.uff"
    assert main(["modes", str(model), "--out", str(full), "--modes", "3"]) == 0
    text = full.read_text()
    (tmp / "cut.uff").write_text(text[: len(text) // 2])
    assert main(["compare", str(model), str(tmp / "cut.uff")]) == 2
    assert "incomplete: the file ends inside a dataset" in _err(capsys)


@pytest.mark.parametrize("scale", [1e300, 1e-300, 1e-320, -7.0])
def test_shapes_at_any_finite_scale_compare_alike(files, capsys, scale):
    model, measured, tmp = files
    data = json.loads(measured.read_text())
    for mode in data["modes"]:
        mode["shape"] = [v * scale for v in mode["shape"]]
    scaled = tmp / "scaled.json"
    scaled.write_text(json.dumps(data))
    assert main(["compare", str(model), str(measured), "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main(["compare", str(model), str(scaled), "--json"]) == 0
    other = json.loads(capsys.readouterr().out)
    tol = 1e-6 if abs(scale) > 1e-310 else 1e-3  # subnormals keep few bits
    assert np.allclose([p["mac"] for p in plain["pairs"]], [p["mac"] for p in other["pairs"]],
                       atol=tol)


@pytest.mark.parametrize("option", ["--freq-noise", "--shape-noise"])
def test_zero_noise_is_refused_with_the_reason(files, capsys, option):
    model, measured, _ = files
    assert main(["diagnose", str(model), str(measured), option, "0"]) == 2
    assert "must lie between 0 and 1" in _err(capsys)


def test_a_tiny_model_says_how_many_elements_it_needs(files, capsys):
    _, measured, tmp = files
    small = (tmp / "small.toml")
    small.write_text(problem_file("ss-steel-beam.toml").read_text().replace(
        "elements = 46", "elements = 2"))
    for command in (["compare"], ["diagnose"], ["update", "--add", "crack"]):
        assert main([command[0], str(small), str(measured), *command[1:]]) == 2
        assert "too few for the 4 measured: use at least 20 elements" in _err(capsys)
