"""No path, link, folder or second run makes gfe-opt lose or overwrite a user's file
(issue 23: each test is a row of its table and failed on the code before it)."""

from __future__ import annotations

import json
import multiprocessing
import os
import shutil
import tomllib

import numpy as np
import pytest

from gfe_opt.batch import JOURNAL_HEADER, journal_path, run_batch
from gfe_opt.cli import main
from gfe_opt.errors import GfeInputError
from gfe_opt.measured import load_measured, make_measured, save_measured
from gfe_opt.model import load_model, save_model
from gfe_opt.outputs import atomic_write
from gfe_opt.problems import problem_file

VICTIM_TEXT = "the user's own file\n"


@pytest.fixture
def scratch(tmp_path):
    model = tmp_path / "model.toml"
    model.write_text(problem_file("ss-steel-beam.toml").read_text())
    measured = tmp_path / "measured.json"
    shutil.copy(problem_file("demo-measured.json"), measured)
    victim = tmp_path / "victim.txt"
    victim.write_text(VICTIM_TEXT)
    return tmp_path, model, measured, victim


def _err(capsys):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def test_a_link_at_the_old_temporary_name_is_not_written_through(scratch):
    tmp, model, _, victim = scratch
    out = tmp / "out.toml"
    (tmp / f".out.toml.tmp{os.getpid()}").symlink_to(victim)   # the name it once used
    save_model(load_model(model), out)
    assert victim.read_text() == VICTIM_TEXT
    assert out.is_file() and not out.is_symlink()
    assert "effects" in tomllib.loads(out.read_text()) or out.read_text()


@pytest.mark.parametrize("writer", ["model", "figure", "measured"])
def test_a_link_at_the_output_is_replaced_never_written_through(scratch, writer):
    tmp, model, measured, victim = scratch
    out = tmp / {"model": "out.toml", "figure": "fig.png", "measured": "m.json"}[writer]
    out.symlink_to(victim)
    if writer == "model":
        save_model(load_model(model), out, force=True)
    elif writer == "measured":
        save_measured(load_measured(measured), out, force=True)
    else:
        atomic_write(out, lambda p: p.write_bytes(b"\x89PNG"), replace=True)
    assert victim.read_text() == VICTIM_TEXT
    assert out.is_file() and not out.is_symlink()


def test_no_temporary_file_or_folder_is_left(scratch):
    tmp, model, _, _ = scratch
    save_model(load_model(model), tmp / "a.toml")
    with pytest.raises(GfeInputError):
        atomic_write(tmp / "b.toml", lambda p: (_ for _ in ()).throw(OSError(28, "No space")))
    assert sorted(p.name for p in tmp.iterdir()) == ["a.toml", "measured.json", "model.toml",
                                                     "victim.txt"]


def _campaign(tmp, n=3):
    sets = tmp / "sets"
    sets.mkdir()
    m = load_measured(problem_file("demo-measured.json"))
    for i in range(n):
        save_measured(m, sets / f"set-{i + 1}.csv")
    return sets


def test_batch_output_inside_its_folder_is_refused_and_the_input_kept(scratch, capsys):
    tmp, model, _, _ = scratch
    sets = _campaign(tmp)
    before = (sets / "set-2.csv").read_bytes()
    for force in ([], ["--force"]):
        assert main(["batch", str(model), str(sets), "--add", "material",
                     "--out", str(sets / "set-2.csv"), *force]) == 2
        assert "would overwrite an input file" in _err(capsys)
    assert (sets / "set-2.csv").read_bytes() == before


def test_a_link_or_a_stranger_at_the_journal_is_refused_and_kept(scratch, capsys):
    tmp, model, _, victim = scratch
    sets = _campaign(tmp, 1)
    out = tmp / "res.csv"
    journal = journal_path(out)
    journal.symlink_to(victim)
    for force in ([], ["--force"]):
        assert main(["batch", str(model), str(sets), "--out", str(out), *force]) == 2
        assert "link" in _err(capsys)
    assert victim.read_text() == VICTIM_TEXT and journal.is_symlink()
    journal.unlink()
    journal.write_text("my notes\n")            # an ordinary file that is not a journal
    for force in ([], ["--force"]):
        assert main(["batch", str(model), str(sets), "--out", str(out), *force]) == 2
        assert "not this batch's journal" in _err(capsys)
    assert journal.read_text() == "my notes\n" and not out.exists()


def test_the_journal_is_created_with_its_header_and_resumed(scratch, tmp_path):
    tmp, model, _, _ = scratch
    sets = _campaign(tmp, 1)
    out = tmp / "res.csv"
    journal = journal_path(out)
    journal.write_text(JOURNAL_HEADER + "\n")   # a batch killed before its first row
    result = run_batch(model, sets, out, workers=1)
    assert result.ran == 1 and out.is_file() and not journal.exists()


def test_demo_refuses_the_users_figures_without_force(tmp_path, capsys):
    out = tmp_path / "mydemo"
    (out / "figures").mkdir(parents=True)
    for name in ("mac.png", "error.png"):
        (out / "figures" / name).write_text(VICTIM_TEXT)
    assert main(["demo", "--out", str(out)]) == 2
    assert "mac.png: exists and is not as the demo wrote it" in _err(capsys)
    assert (out / "figures" / "error.png").read_text() == VICTIM_TEXT
    assert sorted(p.name for p in out.rglob("*")) == ["error.png", "figures", "mac.png"]


def test_the_frame_demo_refuses_the_users_frame_figure_before_any_work(tmp_path, capsys):
    """``demo --frame`` keeps its own list of files (the frame's figures among them) and
    refuses, before any work, one it did not write."""
    out = tmp_path / "framedemo"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "frame_modes.png").write_text(VICTIM_TEXT)
    assert main(["demo", "--frame", "--out", str(out)]) == 2
    assert "frame_modes.png: exists and is not as the demo wrote it" in _err(capsys)
    assert sorted(p.name for p in out.rglob("*")) == ["figures", "frame_modes.png"]


def test_demo_force_refuses_a_folder_where_it_writes_a_file(tmp_path, capsys):
    out = tmp_path / "d"
    (out / "model.toml").mkdir(parents=True)
    assert main(["demo", "--out", str(out), "--force"]) == 2
    assert "model.toml" in _err(capsys) and (out / "model.toml").is_dir()


def test_names_too_long_are_refused_before_any_work_and_long_ones_written(scratch, capsys):
    tmp, model, measured, _ = scratch
    long_ok = tmp / ("n" * 245 + ".toml")           # 250 bytes: the limit is 255
    save_model(load_model(model), long_ok)
    assert long_ok.is_file()
    too_long = tmp / ("n" * 251 + ".toml")
    assert main(["update", str(model), str(measured), "--add", "material",
                 "--out", str(too_long)]) == 2
    assert "its name has 256 bytes" in _err(capsys)


def test_modes_of_a_huge_model_to_a_file_is_refused_before_work(tmp_path, capsys):
    path = tmp_path / "bar.toml"
    path.write_text('name = "bar"\nkind = "bar"\nlength = 2.0\nelements = 1000000\n'
                    '[material]\nE = 70e9\nrho = 2700.0\n[section]\nA = 1e-4\n'
                    '[supports]\nleft = "fixed"\nright = "free"\n')
    assert main(["modes", str(path), "--out", str(tmp_path / "bar.json")]) == 2
    err = _err(capsys)
    assert err.startswith("gfe-opt: error: --out:") and "1000001 nodes" in err


def test_csv_fields_over_the_limit_and_bad_encodings_are_one_line(scratch, capsys):
    tmp, model, _, _ = scratch
    wide = tmp / "wide.csv"
    wide.write_text('x,100.0\n0.1,"' + "1" * 140_000 + '"\n')
    assert main(["compare", str(model), str(wide)]) == 2
    assert "not readable as CSV" in _err(capsys)
    table = tmp / "table.csv"
    table.write_text('file,status\n"' + "a" * 140_000 + '",ok\n')
    assert main(["trend", str(table)]) == 2
    assert "not readable as CSV" in _err(capsys)
    table.write_bytes(b"file,status\n\xff\xfe\xfa,ok\n")
    assert main(["trend", str(table)]) == 2
    assert "not UTF-8" in _err(capsys)


def test_sensor_positions_must_be_numbers(scratch, capsys):
    tmp, model, measured, _ = scratch
    data = json.loads(measured.read_text())
    for bad in ("0.1", True):
        data["sensors"]["x"][0] = bad
        path = tmp / "bad.json"
        path.write_text(json.dumps(data))
        assert main(["compare", str(model), str(path)]) == 2
        assert "sensors.x: must hold numbers only" in _err(capsys)


def test_places_follow_the_structure_whatever_the_files_order(scratch, capsys):
    tmp, model, measured, _ = scratch
    m = load_measured(measured)
    order = np.random.default_rng(0).permutation(m.n_sensors)
    shuffled = make_measured(m.x[order], m.dof, m.frequencies_hz, m.shapes[order], "s")
    save_measured(shuffled, tmp / "shuffled.json")
    np.testing.assert_array_equal(load_measured(tmp / "shuffled.json").x, m.x)
    assert main(["compare", str(model), str(measured)]) == 0
    ordered = capsys.readouterr().out
    assert main(["compare", str(model), str(tmp / "shuffled.json")]) == 0
    assert capsys.readouterr().out == ordered


def test_a_sparkline_is_one_terminal_line(scratch, capsys):
    tmp, model, _, _ = scratch
    x = np.linspace(0.001, 0.574, 5000)
    shapes = np.sin(np.pi * np.outer(x, [1, 2]) / 0.575)
    save_measured(make_measured(x, "w", [208.0, 840.0], shapes, "many"), tmp / "many.json")
    assert main(["compare", str(model), str(tmp / "many.json")]) == 0
    spark = [line for line in capsys.readouterr().out.splitlines() if line.startswith("  |")]
    assert len(spark) == 1 and len(spark[0]) <= 80, spark


def _claim(path, barrier, results):
    from gfe_opt.model import load_model as load

    barrier.wait()
    try:
        save_model(load(str(problem_file("ss-steel-beam.toml"))), path)
        results.put("ok")
    except GfeInputError:
        results.put("refused")


def test_of_two_concurrent_runs_writing_one_new_file_exactly_one_wins(tmp_path):
    context = multiprocessing.get_context("fork")
    for i in range(100):
        path = tmp_path / f"same-{i}.toml"
        barrier, results = context.Barrier(2), context.Queue()
        runs = [context.Process(target=_claim, args=(path, barrier, results))
                for _ in range(2)]
        for run in runs:
            run.start()
        for run in runs:
            run.join(timeout=60)
        outcomes = sorted(results.get(timeout=10) for _ in runs)
        assert outcomes == ["ok", "refused"], (i, outcomes)
        assert tomllib.loads(path.read_text())["name"]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
