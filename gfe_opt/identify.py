r"""From measured FRFs to modes: ``gfe-opt identify``.

The poles come from sdypy-EMA's LSCF (least-squares complex frequency) estimator at model
orders up to ``order`` (default 60), the mode shapes from its LSFD (least-squares frequency
domain) fit of the modal constants, as the library's authors use them; gfe-opt only chooses
the poles, without a person at a stabilisation chart:

1. sdypy-EMA's stabilisation test marks a pole stable when its frequency moves by less than
   0.1 % and its damping by less than 5 % from one order to the next;
2. stable poles with 0 < ζ < 20 % are clustered in frequency (poles within 0.5 % of each
   other are one cluster);
3. a cluster present at a fifth of the orders or more is a physical mode (spurious poles come
   and go with the order); with ``modes`` given, the most persistent clusters are kept;
4. the modal constants :math:`A_{jn}` (LSFD, with residual terms) give the shapes: for a
   fixed reference, :math:`A_{jn} = φ_{jn} φ_{ref,n}`, rotated to real by the phase of the
   largest entry (the normal mode of a lightly damped structure).

Inputs (README "FRFs"): UFF dataset 58 (frequency response functions, one per measurement
point; a roving hammer or a roving accelerometer, the point where the FRFs differ; node
coordinates from dataset 15 or 2411 in the same files), and CSV (a header row of positions in
metres after a first cell, then one row per frequency: the frequency in Hz and one complex
value per point, written ``a+bj``, or two columns per point, real then imaginary, the
position repeated in the header).
"""

from __future__ import annotations

import contextlib
import csv
import io
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import GfeInputError, GfeSolverError
from .inputs import check_input_file, read_text
from .measured import MeasuredModes, make_measured
from .names import FRF_FORMS  # noqa: F401 (part of this module's interface)

#: ordinate data types of UFF dataset 58 (displacement, velocity, acceleration responses)
UFF_FRF_FORMS = {8: "receptance", 11: "mobility", 12: "accelerance"}
STABLE_FREQUENCY = 0.001
STABLE_DAMPING = 0.05
CLUSTER_WIDTH = 0.005
MIN_PERSISTENCE = 0.2


@dataclass
class FRFs:
    """Measured FRFs: ``frf`` (n_points, n_freq) complex, ``freq`` [Hz], point positions
    ``x`` [m], the FRF form and the index of the driving point (or None)."""

    x: np.ndarray
    freq: np.ndarray
    frf: np.ndarray
    form: str
    driving_point: int | None
    source: str


@dataclass
class Identification:
    """The modes identified and what the stabilisation chart shows."""

    measured: MeasuredModes
    damping: np.ndarray
    frfs: FRFs
    band: tuple
    order: int
    stable: list          # per order: stable pole frequencies [Hz]
    clusters: list        # (frequency, persistence) of every cluster
    persistence: np.ndarray   # per mode kept: share of the orders where it is stable
    fit_error: float      # rms |H_fit - H| / rms |H| over the band
    notes: list

    def to_json(self) -> dict:
        """The measured-modes JSON contract (``damping`` per mode)."""
        from .measured import measured_to_dict

        return measured_to_dict(self.measured)


# -------------------------------------------------------------------------------------------
# Reading FRFs
# -------------------------------------------------------------------------------------------


def load_frfs(paths, form: str | None = None) -> FRFs:
    """FRFs from UFF (dataset 58) or CSV files (module docstring); several files are one
    set (their points together)."""
    paths = [Path(p) for p in paths]
    if not paths:
        raise GfeInputError("identify", None, "no FRF file given")
    parts = []
    for p in paths:
        check_input_file(p, "measured")
        suffix = p.suffix.lower()
        if suffix in (".uff", ".unv"):
            parts.append(_read_uff58(p))
        elif suffix == ".csv":
            parts.append(_read_csv(p, form))
        else:
            raise GfeInputError(str(p), None, f"unknown FRF format {suffix!r} (use .uff, "
                                ".unv or .csv)")
    freq = parts[0].freq
    for part in parts[1:]:
        if part.freq.shape != freq.shape or not np.allclose(part.freq, freq, rtol=1e-9):
            raise GfeInputError(part.source, "frequency", "frequency lines differ from "
                                f"those of {parts[0].source}")
    forms = {part.form for part in parts}
    if len(forms) > 1:
        raise GfeInputError("identify", None, f"the files hold different FRF forms {forms}")
    x = np.concatenate([part.x for part in parts])
    frf = np.concatenate([part.frf for part in parts])
    order = np.argsort(x, kind="stable")
    driving = [part.driving_point is not None for part in parts]
    driving_point = None
    if any(driving):
        offset = 0
        for part in parts:
            if part.driving_point is not None:
                driving_point = int(np.flatnonzero(order == offset + part.driving_point)[0])
                break
            offset += part.x.size
    if np.unique(x).size != x.size:
        raise GfeInputError("identify", "points", "two FRFs at one position")
    return FRFs(x[order], freq, frf[order], forms.pop(), driving_point,
                ", ".join(p.source for p in parts))


def _read_uff58(path: Path) -> FRFs:
    from .measured import read_uff_sets

    where = str(path)
    sets, coords = read_uff_sets(path)
    frfs = [s for s in sets if s.get("type") == 58 and s.get("func_type") == 4]
    if not frfs:
        raise GfeInputError(where, "dataset 58", "no frequency response function "
                            "(function type 4) found")
    rsp = [int(s["rsp_node"]) for s in frfs]
    ref = [int(s["ref_node"]) for s in frfs]
    if len(set(rsp)) == 1 and len(frfs) > 1:
        points = ref  # roving hammer: the excitation moves
    elif len(set(ref)) == 1:
        points = rsp  # roving accelerometer (or a single FRF)
    else:
        raise GfeInputError(where, "dataset 58", "neither the response nor the reference "
                            "node is the same in every FRF: not a roving-hammer or "
                            "roving-accelerometer test")
    missing = [n for n in points if n not in coords]
    if missing:
        raise GfeInputError(where, "dataset 58", f"node {missing[0]} has no coordinates "
                            "(dataset 15 or 2411 in the same file)")
    freq = np.asarray(frfs[0]["x"], float)
    frf = []
    for i, s in enumerate(frfs):
        f = np.asarray(s["x"], float)
        if f.shape != freq.shape or not np.allclose(f, freq, rtol=1e-9):
            raise GfeInputError(where, f"dataset 58 #{i + 1}", "frequency lines differ from "
                                "the first FRF's")
        frf.append(np.asarray(s["data"], complex))
    kinds = {int(s.get("ordinate_spec_data_type", 12)) for s in frfs}
    form = UFF_FRF_FORMS.get(kinds.pop(), "accelerance") if len(kinds) == 1 else None
    if form is None:
        raise GfeInputError(where, "dataset 58", "FRFs of different kinds in one set")
    driving = [i for i, s in enumerate(frfs) if int(s["rsp_node"]) == int(s["ref_node"])]
    x = np.array([coords[n] for n in points])
    return FRFs(x, freq, np.array(frf), form, driving[0] if driving else None, where)


def _read_csv(path: Path, form: str | None) -> FRFs:
    where = str(path)
    rows = [r for r in csv.reader(line for line in read_text(path, "measured").splitlines()
                                  if line.strip() and not line.lstrip().startswith("#"))]
    if len(rows) < 3:
        raise GfeInputError(where, None, "needs a header row of positions and frequency rows")
    try:
        positions = [float(v) for v in rows[0][1:]]
    except ValueError:
        raise GfeInputError(where, "header", "cells after the first must be positions in "
                            f"metres, got {rows[0][1:]}") from None
    pairs = (len(positions) % 2 == 0 and len(positions) > 0
             and positions[0::2] == positions[1::2])
    x = np.array(positions[0::2] if pairs else positions)
    freq, values = [], []
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(rows[0]):
            raise GfeInputError(where, f"row {i}", f"has {len(row)} cells, the header has "
                                f"{len(rows[0])}")
        try:
            freq.append(float(row[0]))
            if pairs:
                re, im = np.array(row[1::2], float), np.array(row[2::2], float)
                values.append(re + 1j * im)
            else:
                values.append([complex(v.replace(" ", "").replace("i", "j")) for v in row[1:]])
        except ValueError:
            raise GfeInputError(where, f"row {i}", f"a cell is not a number: {row}") from None
    frf = np.array(values).T
    if not np.all(np.isfinite(frf)) or not np.all(np.isfinite(freq)):
        raise GfeInputError(where, None, "contains NaN or infinite values")
    if np.any(np.diff(freq) <= 0):
        raise GfeInputError(where, "frequency", "frequencies must increase")
    return FRFs(x, np.array(freq), frf, form or "accelerance", None, where)


# -------------------------------------------------------------------------------------------
# Identification
# -------------------------------------------------------------------------------------------


def identify(frfs: FRFs, *, band=None, modes: int | None = None, order: int = 60,
             dof: str = "w") -> Identification:
    """Modes of measured FRFs (module docstring).  ``band`` (lower, upper) [Hz] defaults to
    the measured range without its first and last 2 %; ``modes`` limits how many."""
    try:
        from sdypy import EMA
        from sdypy.EMA import stabilization
    except ImportError:
        raise GfeInputError("identify", None, "needs sdypy-EMA: pip install "
                            "'gfe-opt[identify]'") from None
    freq = frfs.freq
    span = freq[-1] - freq[0]
    lower, upper = band if band else (max(freq[0] + 0.02 * span, freq[1]),
                                      freq[-1] - 0.02 * span)
    if not freq[0] <= lower < upper <= freq[-1]:
        raise GfeInputError("--band", f"{lower:g}:{upper:g}", f"must lie within the "
                            f"measured {freq[0]:g} to {freq[-1]:g} Hz")
    if frfs.frf.shape[0] < 1 or np.sum((freq >= lower) & (freq <= upper)) < 4 * order:
        raise GfeInputError("--band", None, "too few frequency lines in the band for model "
                            f"order {order}")
    notes = []
    frf, freq = _on_fft_grid(frfs.frf, freq, notes)
    quiet = io.StringIO()
    with warnings.catch_warnings(), contextlib.redirect_stderr(quiet):
        warnings.simplefilter("ignore")
        try:
            model = EMA.Model(frf=frf, freq=freq, lower=lower, upper=upper,
                              pol_order_high=order, frf_form=frfs.form,
                              driving_point=frfs.driving_point)
            model.get_poles(method="lscf", show_progress=False)
            fn, xi, test_fn, test_xi = stabilization._stabilization(
                model.all_poles, model.n_bands * order, err_fn=STABLE_FREQUENCY,
                err_xi=STABLE_DAMPING)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise GfeSolverError(f"LSCF failed: {exc}") from None
    stable_mask = (test_fn > 0) & (test_xi > 0) & (xi > 0) & (xi < 0.2) & \
        (fn >= lower) & (fn <= upper)
    stable = [fn[:, k][stable_mask[:, k]] for k in range(fn.shape[1])]
    clusters = _clusters(stable, fn.shape[1])
    members = _clusters(stable, fn.shape[1], members=True)
    keep = [c for c in clusters if c[1] >= MIN_PERSISTENCE]
    if modes is not None:
        if len(clusters) < modes:
            notes.append(f"{modes} modes asked for, {len(clusters)} found stable in the band")
        keep = sorted(sorted(clusters, key=lambda c: -c[1])[:modes])
    if not keep:
        raise GfeSolverError("no stable pole in the band: widen --band, or check the FRFs")
    chosen = [_typical_pole(members[clusters.index(c)], fn, xi, stable_mask) for c in keep]
    model.pole_ind = np.array([(k, _pole_index(model.all_poles[k], fn[r, k], xi[r, k]))
                               for r, k in chosen], dtype=int)
    model.nat_freq = np.array([fn[r, k] for r, k in chosen])
    model.nat_xi = np.array([xi[r, k] for r, k in chosen])
    with warnings.catch_warnings(), contextlib.redirect_stderr(quiet):
        warnings.simplefilter("ignore")
        try:
            H, constants = model.get_constants(whose_poles="own")
        except (ValueError, IndexError, np.linalg.LinAlgError) as exc:
            raise GfeSolverError(f"LSFD failed: {exc}") from None
    nat_freq = np.asarray(model.nat_freq, float)
    damping = np.asarray(model.nat_xi, float)
    if np.any(~np.isfinite(nat_freq)) or np.any(nat_freq <= 0):
        raise GfeSolverError("LSFD returned no usable poles: widen --band or lower --order")
    shapes = _real_shapes(np.asarray(constants))
    measured = make_measured(frfs.x, dof, nat_freq, shapes, frfs.source,
                             np.clip(damping, 0.0, 0.999))
    persistence = np.array([max((c[1] for c in keep if abs(c[0] / f - 1) < 0.02),
                                default=0.0) for f in measured.frequencies_hz])
    # sdypy-EMA keeps the lines up to the band's upper end; the fit holds inside the band
    used = np.asarray(model.freq, float)
    inside = (used >= lower) & (used <= upper)
    fitted, measured_frf = np.asarray(H)[:, inside], np.asarray(model.frf)[:, inside]
    error = float(np.sqrt(np.mean(np.abs(fitted - measured_frf) ** 2))
                  / np.sqrt(np.mean(np.abs(measured_frf) ** 2)))
    return Identification(measured, measured.damping, frfs, (lower, upper), order, stable,
                          clusters, persistence, error, notes)


def _on_fft_grid(frf, freq, notes):
    """FRFs on lines k·Δf.  sdypy-EMA's LSCF works in the discrete-time domain of an FFT
    and pads lines below the first from 0 in steps of Δf: lines starting off that grid (a
    zoom band from 20 Hz in steps of 1.42 Hz) or unevenly spaced shift every pole (0.2 % at
    the first mode in tests/test_identify.py).  Such FRFs are resampled (cubic splines on the
    real and imaginary parts) onto the grid of their median spacing, with a note."""
    from scipy.interpolate import CubicSpline

    steps = np.diff(freq)
    df = float(np.median(steps))
    uniform = np.all(np.abs(steps / df - 1) < 1e-6)
    aligned = abs(freq[0] / df - round(freq[0] / df)) < 1e-6
    if uniform and aligned:
        return frf, freq
    grid = np.arange(np.ceil(freq[0] / df - 1e-9), np.floor(freq[-1] / df + 1e-9) + 1) * df
    spline = CubicSpline(freq, frf, axis=1)
    why = "unevenly spaced" if not uniform else f"starting at {freq[0]:g} Hz, off the grid k·Δf"
    notes.append(f"frequency lines {why}: FRFs resampled onto {grid.size} lines k·{df:.4g} Hz "
                 "(sdypy-EMA's LSCF assumes FFT lines)")
    return spline(grid), grid


def _clusters(stable, n_orders, members=False):
    """Stable pole frequencies of all orders grouped (sorted, a new group where the gap to
    the previous exceeds CLUSTER_WIDTH relative); each group's median and the share of the
    orders in which it appears (or, with ``members``, each group's (frequency, order))."""
    points = sorted((f, k) for k, fs in enumerate(stable) for f in fs)
    groups, current = [], []
    for f, k in points:
        if current and f > current[-1][0] * (1 + CLUSTER_WIDTH):
            groups.append(current)
            current = []
        current.append((f, k))
    if current:
        groups.append(current)
    if members:
        return groups
    return [(float(np.median([f for f, _ in g])), len({k for _, k in g}) / n_orders)
            for g in groups]


def _typical_pole(group, fn, xi, stable_mask):
    """The stable pole of a cluster nearest its median frequency and damping (in units of
    the stability tolerances), as (row, order) of ``fn``.  Taking the pole nearest in
    frequency alone (sdypy-EMA's select_closest_poles) can take a spurious pole of a
    near-noiseless fit whose damping is off by 90 %."""
    candidates = []
    for f, k in group:
        rows = np.flatnonzero(stable_mask[:, k] & (fn[:, k] == f))
        candidates += [(int(r), int(k)) for r in rows]
    f_med = np.median([fn[r, k] for r, k in candidates])
    xi_med = np.median([xi[r, k] for r, k in candidates])
    return min(candidates, key=lambda rk: abs(fn[rk] / f_med - 1) / STABLE_FREQUENCY
               + abs(xi[rk] / xi_med - 1) / STABLE_DAMPING)


def _pole_index(poles, f, zeta):
    """Index, among one order's poles, of the pole with frequency f and damping ζ."""
    w = 2 * np.pi * f
    target = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    return int(np.argmin(np.abs(np.asarray(poles) - target)))


def _real_shapes(constants) -> np.ndarray:
    """Complex modal constants (n_points, n_modes) as real shapes: each column rotated by
    the phase of its largest entry and its real part kept."""
    from .modal import peak_rows

    A = np.atleast_2d(constants)
    peak = peak_rows(A)
    phase = np.angle(A[peak, np.arange(A.shape[1])])
    return np.real(A * np.exp(-1j * phase)[None, :])
