"""Hostile input and resources: the inputs that once ended in a traceback, were accepted
without a word or ate the machine, each a regression test (issue 13's table)."""

import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pytest

from gfe_opt.cli import main
from gfe_opt.problems import problem_file


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hostile")
    model = tmp / "model.toml"
    model.write_text(problem_file("ss-steel-beam.toml").read_text())
    truth = tmp / "truth.toml"
    truth.write_text(model.read_text().replace("elements = 46", "elements = 200")
                     + '\n[[effects]]\neffect = "crack"\nposition = 0.19\ndepth_ratio = 0.5\n')
    measured = tmp / "measured.json"
    assert main(["modes", str(truth), "--out", str(measured), "--modes", "4"]) == 0
    return tmp, model, measured


def _fails(capsys, argv, match, code=2):
    assert main(argv) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert match in err, err


def test_binary_and_utf16_models_are_one_line(files, capsys):
    tmp, model, measured = files
    (tmp / "bin.toml").write_bytes(os.urandom(2000))
    _fails(capsys, ["compare", str(tmp / "bin.toml"), str(measured)], "bin.toml:")
    (tmp / "u16.toml").write_bytes(model.read_text().encode("utf-16"))
    _fails(capsys, ["compare", str(tmp / "u16.toml"), str(measured)], "UTF-16")


def test_a_byte_order_mark_is_accepted(files, capsys):
    tmp, model, measured = files
    (tmp / "bom.toml").write_bytes(b"\xef\xbb\xbf" + model.read_bytes())
    assert main(["compare", str(tmp / "bom.toml"), str(measured)]) == 0


@pytest.mark.parametrize("elements,match", [(1, "too few for the 4 measured"),
                                            (10_000_000, "above 30000")])
def test_meshes_too_coarse_or_too_fine_are_one_line_at_once(files, capsys, elements, match):
    tmp, model, measured = files
    bad = tmp / f"e{elements}.toml"
    bad.write_text(model.read_text().replace("elements = 46", f"elements = {elements}"))
    start = time.perf_counter()
    _fails(capsys, ["compare", str(bad), str(measured)], match)
    assert time.perf_counter() - start < 5  # refused before anything is allocated


def test_output_paths(files, capsys, tmp_path):
    _, model, measured = files
    out = tmp_path / "no" / "such" / "dir" / "x.toml"
    assert main(["update", str(model), str(measured), "--add", "material",
                 "--out", str(out)]) == 0 and out.is_file()
    (tmp_path / "adir").mkdir()
    _fails(capsys, ["update", str(model), str(measured), "--add", "material",
                    "--out", str(tmp_path / "adir"), "--force"], "is a directory")
    report = tmp_path / "nodir" / "r.html"
    assert main(["compare", str(model), str(measured), "--report", str(report)]) == 0
    assert report.is_file()
    _fails(capsys, ["compare", str(model), str(measured), "--plot", str(measured),
                    "--force"], "not a folder")


def test_a_read_only_file_system_is_one_line(files, capsys, tmp_path, monkeypatch):
    _, model, measured = files

    def refuse(*args):
        raise OSError(30, "Read-only file system")

    monkeypatch.setattr(os, "replace", refuse)
    monkeypatch.setattr(os, "link", refuse)
    _fails(capsys, ["update", str(model), str(measured), "--add", "material",
                    "--out", str(tmp_path / "u.toml")], "cannot write (Read-only file system)")
    assert not list(tmp_path.iterdir())  # no temporary file left either


@pytest.mark.parametrize("add,match", [
    ("crack:depth_ratio=1.5", "must lie between 0 and 1"),
    ("point_mass:mass=-1", "must be > 0"),
    ("crack:position=0", "the pinned left end, where the bending moment is zero"),
    ("crack:position=0.2,position=0.3", "position is given twice"),
    ("crak", "did you mean 'crack'"),
])
def test_added_values_are_checked(files, capsys, add, match):
    _, model, measured = files
    _fails(capsys, ["update", str(model), str(measured), "--add", add], match)


def test_frequencies_in_rad_per_second_are_named(files, capsys, tmp_path):
    import json

    _, model, measured = files
    data = json.loads(measured.read_text())
    for mode in data["modes"]:
        mode["frequency"] *= 2 * 3.14159
    (tmp_path / "rad.json").write_text(json.dumps(data))
    for command in (["compare"], ["diagnose"], ["update", "--add", "crack"]):
        _fails(capsys, [command[0], str(model), str(tmp_path / "rad.json"), *command[1:]],
               "close to 2π: given in rad/s?")


def test_a_sensor_on_a_pinned_support_is_dropped_with_a_note(files, capsys, tmp_path):
    import json

    _, model, measured = files
    data = json.loads(measured.read_text())
    data["sensors"]["x"][0] = 0.0  # sits on the pin: reads only noise
    (tmp_path / "pin.json").write_text(json.dumps(data))
    assert main(["compare", str(model), str(tmp_path / "pin.json")]) == 0
    out = capsys.readouterr().out
    assert "sensor at x = 0 m on a support that holds the structure still: left out" in out
    assert "fails most near x = 0.000" not in out


def test_special_and_oversized_inputs_are_refused_before_reading(files, capsys, tmp_path):
    _, model, measured = files
    os.mkfifo(tmp_path / "fifo.json")
    _fails(capsys, ["compare", str(model), str(tmp_path / "fifo.json")], "is a FIFO")
    (tmp_path / "dir.json").mkdir()
    _fails(capsys, ["compare", str(model), str(tmp_path / "dir.json")], "is a directory")
    big = tmp_path / "big.json"
    with open(big, "wb") as fh:  # sparse: 300 MB that take no disk
        fh.truncate(300 * 1024 * 1024)
    _fails(capsys, ["compare", str(model), str(big)], "above the 200 MB limit")


def test_concurrent_writers_leave_one_complete_file(files, tmp_path):
    _, model, measured = files
    out = tmp_path / "u.toml"
    argv = ["update", str(model), str(measured), "--add", "material", "--out", str(out),
            "--force"]
    runs = [subprocess.Popen([sys.executable, "-m", "gfe_opt.cli", *argv],
                             stderr=subprocess.PIPE) for _ in range(3)]
    assert [r.wait(timeout=120) for r in runs] == [0, 0, 0]
    assert tomllib.loads(out.read_text())["effects"][0]["effect"] == "material"
    assert [p.name for p in tmp_path.iterdir()] == ["u.toml"]


def _group_members(pgid: int) -> list[int]:
    """Processes of a process group (Linux /proc), the leader included."""
    members = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid:
            members.append(int(stat.parent.name))
    return members


def _default_sigint():
    """Ctrl-C's default disposition in the child, as in a terminal: a suite started in the
    background by a non-interactive shell (``pytest &``) has SIGINT ignored, the child
    inherits that, and Python then installs no KeyboardInterrupt handler (it exited 0)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_is_one_line_exit_130_no_file_no_worker_left(files, tmp_path):
    _, model, measured = files
    # a finer model than the fixture's: the diagnosis lasts long enough to be interrupted
    # however fast the fits (the fixed 2 s wait came after the end once fits were faster)
    fine = tmp_path / "fine.toml"
    fine.write_text(model.read_text().replace("elements = 46", "elements = 150"))
    report = tmp_path / "r.html"
    run = subprocess.Popen([sys.executable, "-c", "import sys; from gfe_opt.entry import main;"
                            " sys.exit(main())", "diagnose", str(fine), str(measured),
                            "--report", str(report)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True, preexec_fn=_default_sigint)
    deadline = time.monotonic() + 60
    while len(_group_members(run.pid)) < 2 and run.poll() is None:  # until workers fit
        assert time.monotonic() < deadline, "no worker started"
        time.sleep(0.05)
    time.sleep(0.3)  # inside the candidate fits
    os.killpg(run.pid, signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 130 and err.count("\n") == 1 and "interrupted" in err, err
    time.sleep(0.5)
    with pytest.raises(ProcessLookupError):
        os.killpg(run.pid, 0)  # no worker left in the process group
    assert not report.exists()
