"""Measured modes: frequencies [Hz] and shapes at sensors, read from JSON, CSV or UFF.

Formats (contracts, see README "Measured modes"):

* JSON::

    {"sensors": {"x": [0.0125, 0.025], "dof": "w"},
     "modes": [{"frequency": 223.4, "damping": 0.012, "shape": [0.068, 0.136]}]}

  ``damping`` (the modal damping ratio ζ, 0 ≤ ζ < 1) is optional.  A test without shapes
  leaves out ``sensors`` and every ``shape``: ``{"modes": [{"frequency": 6.57}, ...]}``.

* CSV: a header row ``x,<f1>,<f2>,...`` (the first cell any label, the others the natural
  frequencies in Hz), then one row per sensor: its position x [m] and one value per mode.
  Lines starting with ``#`` are comments.  The DOF is the model's (``w`` beam, ``u`` bar).
  The header row alone is a frequency-only test.
* UFF (``.uff``/``.unv``): node coordinates from dataset 15 or 2411 (x along the structure),
  one dataset 55 (analysis type 2, normal modes) per mode.  ``w`` is read from the z
  component (or y when every z is zero), ``u`` from the x component.

Fewer than :data:`MIN_SHAPE_SENSORS` sensors make a *frequency-only* test: shapes at one or
two points cannot tell modes apart (the MAC of two numbers is near 1 for any pair), so the
modes pair by frequency and only frequencies are compared.

Shapes may have any scale and sign; they are kept with each mode's largest amplitude at 1 (a
mode shape's scale means nothing, and 1e300 squared overflows).  Modes are sorted by
frequency; sensors keep file order.
"""

from __future__ import annotations

import csv
import itertools
import json
from dataclasses import dataclass, replace
from datetime import datetime
from functools import lru_cache
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from . import elements as el
from .errors import GfeInputError
from .inputs import MAX_MEASURED_MODES, MAX_SENSORS, check_input_file, parse_failure, read_text
from .outputs import atomic_write, check_output_path

DOFS = ("w", "u")
#: shapes at fewer sensors than this are not compared (frequency-only test)
MIN_SHAPE_SENSORS = 3
#: measured frequencies above this are not structural modes
MAX_FREQUENCY_HZ = 1e8


class ModeCounts:
    """What a fit counts of a test (``frequencies_hz`` and ``n_sensors`` given by the
    class): modes, whether shapes are used, residuals."""

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)

    @property
    def frequency_only(self) -> bool:
        """Too few sensors for shapes to tell modes apart: compared by frequency alone."""
        return self.n_sensors < MIN_SHAPE_SENSORS

    @property
    def shape_sensors(self) -> int:
        """Shape residuals per mode (0 for a frequency-only test)."""
        return 0 if self.frequency_only else self.n_sensors

    @property
    def n_values(self) -> int:
        """Measured values compared with a model: frequencies and, if used, shapes."""
        return self.n_modes * (1 + self.shape_sensors)

    @property
    def omega(self) -> np.ndarray:
        return 2.0 * np.pi * self.frequencies_hz

    def without_shapes_note(self) -> str | None:
        """Why the shapes are not used, or None (a beam's test or a frame's)."""
        if not self.frequency_only:
            return None
        what = ("no mode shapes" if self.n_sensors == 0 else
                f"shapes at {self.n_sensors} sensor{'s' if self.n_sensors > 1 else ''} "
                "cannot tell modes apart")
        return (f"{what}: modes paired by frequency (nearest, one to one) and only "
                "frequencies compared; MAC and where the model fails are unavailable")


@dataclass(frozen=True)
class MeasuredModes(ModeCounts):
    """Measured natural frequencies (n_modes,) [Hz] and shapes (n_sensors, n_modes).

    ``x`` holds the sensor positions [m] from the left end, ``dof`` the measured direction
    (``"w"`` transverse, ``"u"`` axial).
    """

    x: np.ndarray
    dof: str
    frequencies_hz: np.ndarray
    shapes: np.ndarray
    source: str = "measured"
    damping: np.ndarray | None = None
    time: str | float | None = None    # when the test was made (ISO 8601 text or a number)
    label: str | None = None           # a name for the test (batch tables and trends)

    @property
    def n_sensors(self) -> int:
        return len(self.x)


def make_measured(x, dof, frequencies_hz, shapes, source="measured",
                  damping=None) -> MeasuredModes:
    """Validate and build :class:`MeasuredModes` (modes sorted by frequency).  ``x`` empty
    and ``shapes`` None make a frequency-only test; ``damping`` holds ζ per mode (NaN where
    not measured) or is None."""
    if dof not in DOFS:
        raise GfeInputError(source, "sensors.dof", f"unknown dof {dof!r} (one of w, u)")
    x = _finite_array([] if x is None else x, source, "sensors.x", ndim=1)
    if x.size > MAX_SENSORS:
        raise GfeInputError(source, "sensors.x", f"{x.size} sensors is above the limit of "
                            f"{MAX_SENSORS}")
    if np.unique(x).size != x.size:
        dup = x[np.flatnonzero(np.diff(np.sort(x)) == 0)[0]]
        raise GfeInputError(source, "sensors.x", f"sensor position {dup:g} m appears twice")
    f = _finite_array(frequencies_hz, source, "frequency", ndim=1)
    if f.size == 0:
        raise GfeInputError(source, "modes", "no modes")
    if f.size > MAX_MEASURED_MODES:
        raise GfeInputError(source, "modes", f"{f.size} modes is above the limit of "
                            f"{MAX_MEASURED_MODES} measured modes")
    if np.any(f <= 0):
        i = int(np.flatnonzero(f <= 0)[0])
        raise GfeInputError(source, f"modes[{i}].frequency", f"must be > 0 Hz, got {f[i]:g}")
    if np.any(f > MAX_FREQUENCY_HZ):
        i = int(np.flatnonzero(f > MAX_FREQUENCY_HZ)[0])
        raise GfeInputError(source, f"modes[{i}].frequency", f"{f[i]:g} Hz is above "
                            f"{MAX_FREQUENCY_HZ:g} Hz: not a structural mode (a typo?)")
    if shapes is None:
        if x.size:
            raise GfeInputError(source, "shape", f"{x.size} sensors but no shapes")
        shapes = np.zeros((0, f.size))
    shapes = _finite_array(shapes, source, "shape", ndim=2)
    if shapes.shape != (x.size, f.size):
        raise GfeInputError(source, "shape", f"expected {x.size} values per mode (one per "
                            f"sensor) for {f.size} modes, got array {shapes.shape}")
    if x.size:
        zero = np.flatnonzero(~np.any(shapes != 0, axis=0))
        if zero.size:
            raise GfeInputError(source, f"modes[{zero[0]}].shape", "all values are zero")
        # shapes have any scale: each mode to a largest amplitude of 1 before any product
        # (1e300 squared overflows, 1e-320 squared underflows)
        shapes = shapes / np.max(np.abs(shapes), axis=0)
    if x.size:
        # sensors in position order, whatever the file's: everything drawn or read along
        # the structure (sparkline, "also near", plots) follows them
        along = np.argsort(x, kind="stable")
        x, shapes = x[along], shapes[along]
    if damping is not None:
        damping = np.asarray(damping, dtype=float)
        if damping.shape != f.shape:
            raise GfeInputError(source, "damping", f"expected one value per mode ({f.size}), "
                                f"got {damping.size}")
        bad = np.flatnonzero(~np.isnan(damping) & ~((damping >= 0) & (damping < 1)))
        if bad.size:
            raise GfeInputError(source, f"modes[{bad[0]}].damping", "must be a damping ratio "
                                f"in [0, 1), got {damping[bad[0]]:g}")
    order = np.argsort(f, kind="stable")
    f, shapes = f[order], shapes[:, order]
    damping = None if damping is None else damping[order]
    dup = np.flatnonzero(np.diff(f) == 0)
    if dup.size:
        raise GfeInputError(source, "frequency", f"frequency {f[dup[0]]:g} Hz appears twice")
    return MeasuredModes(x=x, dof=dof, frequencies_hz=f, shapes=shapes, source=source,
                         damping=damping)


_NUMBER_TYPES = (int, float, np.integer, np.floating)


def _numbers_only(values) -> bool:
    """True when ``values`` (an array, or lists nested one or two deep) hold numbers only:
    no strings or booleans (``np.asarray(..., float)`` would take "0.1" and true).  The
    types of a list of lists are collected in C (``map(type, ...)``): 20 million values in
    0.6 s, where a recursive check took 8 s."""
    if isinstance(values, np.ndarray):
        return values.dtype.kind in "iuf"
    if not isinstance(values, (list, tuple)):
        values = [values]
    if any(isinstance(v, (list, tuple)) for v in values):
        if not all(isinstance(v, (list, tuple)) for v in values):
            return False
        values = itertools.chain.from_iterable(values)
    kinds = set(map(type, values))
    return all(issubclass(k, _NUMBER_TYPES) and not issubclass(k, (bool, np.bool_))
               for k in kinds)


def _finite_array(values, source, field, ndim):
    if not _numbers_only(values):
        raise GfeInputError(source, field, "must hold numbers only (no text or true/false)")
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise GfeInputError(source, field, "must hold numbers only") from None
    if arr.ndim != ndim:
        raise GfeInputError(source, field, f"must be a {ndim}-d array of numbers")
    if not np.all(np.isfinite(arr)):
        raise GfeInputError(source, field, "contains NaN or infinite values")
    return arr


# -------------------------------------------------------------------------------------------
# Readers
# -------------------------------------------------------------------------------------------


def load_measured(path, dof: str | None = None) -> MeasuredModes:
    """Read measured modes from ``.json``, ``.csv`` or ``.uff``/``.unv``.

    ``dof`` is needed only where the file does not say it (CSV; defaults to ``"w"``).
    """
    path = check_input_file(path, "measured")
    suffix = path.suffix.lower()
    if suffix == ".json":
        return _read_json(path)
    if suffix == ".csv":
        return _read_csv(path, dof or "w")
    if suffix in (".uff", ".unv"):
        return _read_uff(path, dof)
    raise GfeInputError(str(path), None, f"unknown measured-data format {suffix!r} "
                        "(use .json, .csv, .uff or .unv)")


def read_json(path, what: str = "measured"):
    """The parsed JSON of an input file; a file that is not JSON is one line."""
    where = str(path)
    try:
        return json.loads(read_text(path, what))
    except json.JSONDecodeError as exc:
        raise GfeInputError(where, None, f"not valid JSON ({exc})") from None
    except RecursionError:
        raise GfeInputError(where, None, "not valid JSON (nested too deeply)") from None
    except ValueError as exc:   # (an integer of more digits than Python converts)
        raise GfeInputError(where, None, f"not valid JSON ({parse_failure(exc)})") from None


def _read_json(path: Path) -> MeasuredModes:
    where = str(path)
    data = read_json(path)
    if not isinstance(data, dict):
        raise GfeInputError(where, None, "top level must be an object with sensors and modes")
    for key in data:
        if key not in ("sensors", "modes", "time", "label"):
            raise GfeInputError(where, key, "unknown key (expected sensors, modes, time, "
                                "label)")
    stamp = time_and_label(data.get("time"), data.get("label"), where)
    modes = data.get("modes")
    if not isinstance(modes, list) or not modes:
        raise GfeInputError(where, "modes", "missing or empty (a list of modes)")
    with_shape = [isinstance(m, dict) and "shape" in m for m in modes]
    sensors = data.get("sensors")
    if any(with_shape) or sensors is not None:
        if not isinstance(sensors, dict) or "x" not in sensors:
            raise GfeInputError(where, "sensors", "missing or without x (sensor positions "
                                "in m); leave out sensors and every shape for a "
                                "frequency-only test")
        for key in sensors:
            if key not in ("x", "dof"):
                raise GfeInputError(where, f"sensors.{key}", "unknown key (expected x, dof)")
    n_sensors = (len(sensors["x"]) if isinstance(sensors["x"], list) else -1) if sensors \
        else 0
    shaped = n_sensors != 0
    freqs, shapes, damping = [], [], []
    for i, mode in enumerate(modes):
        if not isinstance(mode, dict) or "frequency" not in mode:
            raise GfeInputError(where, f"modes[{i}]", "needs a frequency")
        for key in mode:
            if key not in ("frequency", "damping", "shape"):
                raise GfeInputError(where, f"modes[{i}].{key}", "unknown key (expected "
                                    "frequency, damping, shape)")
        if not _is_number(mode["frequency"]):
            raise GfeInputError(where, f"modes[{i}].frequency",
                                f"must be a number, got {mode['frequency']!r}")
        if "damping" in mode and not _is_number(mode["damping"]):
            raise GfeInputError(where, f"modes[{i}].damping",
                                f"must be a number, got {mode['damping']!r}")
        if shaped and "shape" not in mode:
            raise GfeInputError(where, f"modes[{i}]", "has no shape while there are sensors "
                                "(give every mode a shape, or none and no sensors)")
        if not shaped and "shape" in mode:
            raise GfeInputError(where, f"modes[{i}].shape", "given but there are no sensors")
        if shaped:
            if not isinstance(mode["shape"], list) or not all(_is_number(v)
                                                              for v in mode["shape"]):
                raise GfeInputError(where, f"modes[{i}].shape", "must be a list of numbers")
            if len(mode["shape"]) != n_sensors:
                raise GfeInputError(where, f"modes[{i}].shape", f"has {len(mode['shape'])} "
                                    f"values but there are {n_sensors} sensors")
            shapes.append(mode["shape"])
        freqs.append(mode["frequency"])
        damping.append(mode.get("damping", np.nan))
    damping = None if all(np.isnan(d) for d in damping) else damping
    if not shaped:
        return replace(make_measured(None, (sensors or {}).get("dof", "w"), freqs, None,
                                     where, damping), **stamp)
    return replace(make_measured(sensors["x"], sensors.get("dof", "w"), freqs,
                                 np.array(shapes, dtype=float).T, where, damping), **stamp)


def time_and_label(time, label, where) -> dict:
    """The optional ``time`` (ISO 8601 text such as ``2026-03-01T12:00``, or a number in
    the user's unit) and ``label`` (text) of a measured set, checked."""
    if time is not None:
        if isinstance(time, str):
            try:
                datetime.fromisoformat(time)
            except ValueError:
                raise GfeInputError(where, "time", f"not an ISO 8601 date/time: {time!r} "
                                    "(e.g. 2026-03-01T12:00), or give a number") from None
        elif not _is_number(time) or not np.isfinite(time):
            raise GfeInputError(where, "time", f"must be ISO 8601 text or a number, got "
                                f"{time!r}")
    if label is not None and not isinstance(label, str):
        raise GfeInputError(where, "label", f"must be text, got {label!r}")
    return {"time": time, "label": label}


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def csv_rows(lines, where: str) -> list[list[str]]:
    """Rows of CSV text; a field over the csv module's limit (131 072 characters) or a
    malformed quote is one line naming the file and the row, not an internal error."""
    reader = csv.reader(lines)
    try:
        return list(reader)
    except csv.Error as exc:
        raise GfeInputError(where, f"row {reader.line_num}", f"not readable as CSV ({exc})"
                            ) from None


def csv_data_rows(text: str, where: str) -> list[list[str]]:
    """The rows of a measured CSV, its ``#`` comment lines and blank lines left out."""
    return csv_rows([ln for ln in text.splitlines()
                     if ln.strip() and not ln.lstrip().startswith("#")], where)


def csv_numbers(rows, where: str, lead: int, lead_text: str, text_column=None):
    """A measured CSV's frequencies (the header's cells after its ``lead`` label cells) and
    its sensor rows as numbers (the cell ``text_column`` kept as text): every row as many
    cells as the header; a bad cell is one line naming the row."""
    header = rows[0]
    try:
        freqs = [float(v) for v in header[lead:]]
    except ValueError:
        raise GfeInputError(where, "header", f"cells after {lead_text} must be frequencies "
                            f"in Hz, got {header[lead:]}") from None
    out = []
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise GfeInputError(where, f"row {i}", f"has {len(row)} cells, header has "
                                f"{len(header)}")
        try:
            out.append([v if j == text_column else float(v) for j, v in enumerate(row)])
        except ValueError:
            raise GfeInputError(where, f"row {i}", f"non-numeric cell in {row}") from None
    return freqs, out


def _read_csv(path: Path, dof: str) -> MeasuredModes:
    where = str(path)
    text = read_text(path, "measured")
    rows = csv_data_rows(text, where)
    if not rows:
        raise GfeInputError(where, None, "needs a header row of frequencies (and sensor rows)")
    freqs, values = csv_numbers(rows, where, 1, "the first")
    x, shapes = [v[0] for v in values], [v[1:] for v in values]
    return replace(make_measured(x, dof, freqs, np.array(shapes) if x else None, where),
                   **csv_stamp(text, where))


def csv_stamp(text: str, where: str) -> dict:
    """``time`` and ``label`` of a measured CSV from its comment lines ``# time: ...`` and
    ``# label: ...``, checked (:func:`time_and_label`)."""
    stamp = {}
    for line in text.splitlines():
        key, sep, value = line.lstrip().lstrip("#").partition(":")
        if line.lstrip().startswith("#") and sep and key.strip() in ("time", "label"):
            value = value.strip()
            stamp[key.strip()] = (float(value) if key.strip() == "time"
                                  and _looks_numeric(value) else value)
    return time_and_label(stamp.get("time"), stamp.get("label"), where)


def _looks_numeric(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _check_uff_complete(path: Path) -> None:
    """Every ASCII dataset of a universal file opens and closes with a line ``    -1``: an
    odd count means the file ends inside a dataset (cut short), which pyuff would drop
    without a word."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(80)
            if b"\0" in head:
                return  # binary universal file: pyuff checks its record lengths
            fh.seek(0)
            delimiters = sum(1 for line in fh if line.strip() == b"-1")
    except OSError as exc:
        raise GfeInputError(str(path), None, f"cannot read ({exc.strerror})") from None
    if delimiters % 2:
        raise GfeInputError(str(path), None, f"incomplete: the file ends inside a dataset "
                            f"({delimiters} '-1' delimiter lines, an even number expected); "
                            "was it cut short?")


def read_uff_sets(path: Path, plane: bool = False) -> tuple[list, dict]:
    """The datasets of a universal file (pyuff) and its node x coordinates (datasets 15 and
    2411; with ``plane`` (x, y)); a file cut short or unreadable is one line."""
    import pyuff

    _check_uff_complete(path)
    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions on malformed files
        raise GfeInputError(str(path), None, f"not a readable UFF file ({exc})") from None
    sets = [sets] if isinstance(sets, dict) else sets
    coords = {}
    for s in sets:
        if s.get("type") in (15, 2411):
            for n, x, y in zip(np.asarray(s["node_nums"]).astype(int), s["x"], s["y"]):
                coords[int(n)] = (float(x), float(y)) if plane else float(x)
    return sets, coords


def uff_modes(path, plane: bool = False) -> tuple[list, dict, list]:
    """The normal-mode datasets 55 of a universal file, its node coordinates
    (:func:`read_uff_sets`) and the first mode's node numbers; none of either is one line."""
    where = str(path)
    sets, coords = read_uff_sets(path, plane=plane)
    modes = [s for s in sets if s.get("type") == 55 and s.get("analysis_type") == 2]
    if not coords:
        raise GfeInputError(where, "dataset 15/2411", "no node coordinates found")
    if not modes:
        raise GfeInputError(where, "dataset 55", "no normal-mode data (analysis type 2) found")
    return modes, coords, [int(n) for n in np.asarray(modes[0]["node_nums"]).astype(int)]


def _read_uff(path: Path, dof: str | None) -> MeasuredModes:
    where = str(path)
    modes, coords, nodes = uff_modes(path)
    missing = [n for n in nodes if n not in coords]
    if missing:
        raise GfeInputError(where, "dataset 55", f"node {missing[0]} has no coordinates")
    has_z = any(np.any(np.asarray(m["r3"]) != 0) for m in modes)
    has_y = any(np.any(np.asarray(m["r2"]) != 0) for m in modes)
    if dof is None:
        dof = "w" if has_z or has_y else "u"
    comp = "r1" if dof == "u" else ("r3" if has_z or not has_y else "r2")
    shapes, freqs, damping = [], [], []
    for i, m in enumerate(modes):
        if [int(n) for n in np.asarray(m["node_nums"]).astype(int)] != nodes:
            raise GfeInputError(where, f"dataset 55 #{i + 1}", "nodes differ from the first mode")
        values = np.real(np.asarray(m[comp], dtype=complex)).ravel()
        if values.size != len(nodes):
            raise GfeInputError(where, f"dataset 55 #{i + 1}", f"{values.size} values for "
                                f"{len(nodes)} nodes (a damaged record)")
        shapes.append(values)
        freqs.append(float(m["freq"]))
        damping.append(float(m.get("modal_damp_vis", 0.0) or 0.0))
    # dataset 55 always has a damping field: zero everywhere means "not given"
    damping = damping if any(d > 0 for d in damping) else None
    return make_measured([coords[n] for n in nodes], dof, freqs, np.array(shapes).T, where,
                         damping)


# -------------------------------------------------------------------------------------------
# Writers (atomic: a crash leaves the old file or the new one)
# -------------------------------------------------------------------------------------------


def measured_to_dict(m: MeasuredModes) -> dict:
    """The JSON form of measured modes (``damping`` where measured, no ``sensors`` and no
    ``shape`` for a test without sensors)."""
    modes = []
    for j, f in enumerate(m.frequencies_hz):
        mode = {"frequency": float(f)}
        if m.damping is not None and np.isfinite(m.damping[j]):
            mode["damping"] = float(m.damping[j])
        if m.n_sensors:
            mode["shape"] = [float(v) for v in m.shapes[:, j]]
        modes.append(mode)
    out = {"sensors": {"x": [float(v) for v in m.x], "dof": m.dof}} if m.n_sensors else {}
    stamp = {k: v for k, v in (("time", m.time), ("label", m.label)) if v is not None}
    return {**stamp, **out, "modes": modes}


def save_measured(m: MeasuredModes, path, *, force: bool = False, protect=()) -> None:
    """Write measured modes as ``.json``, ``.csv`` or ``.uff``/``.unv`` (by extension),
    atomically, to an ordinary file (:func:`~gfe_opt.outputs.check_output_path`)."""
    path = check_output_path(path, force, protect, kind="modes")
    suffix = path.suffix.lower()
    if suffix == ".json":
        text = json.dumps(measured_to_dict(m), indent=1)
        atomic_write(path, lambda p: p.write_text(text + "\n", encoding="utf-8"),
                     replace=force)
    elif suffix == ".csv":
        def write(p):
            with open(p, "w", newline="", encoding="utf-8") as fh:
                w = csv.writer(fh)
                w.writerow(["x"] + [repr(float(f)) for f in m.frequencies_hz])
                for i, x in enumerate(m.x):
                    w.writerow([repr(float(x))] + [repr(float(v)) for v in m.shapes[i]])
        atomic_write(path, write, replace=force)
    elif suffix in (".uff", ".unv"):
        if not m.n_sensors:
            raise GfeInputError(str(path), None, "modes without shapes cannot be written as "
                                "UFF dataset 55 (it holds shapes at nodes): use .json or .csv")
        atomic_write(path, lambda p: _write_uff(m, p), replace=force)
    else:
        raise GfeInputError(str(path), None, f"unknown measured-data format {suffix!r}")


def _write_uff(m: MeasuredModes, path) -> None:
    import pyuff

    n = m.n_sensors
    nodes = np.arange(1, n + 1)
    zeros = np.zeros(n)
    sets = [pyuff.prepare_2411(node_nums=nodes, def_cs=np.zeros(n, int),
                               disp_cs=np.zeros(n, int), color=np.ones(n, int),
                               x=np.asarray(m.x, float), y=zeros, z=zeros,
                               return_full_dict=True)]
    for j, f in enumerate(m.frequencies_hz):
        comp = {"r1": zeros, "r2": zeros, "r3": zeros}
        comp["r1" if m.dof == "u" else "r3"] = m.shapes[:, j].astype(float)
        sets.append(pyuff.prepare_55(
            id1=f"gfe-opt mode {j + 1}", id2="NONE", id3="NONE", id4="NONE", id5="NONE",
            model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2,
            n_data_per_node=3, load_case=1, mode_n=j + 1, freq=float(f), modal_m=0.0,
            modal_damp_vis=float(np.nan_to_num(m.damping[j])) if m.damping is not None
            else 0.0, modal_damp_his=0.0, node_nums=nodes,
            **comp))
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")


# -------------------------------------------------------------------------------------------
# Mapping sensors onto a model
# -------------------------------------------------------------------------------------------


def on_model(measured: MeasuredModes, model) -> tuple[MeasuredModes, list[str]]:
    """The measured modes without sensors on an end whose support holds the measured DOF
    still (they read only noise, and would point the localisation at the support), and a
    note saying which were dropped."""
    from .effects.base import translation_held

    tol = 1e-6 * model.length
    held = [x for end, x in enumerate((0.0, model.length)) if translation_held(model, end)]
    drop = np.zeros(measured.n_sensors, dtype=bool)
    for x in held:
        drop |= np.abs(measured.x - x) <= tol
    if not np.any(drop):
        return measured, []
    if np.all(drop):
        raise GfeInputError(measured.source, "sensors.x", "every sensor sits on a support "
                            "that holds the structure still: nothing to compare")
    kept = replace(make_measured(measured.x[~drop], measured.dof, measured.frequencies_hz,
                                 measured.shapes[~drop], measured.source, measured.damping),
                   time=measured.time, label=measured.label)
    where = ", ".join(f"x = {x:g} m" for x in measured.x[drop])
    return kept, [f"sensor{'s' if drop.sum() > 1 else ''} at {where} on a support that holds "
                  "the structure still: left out (it reads only noise)"]


@lru_cache(maxsize=32)
def _element_to_node(n_el: int) -> sp.csr_matrix:
    """Cubic Lagrange interpolation (n_el + 1, n_el) from element middles to the nodes, the
    four nearest elements (fewer on a shorter beam); a fit asks for it at every step."""
    k = min(4, n_el)
    rows, cols, vals = [], [], []
    for i in range(n_el + 1):
        first = min(max(i - 2, 0), n_el - k)
        mid = first + 0.5 + np.arange(k)
        for a in range(k):
            others = np.delete(mid, a)
            rows.append(i)
            cols.append(first + a)
            vals.append(np.prod((i - others) / (mid[a] - others)))
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_el + 1, n_el))


def _shear_sensor_matrix(n_el, L, e, xi, shear_g) -> sp.csr_matrix:
    r"""Deflection at sensors of a Timoshenko beam: cubic Hermite in w with nodal slopes
    :math:`w' = θ + γ`, θ the section rotation and γ the shear strain at the node.

    Each element's shear strain is constant (the element of eq. 18 interpolates w and θ
    interdependently): :math:`γ_e = \frac{g}{1+g}\left(\frac{w_j - w_i}{L} -
    \frac{θ_i + θ_j}{2}\right)`.  It is superconvergent at the element's middle, so the
    nodal γ is the cubic (Lagrange) interpolation of the four nearest elements' values
    (fewer when the beam has fewer elements).  Exact at the nodes, exact for static end
    loads, and O(h³) between them on vibration modes (the inertia inside an element;
    ``tests/test_shear_sensors.py`` measures rates of 3.1-4.1 on closed-form modes: 3e-4 of
    the amplitude in mode 5 of an L/h = 6 beam at 40 elements); at g = 0 it is plain
    Hermite.  Taking θ as the slope does not converge at all at fixed κGA (off by 1.8 % in
    that mode), the element's own interdependent functions (constant γ) are O(h²) (1 %).
    """
    c = np.broadcast_to(np.asarray(shear_g, float), (n_el,))
    c = c / (1.0 + c)
    fixed, P, unit_strain = _shear_sensor_parts(n_el, float(L), e.tobytes(), xi.tobytes())
    return (fixed + (P @ sp.diags(c)) @ unit_strain).tocsr()


@lru_cache(maxsize=64)
def _shear_sensor_parts(n_el, L, e_bytes, xi_bytes):
    """The sensor matrix of :func:`_shear_sensor_matrix` is C = C₀ + P diag(c) S: C₀ plain
    Hermite with θ as the slope, P (sensors × elements) the slope shape functions times
    the element-to-node interpolation, S each element's unit shear strain.  A fit asks for
    it at every step with another c; its parts are made once per mesh and sensor set."""
    e = np.frombuffer(e_bytes, dtype=int)
    xi = np.frombuffer(xi_bytes, dtype=float)
    n_nodes, n_dof = n_el + 1, 2 * (n_el + 1)
    cols = 2 * np.arange(n_el)[:, None] + np.arange(4)
    unit_strain = sp.csr_matrix((np.tile(np.array([-1.0 / L, -0.5, 1.0 / L, -0.5]), n_el),
                                 (np.repeat(np.arange(n_el), 4), cols.ravel())),
                                shape=(n_el, n_dof))
    pick = np.arange(n_nodes)
    w = sp.csr_matrix((np.ones(n_nodes), (pick, 2 * pick)), shape=(n_nodes, n_dof))
    theta = sp.csr_matrix((np.ones(n_nodes), (pick, 2 * pick + 1)), shape=(n_nodes, n_dof))
    H = el.hermite(xi)
    fixed = (sp.diags(H[:, 0]) @ w[e] + sp.diags(L * H[:, 1]) @ theta[e]
             + sp.diags(H[:, 2]) @ w[e + 1] + sp.diags(L * H[:, 3]) @ theta[e + 1]).tocsr()
    nodes = _element_to_node(n_el)
    P = (sp.diags(L * H[:, 1]) @ nodes[e] + sp.diags(L * H[:, 3]) @ nodes[e + 1]).tocsr()
    return fixed, P, unit_strain


def observation(disc, measured) -> sp.csr_matrix:
    """:func:`sensor_matrix` of a discretisation (its Timoshenko g, if any) and a test; a
    frame's sensors read through its mesh (:func:`gfe_opt.frame_data.observation`: a joint
    spring gives a member's end its own rotation, so the matrix follows the effects)."""
    return disc.observation(measured)


def sensor_matrix(nodes, kind: str, x, dof: str, source="measured",
                  shear_g=None) -> sp.csr_matrix:
    """Observation matrix C (n_sensors, n_dof): model response at the sensors = C φ.

    A sensor between nodes is interpolated with the element shape functions (cubic Hermite
    for a beam's w, linear for a bar's u); a sensor outside the structure is an error.
    With ``shear_g`` (Timoshenko g = 12EI/(κGAL²), per element or one value) the nodal θ of
    a beam is the section rotation, not the slope: see :func:`_shear_sensor_matrix`.
    """
    nodes = np.asarray(nodes, float)
    length = nodes[-1] - nodes[0]
    expected = "w" if kind == "beam" else "u"
    if dof != expected:
        raise GfeInputError(source, "sensors.dof", f"measured dof {dof!r} does not fit a "
                            f"{kind} model (needs {expected!r})")
    x = np.asarray(x, float)
    tol = 1e-9 * length
    outside = np.flatnonzero((x < nodes[0] - tol) | (x > nodes[-1] + tol))
    if outside.size:
        i = int(outside[0])
        hint = " (millimetres instead of metres?)" if np.max(x) > 50 * length else ""
        raise GfeInputError(source, f"sensors.x[{i}]", f"{x[i]:g} m lies outside the "
                            f"structure [{nodes[0]:g}, {nodes[-1]:g}] m{hint}")
    n_el = len(nodes) - 1
    L = length / n_el
    e = np.clip(np.floor((x - nodes[0]) / L).astype(int), 0, n_el - 1)
    xi = np.clip((x - nodes[e]) / L, 0.0, 1.0)
    if kind == "beam":
        if shear_g is not None:
            return _shear_sensor_matrix(n_el, L, e, xi, shear_g)
        vals = el.hermite(xi) * np.array([1.0, L, 1.0, L])
        cols = 2 * e[:, None] + np.arange(4)
        n_dof = 2 * (n_el + 1)
    else:
        vals = el.linear(xi)
        cols = e[:, None] + np.arange(2)
        n_dof = n_el + 1
    rows = np.repeat(np.arange(x.size), vals.shape[1])
    return sp.csr_matrix((vals.ravel(), (rows, cols.ravel())), shape=(x.size, n_dof))

