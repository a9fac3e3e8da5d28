"""A fuzzer in the suite: valid model, JSON, CSV and UFF files and option strings, mutated
(bytes, encodings, keys, values, lengths), through the command line in-process.  Every run
ends with exit 0, exit 2 and one line, or exit 1 and the solver's status: never a traceback,
never an internal error.

The number of examples comes from the hypothesis profile: ``ci`` (the default, a few
thousand within a minute) or ``long`` (``python scripts/fuzz.py``, or
``python -m pytest tests/test_fuzz.py --hypothesis-profile long``).
"""

import contextlib
import copy
import io
import json
import os
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gfe_opt.cli import main

MODEL = """name = "fuzz"
kind = "beam"
length = 0.575
elements = 12
[material]
E = 206e9
rho = 7800
nu = 0.3
[section]
shape = "rectangle"
b = 0.009525
h = 0.03175
[supports]
left = "pinned"
right = "pinned"

[[effects]]
effect = "crack"
position = 0.2
depth_ratio = 0.3
"""

WEIRD = [0, -1, 1, 0.5, 1e308, -1e308, 1e-320, 10**30, "", "x", "pinned", [], [1, 2], {},
         True, None, "nan", "inf", -0.0, 3]
OPTIONS = ["--json", "--force", "--mac-threshold", "--noise", "--freq-noise", "--shape-noise",
           "--candidates", "--modes", "--add", "--out", "--plot", "--report", "--bogus"]
VALUES = ["0", "-1", "1", "0.5", "1e400", "nan", "", "x", "crack", "material,crack",
          "crak", "crack:position=0.2", "crack:position=9", "point_mass:mass=-1",
          "stiffness_profile:x=0;0.575", "3", "99999999", "out.toml", "out.json", "figs",
          "r.html", "/dev/null"]


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fuzz-seeds")
    (tmp / "model.toml").write_text(MODEL)
    texts = {"model.toml": MODEL}
    for suffix in ("json", "csv", "uff"):
        out = tmp / f"measured.{suffix}"
        assert _run(["modes", str(tmp / "model.toml"), "--out", str(out), "--modes", "4"])[0] == 0
        texts[f"measured.{suffix}"] = out.read_text()
    return texts


def _run(argv, cwd=None):
    """Run the CLI in `cwd` (a bare value such as `--plot nan` is a path relative to it)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(cwd or os.getcwd()), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _check(code, out, err):
    assert "Traceback" not in err + out, err
    assert code in (0, 1, 2), (code, err)
    if code:
        assert err.count("\n") == 1 and err.startswith("gfe-opt"), err
    if code == 1:
        assert "solver failed" in err, err


# -- mutations -------------------------------------------------------------------------------

@st.composite
def byte_mutation(draw, text: str) -> bytes:
    data = bytearray(text.encode())
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["flip", "delete", "insert", "truncate", "duplicate",
                                   "utf16", "latin1", "bom", "empty", "nul", "wide"]))
        i = draw(st.integers(0, max(len(data) - 1, 0)))
        if op == "flip" and data:
            data[i] ^= 1 << draw(st.integers(0, 7))
        elif op == "delete":
            del data[i:i + draw(st.integers(1, 40))]
        elif op == "insert":
            data[i:i] = draw(st.binary(min_size=1, max_size=20))
        elif op == "truncate":
            del data[i:]
        elif op == "duplicate":
            data[i:i] = data[i:i + draw(st.integers(1, 200))]
        elif op == "utf16":
            data = bytearray(bytes(data).decode("utf-8", "replace").encode("utf-16"))
        elif op == "latin1":
            data = bytearray(bytes(data).decode("utf-8", "replace").replace(
                "e", "é").encode("latin-1", "replace"))
        elif op == "bom":
            data = bytearray(b"\xef\xbb\xbf" + bytes(data))
        elif op == "empty":
            data = bytearray()
        elif op == "nul":
            data[i:i] = b"\0"
        elif op == "wide":  # a field past the csv module's 131 072 characters
            data[i:i] = b'"' + b"1" * draw(st.sampled_from([131_073, 140_000])) + b'"'
    return bytes(data)


def _paths(tree, prefix=()):
    yield prefix
    if isinstance(tree, dict):
        for k, v in tree.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            yield from _paths(v, prefix + (i,))


@st.composite
def structure_mutation(draw, tree):
    """Keys deleted, renamed or set to odd values; lists shortened or lengthened."""
    tree = json.loads(json.dumps(tree))
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(tree) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = tree
        for key in path[:-1]:
            parent = parent[key]
        key = path[-1]
        op = draw(st.sampled_from(["value", "delete", "rename", "grow", "shrink"]))
        if op == "value":
            # a copy: a later delete inside [1, 2] must not change WEIRD itself (hypothesis
            # saw the next examples draw differently: FlakyStrategyDefinition)
            parent[key] = copy.deepcopy(draw(st.sampled_from(WEIRD)))
        elif op == "delete":
            del parent[key]
        elif op == "rename" and isinstance(parent, dict):
            parent[str(key)[:-1] + "_"] = parent.pop(key)
        elif op in ("grow", "shrink") and isinstance(parent[key], list):
            parent[key] = parent[key] + parent[key][:1] if op == "grow" else parent[key][:-1]
    return tree


def _toml(tree) -> str:
    """A small TOML writer for mutated trees (tomli_w refuses None and mixed arrays)."""
    def value(v):
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, bool):
            return "true" if v else "false"
        if v is None:
            return '"None"'
        if isinstance(v, float) and v != v:
            return "nan"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{json.dumps(k)} = {value(x)}" for k, x in v.items()) + "}"
        return repr(v)

    lines = [f"{json.dumps(k)} = {value(v)}" for k, v in tree.items()
             if not isinstance(v, dict) and k != "effects"]
    for k, v in tree.items():
        if isinstance(v, dict):
            lines.append(f"[{json.dumps(k)}]")
            lines += [f"{json.dumps(kk)} = {value(vv)}" for kk, vv in v.items()]
    if isinstance(tree.get("effects"), list):
        for e in tree["effects"]:
            lines.append("[[effects]]")
            if isinstance(e, dict):
                lines += [f"{json.dumps(kk)} = {value(vv)}" for kk, vv in e.items()]
    elif "effects" in tree:
        lines.insert(0, f"effects = {value(tree['effects'])}")
    return "\n".join(lines) + "\n"


COMMANDS = [["compare"], ["compare", "--json"], ["update", "--add", "material"],
            ["modes"]]


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_files_never_crash(seeds, tmp_path, data):
    target = data.draw(st.sampled_from(sorted(seeds)))
    text = seeds[target]
    if data.draw(st.booleans()) and target.endswith((".toml", ".json")):
        tree = tomllib.loads(text) if target.endswith(".toml") else json.loads(text)
        mutated = data.draw(structure_mutation(tree))
        raw = (_toml(mutated) if target.endswith(".toml") else json.dumps(mutated)).encode()
    else:
        raw = data.draw(byte_mutation(text))
    files = {name: tmp_path / name for name in seeds}
    for name, path in files.items():
        path.write_bytes(raw if name == target else seeds[name].encode())
    measured = target if target.startswith("measured") else data.draw(
        st.sampled_from([n for n in seeds if n.startswith("measured")]))
    command = data.draw(st.sampled_from(COMMANDS))
    if command[0] == "modes":
        argv = ["modes", str(files["model.toml"]), "--out", str(tmp_path / "o.json"),
                "--force"]
    else:
        argv = [command[0], str(files["model.toml"]), str(files[measured]), *command[1:]]
    _check(*_run(argv, tmp_path))


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_options_never_crash(seeds, tmp_path, data):
    for name, text in seeds.items():
        (tmp_path / name).write_text(text)
    command = data.draw(st.sampled_from(["compare", "update", "modes", "diagnose", "bogus"]))
    args = [command, str(tmp_path / "model.toml")]
    if command != "modes":
        args.append(str(tmp_path / data.draw(st.sampled_from(
            ["measured.json", "measured.csv", "measured.uff"]))))
    if command == "diagnose":
        args += ["--candidates", "material"]  # the full diagnosis is tested elsewhere
    for _ in range(data.draw(st.integers(0, 4))):
        option = data.draw(st.sampled_from(OPTIONS))
        args.append(option)
        if option not in ("--json", "--force", "--bogus") and data.draw(st.booleans()):
            value = data.draw(st.sampled_from(VALUES))
            args.append(str(tmp_path / value) if value in ("out.toml", "out.json", "figs",
                                                           "r.html") else value)
    _check(*_run(args, tmp_path))


def _table_seed() -> str:
    """A small batch table as ``gfe-opt batch`` writes it (CSV): four sets, a crack growing."""
    import tempfile
    from pathlib import Path

    from gfe_opt.batch import FIXED_COLUMNS, write_table

    rows = []
    for i in range(4):
        row = dict.fromkeys(FIXED_COLUMNS)
        row.update(file=f"set-{i}.json", sha1="0" * 40, time=f"2026-01-0{i + 1}T00:00",
                   task="update material+crack", model_sha1="1" * 40, status="ok",
                   freq_error_before_pct=0.5 + i, freq_error_after_pct=0.04,
                   **{"material.E": 2.06e11 * (1 + 0.001 * i), "material.E.sigma": 1e8,
                      "crack.depth_ratio": 0.1 * i, "crack.depth_ratio.sigma": 0.01,
                      "crack.size_sigmas": 10.0 * i})
        rows.append(row)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "table.csv"
        write_table(rows, path)
        return path.read_text()


TABLE = _table_seed()


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_batch_tables_never_crash(tmp_path, data):
    """``gfe-opt trend`` on a mutated batch table (issue 23: a field over the CSV limit or a
    table that is not UTF-8 ended in an internal error)."""
    path = tmp_path / "table.csv"
    path.write_bytes(data.draw(byte_mutation(TABLE)))
    args = ["trend", str(path)] + (["--json"] if data.draw(st.booleans()) else [])
    _check(*_run(args, tmp_path))
