"""Monitoring campaigns: one model, many measured sets (``gfe-opt batch``, ``gfe-opt trend``).

Each measured file in a folder (``.json``, ``.csv``, ``.uff``, ``.unv``; sorted by name) is
one task: the diagnosis of the model against it or, with ``add``, the update of the named
effects.  The model may be a beam, a bar or a plane frame (its sets in the frame contract:
JSON, CSV or UFF, with ``label``/``time`` as a beam's).  Each task becomes one row of a
table (README "Batch results"): the file, its ``label``/``time``, the verdict, every fitted
parameter with its standard deviation and its size in standard deviations from "no
effect", the error before and after, χ² per residual, the solver status and the seconds
taken.  A set that fails (bad file, solver failure)
becomes a row with ``status = "error"`` and its message; the batch goes on.

Where the tasks run:

* by default a local pool of processes on this machine's cores (``workers``);
* with ``scheduler`` (``tcp://HOST:8786``) the same tasks go to a Dask distributed cluster
  (``dask scheduler`` and ``dask worker tcp://HOST:8786`` started by the user).  Each task
  carries the model's and the measured file's bytes, so workers need no shared disk.

Each task runs its candidate fits one after another in one BLAS thread (the parallelism is
across sets), so a row does not depend on how many workers there are: the table is the same
bit for bit, apart from the ``seconds`` column, whatever the workers or the scheduler.

Resumable: every finished row is appended (one JSON line, flushed and synced) to a journal
``OUT.partial`` beside the output; the output itself is written atomically when the batch
ends (or is interrupted).  A rerun with the same ``out`` skips the sets already in the table
or the journal (same file name and content); a crash or Ctrl-C loses at most the sets in
flight.  The model's hash and the task are stored in each row: a rerun with another model or
other ``add`` is refused (start a new ``out``, or ``force``).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import shutil
import signal
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

from .errors import GfeInputError
from .outputs import check_output_path, create_exclusive, open_own
from .threads import one_thread_limits

MEASURED_SUFFIXES = (".json", ".csv", ".uff", ".unv")
TABLE_SUFFIXES = (".parquet", ".csv")
#: columns every row has, in this order; parameter columns follow, sorted
FIXED_COLUMNS = ("file", "sha1", "label", "time", "task", "model_sha1", "status", "error",
                 "verdict", "effect", "freq_error_before_pct", "freq_error_after_pct",
                 "mac_mean_before", "mac_mean_after", "chi2_per_residual", "solver_status",
                 "seconds")
SIGNIFICANT_SIGMAS = 3.0


# -------------------------------------------------------------------------------------------
# One set
# -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Task:
    """What every set is asked: the model (its text and name), the effects to add (empty:
    diagnose) and the noise levels."""

    model_name: str
    model_text: str
    add: tuple = ()
    freq_noise: float | None = None
    shape_noise: float | None = None
    loop: bool = False      # diagnose, add what is suggested, again (diagnosis.follow)

    @property
    def label(self) -> str:
        if self.add:
            return "update " + " + ".join(self.add)
        return "diagnose --loop" if self.loop else "diagnose"

    @property
    def model_sha1(self) -> str:
        return hashlib.sha1(self.model_text.encode()).hexdigest()


def run_set(task: Task, name: str, data: bytes) -> dict:
    """One row: ``task`` on the measured file ``name`` with contents ``data``.  Never
    raises for a bad set (the row holds the error); runs serially in one BLAS thread."""
    from . import diagnosis

    start = time.perf_counter()
    row = {"file": name, "sha1": hashlib.sha1(data).hexdigest(), "task": task.label,
           "model_sha1": task.model_sha1, "status": "ok", "error": None}
    serial, diagnosis.SERIAL_FITS = diagnosis.SERIAL_FITS, True
    try:
        with tempfile.TemporaryDirectory(prefix=f"{TEMP_PREFIX}{os.getpid()}-") as tmp, \
                one_thread_limits():
            model_path = Path(tmp) / Path(task.model_name).name
            model_path.write_text(task.model_text)
            measured_path = Path(tmp) / Path(name).name
            measured_path.write_bytes(data)
            row.update(_solve(task, model_path, measured_path, name))
    except GfeInputError as exc:
        row.update(status="error", error=str(exc).replace(str(Path(tmp)) + os.sep, ""))
    except Exception as exc:  # a solver failure or a bug: a row, and the batch goes on
        row.update(status="error", error=f"{type(exc).__name__}: {exc}")
    finally:
        diagnosis.SERIAL_FITS = serial
    row["seconds"] = round(time.perf_counter() - start, 3)
    return row


#: a set's files lie in a temporary folder named with the worker's process id, so that a
#: batch can remove the folders of workers that were killed mid-set (:func:`sweep_temp`)
TEMP_PREFIX = "gfe-batch-"


def sweep_temp(root=None) -> int:
    """Remove this user's set folders (:data:`TEMP_PREFIX` + process id) left in ``root``
    (default: the temporary directory) by processes that no longer run (a worker killed
    mid-set cannot clean up); returns how many.  Folders of running processes, of other
    users, and of any other name are left; on POSIX systems only."""
    if os.name != "posix":   # os.kill(pid, 0) would end the process elsewhere
        return 0
    root = Path(tempfile.gettempdir() if root is None else root)
    removed = 0
    for path in root.glob(f"{TEMP_PREFIX}*-*"):
        pid = path.name[len(TEMP_PREFIX):].split("-", 1)[0]
        try:
            if not pid.isdigit() or path.is_symlink() or not path.is_dir() \
                    or path.stat().st_uid != os.getuid():
                continue
            os.kill(int(pid), 0)   # raises when no such process runs
            continue
        except ProcessLookupError:
            pass
        except OSError:   # a process of another user (PermissionError), or unreadable
            continue
        shutil.rmtree(path, ignore_errors=True)
        removed += 1
    return removed


def _solve(task: Task, model_path: Path, measured_path: Path, name: str) -> dict:
    from .diagnosis import diagnose, update
    from .effects import effect_type
    from .model import load_model
    from .structure import structure

    model = load_model(model_path, frames=True)
    measured = structure(model).load_measured(measured_path)   # a bar's CSV: u
    out = {"label": measured.label, "time": None if measured.time is None
           else str(measured.time)}
    if task.add:
        outcome = update(model, measured, list(task.add), freq_noise=task.freq_noise,
                         shape_noise=task.shape_noise)
        fit, before, after = outcome.fit, outcome.before, outcome.after
        out.update(verdict="updated", effect=" + ".join(task.add))
    elif task.loop:
        from .diagnosis import follow

        done = follow(model, measured, freq_noise=task.freq_noise,
                      shape_noise=task.shape_noise)
        d = done.diagnosis
        fit = done.fit if done.fit is not None else d.reference
        before = done.first.current
        after = fit.misfit if fit is not None else d.current
        out.update(verdict=d.verdict,
                   effect=" + ".join(e.name for e in done.found) or None,
                   verdicts=" -> ".join(done.verdicts))
    else:
        d = diagnose(model, measured, freq_noise=task.freq_noise,
                     shape_noise=task.shape_noise)
        fit = d.together or (d.fits[0] if d.verdict == "effect_found" else d.reference)
        before = d.current
        after = fit.misfit if fit is not None else d.current
        out.update(verdict=d.verdict, effect=" + ".join(d.suggested) or None)
    out.update(freq_error_before_pct=before.freq_error_rms_pct,
               freq_error_after_pct=after.freq_error_rms_pct,
               mac_mean_before=before.mac_mean, mac_mean_after=after.mac_mean,
               chi2_per_residual=after.chi2_per_residual,
               solver_status=fit.status if fit is not None else None)
    if fit is not None:
        base = fit.model.with_effects([], check=False)
        seen = {}
        for effect, sigma in zip(fit.effects, fit.sigma):
            seen[effect.name] = seen.get(effect.name, 0) + 1
            prefix = effect.name + ("" if seen[effect.name] == 1 else f"#{seen[effect.name]}")
            kind = effect_type(effect.name)
            for key, value in effect.parameters.items():
                if isinstance(value, (int, float)) and not isinstance(value, bool):
                    out[f"{prefix}.{key}"] = float(value)
                    s = sigma.get(key) if isinstance(sigma, dict) else None
                    out[f"{prefix}.{key}.sigma"] = (float(s) if isinstance(s, (int, float))
                                                     and math.isfinite(s) else None)
                elif isinstance(value, str):
                    out[f"{prefix}.{key}"] = value
            size = kind.size_in_sigmas(base, effect.parameters, sigma)
            out[f"{prefix}.size_sigmas"] = float(size) if math.isfinite(size) else None
    return out


# -------------------------------------------------------------------------------------------
# Tables
# -------------------------------------------------------------------------------------------


def read_table(path) -> list[dict]:
    """Rows of a results table (Parquet or CSV) as dicts."""
    path = Path(path)
    if path.suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        try:
            return pq.read_table(path).to_pylist()
        except Exception as exc:  # pyarrow's errors are many kinds
            raise GfeInputError(str(path), None, f"not a readable Parquet table ({exc})"
                                ) from None
    from .inputs import read_text
    from .measured import csv_rows

    rows = csv_rows(read_text(path, "results").splitlines(keepends=True), str(path))
    if not rows:
        return []
    header = rows[0]  # a short row's missing cells are None, as csv.DictReader gave them
    return [{**dict.fromkeys(header), **{k: _from_csv(v) for k, v in zip(header, row)}}
            for row in rows[1:] if row]


def _from_csv(text):
    if text is None or text == "":
        return None
    try:
        return float(text)
    except ValueError:
        return text


def columns_of(rows) -> list[str]:
    """The fixed columns, then every parameter column in sorted order."""
    extra = sorted({k for row in rows for k in row} - set(FIXED_COLUMNS))
    return list(FIXED_COLUMNS) + extra


def write_table(rows, path) -> None:
    """The rows, sorted by file name, written atomically as Parquet or CSV."""
    from .outputs import atomic_write

    path = Path(path)
    rows = sorted((_plain(r) for r in rows), key=lambda r: r["file"])
    names = columns_of(rows)
    if path.suffix.lower() == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        arrays = {}
        for name in names:
            values = [row.get(name) for row in rows]
            kinds = {type(v) for v in values if v is not None}
            if kinds <= {int, float} and kinds:
                arrays[name] = pa.array([None if v is None else float(v) for v in values],
                                        pa.float64())
            else:
                arrays[name] = pa.array([None if v is None else str(v) for v in values],
                                        pa.string())
        buffer = io.BytesIO()
        pq.write_table(pa.table(arrays), buffer)
        data = buffer.getvalue()
        atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))
    else:
        text = io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(names)
        for row in rows:
            writer.writerow(["" if row.get(n) is None else
                             repr(row[n]) if isinstance(row[n], float) else row[n]
                             for n in names])
        data = text.getvalue().encode()
        atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))


def journal_path(out: Path) -> Path:
    return out.with_name(out.name + ".partial")


#: the first line of a batch journal: a file of that name without it is not ours
JOURNAL_HEADER = json.dumps({"gfe_opt_batch_journal": 1})


def _read_journal(path: Path) -> list[dict]:
    """The rows of this batch's journal (refused if the file is a link or not a journal)."""
    rows = []
    if not (path.exists() or path.is_symlink()):
        return rows
    with open_own(path, JOURNAL_HEADER) as handle:
        text = handle.read()
    for line in text.splitlines():
        try:
            row = json.loads(line)
        except ValueError:   # (JSONDecodeError among them)
            continue  # a line cut short by a crash: that set runs again
        if isinstance(row, dict) and "file" in row:
            rows.append(row)
    return rows


def _check_batch_outputs(out: Path, journal: Path, inputs) -> None:
    """Before any work: the table and its journal are ordinary paths of their own, neither
    an input (the model, a measured file of the folder) nor a link; an existing table is
    resumed or, with --force, replaced (gfe_opt.outputs)."""
    check_output_path(out, True, inputs, where="--out")
    check_output_path(journal, True, inputs, where="--out (its journal)")
    if out.is_symlink():
        raise GfeInputError("--out", str(out), "is a link: give the table's own path")
    if journal.is_symlink():
        raise GfeInputError("--out", str(journal), "(the batch's journal) is a link; remove it")


# -------------------------------------------------------------------------------------------
# The batch
# -------------------------------------------------------------------------------------------


@dataclass
class BatchResult:
    """What a batch did: rows of the whole table, how many ran now, skipped, failed."""

    rows: list
    ran: int
    skipped: int
    failed: int
    seconds: float
    out: Path
    notes: list = field(default_factory=list)


def measured_files(folder) -> list[Path]:
    """The measured files of a folder, sorted by name."""
    folder = Path(folder)
    if not folder.is_dir():
        raise GfeInputError(str(folder), None, "not a folder of measured files")
    files = sorted((p for p in folder.iterdir()
                    if p.is_file() and p.suffix.lower() in MEASURED_SUFFIXES),
                   key=lambda p: p.name)
    if not files:
        raise GfeInputError(str(folder), None, "holds no measured file (.json, .csv, .uff, "
                            ".unv)")
    return files


def run_batch(model_path, folder, out, *, add=(), scheduler=None, workers=None,
              freq_noise=None, shape_noise=None, force=False, progress=None,
              loop=False) -> BatchResult:
    """Run ``task`` on every measured file of ``folder`` (module docstring); ``loop``: each
    set's diagnosis is followed as the validation campaigns do (:func:`~gfe_opt.diagnosis.
    follow`), the row holding the final verdict, the effects the loop added and their fit."""
    from .inputs import check_input_file, read_text
    from .model import load_model

    start = time.perf_counter()
    out = Path(out)
    if out.suffix.lower() not in TABLE_SUFFIXES:
        raise GfeInputError("--out", str(out), "must end in .parquet or .csv")
    if workers is not None and workers < 1:
        raise GfeInputError("--workers", None, f"must be >= 1, got {workers}")
    check_input_file(Path(model_path), "model")
    model = load_model(model_path, frames=True)  # a bad model is one error, not a row per set
    if add and loop:
        raise GfeInputError("--loop", None, "follows a diagnosis; it cannot go with --add")
    if add:
        from .model import parse_effect

        for text in add:
            parse_effect(text, model)
    task = Task(str(model_path), read_text(Path(model_path), "model"), tuple(add),
                freq_noise, shape_noise, loop)
    files = measured_files(folder)
    sweep_temp()   # set folders of workers killed in an earlier batch
    journal = journal_path(out)
    _check_batch_outputs(out, journal, [Path(model_path), *files])
    done = []
    if force:
        if journal.exists():
            open_own(journal, JOURNAL_HEADER).close()  # only this batch's own journal goes
            journal.unlink()
    else:
        if out.exists():
            done = read_table(out)
        done += _read_journal(journal)
    if any("file" not in r or "model_sha1" not in r for r in done):
        raise GfeInputError("--out", str(out), "exists and is not a gfe-opt batch table; give "
                            "a new --out, or --force to replace it")
    other = [r for r in done if r.get("model_sha1") != task.model_sha1
             or r.get("task") != task.label]
    if other:
        raise GfeInputError("--out", str(out), f"holds results of another model or task "
                            f"({other[0].get('task')}): give a new --out, or --force to "
                            "start over")
    by_key = {(r["file"], r["sha1"]): r for r in done}
    todo = []
    for path in files:
        data = path.read_bytes()
        key = (path.name, hashlib.sha1(data).hexdigest())
        if key not in by_key:
            todo.append((path.name, data))
    names_now = {p.name for p in files}
    kept = [r for r in by_key.values() if r["file"] in names_now]
    skipped = len(kept)
    new_rows = []
    log = (open_own(journal, JOURNAL_HEADER) if journal.exists()
           else create_exclusive(journal, JOURNAL_HEADER))
    if log is None:
        raise GfeInputError("--out", str(journal), "appeared while the batch started (another "
                            "batch with this --out?); run one batch per table")
    try:
        with log:
            for row in _execute(task, todo, scheduler, workers, progress, skipped):
                row = _plain(row)
                log.write(json.dumps(row, allow_nan=False) + "\n")
                log.flush()
                os.fsync(log.fileno())
                new_rows.append(row)
    finally:
        rows = _clean(kept + new_rows)
        if rows:
            write_table(rows, out)
        if journal.is_file() and not journal.is_symlink() and (
                len(new_rows) == len(todo) and rows or not new_rows):
            journal.unlink()  # all in the table, or nothing was written
    failed = sum(1 for r in rows if r["status"] != "ok")
    return BatchResult(sorted(rows, key=lambda r: r["file"]), len(new_rows), skipped, failed,
                       time.perf_counter() - start, out)


def _plain(row: dict) -> dict:
    """A row with non-finite numbers as None (JSON, Parquet and CSV nulls) and numpy
    scalars as Python numbers."""
    out = {}
    for k, v in row.items():
        if hasattr(v, "item") and not isinstance(v, (str, bytes)):
            v = v.item()
        out[k] = None if isinstance(v, float) and not math.isfinite(v) else v
    return out


def _clean(rows):
    """Plain rows, one per file (the newest)."""
    return list({row["file"]: _plain(row) for row in rows}.values())


def _execute(task, todo, scheduler, workers, progress, skipped):
    """Rows as they finish, from a Dask cluster, a local pool or this process."""
    total = len(todo) + skipped
    report = _Progress(progress, total, skipped)
    if not todo:
        report(None)
        return
    if scheduler:
        yield from _dask(task, todo, scheduler, report)
        return
    workers = min(workers or os.cpu_count() or 1, len(todo))
    if workers == 1:
        for name, data in todo:
            row = run_set(task, name, data)
            report(row)
            yield row
        return
    import multiprocessing

    context = multiprocessing.get_context("fork")
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context,
                               initializer=_ignore_sigint)
    try:
        with one_thread_limits():   # the workers fork at the first submit and inherit it
            futures = [pool.submit(run_set, task, name, data) for name, data in todo]
        for future in as_completed(futures):
            row = future.result()
            report(row)
            yield row
    except BaseException:
        from .diagnosis import stop_pool

        stop_pool(pool)
        raise
    pool.shutdown(wait=True)


def _ignore_sigint():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _dask(task, todo, scheduler, report):
    try:
        from distributed import Client
        from distributed import as_completed as dask_completed
    except ImportError:
        raise GfeInputError("--scheduler", scheduler, "needs Dask: pip install "
                            "'gfe-opt[dask]'") from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise GfeInputError("--scheduler", scheduler, f"no Dask scheduler answers ({exc})"
                            ) from None
    try:
        futures = [client.submit(run_set, task, name, data, pure=False)
                   for name, data in todo]
        for future in dask_completed(futures):
            row = future.result()
            report(row)
            yield row
    finally:
        client.close()


class _Progress:
    """Calls ``progress(done, total, failed, seconds_left)`` after every set."""

    def __init__(self, progress, total, skipped):
        self.progress, self.total, self.done, self.failed = progress, total, skipped, 0
        self.start, self.new = time.perf_counter(), 0

    def __call__(self, row):
        if row is not None:
            self.done += 1
            self.new += 1
            self.failed += row["status"] != "ok"
        if self.progress:
            elapsed = time.perf_counter() - self.start
            left = (elapsed / self.new * (self.total - self.done)) if self.new else None
            self.progress(self.done, self.total, self.failed, left)
