"""Trends of a monitoring campaign: the table of ``gfe-opt batch`` read along time.

Sets are ordered by ``time`` when every set has one (ISO 8601 text or numbers), else by file
name (the batch's order), labelled by ``label`` where given.  For each fitted parameter the
value and one standard deviation; for each effect the first set where it becomes
significant (its size reaches 3 σ from "no effect" after sets where it did not, and stays
so in the next set: one noisy set is no onset; with ``batch`` diagnosing, the first set whose
verdict names it, and the next).  Onsets are for local effects (a crack, a mass, a section
loss): a global one such as ``material`` moves with the temperature and is drawn, not
flagged.  A local effect significant from the first set on is "present from the start":
that is the model's baseline, not an onset.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime

import numpy as np

from .batch import SIGNIFICANT_SIGMAS
from .effects import effect_type
from .errors import GfeInputError


@dataclass
class Onset:
    effect: str
    index: int          # position in the ordered sets
    file: str
    when: str           # time or label of that set (or the file name)
    value: dict         # the effect's parameters in that set

    def to_json(self) -> dict:
        return {"effect": self.effect, "index": self.index, "file": self.file,
                "when": self.when, "parameters": self.value}


@dataclass
class Trend:
    """Ordered sets, parameter series and onsets (module docstring)."""

    source: str
    axis: str                       # "time", "number" or "set"
    x: list                         # datetimes, numbers or set indices
    ticks: list                     # text per set (time, label or file)
    files: list
    parameters: dict                # "effect.key" -> (values, sigmas) arrays (NaN: none)
    errors_before: np.ndarray
    errors_after: np.ndarray
    onsets: list
    from_start: list                # effects significant from the first set on
    failed: list                    # (file, error)
    notes: list = field(default_factory=list)
    places: dict = field(default_factory=dict)  # effect -> its place on a frame (text)

    def named(self, effect: str) -> str:
        """``joint_spring#2`` -> ``joint_spring#2 (node=C, member=beam)`` on a frame."""
        return f"{effect} ({self.places[effect]})" if effect in self.places else effect

    def to_json(self) -> dict:
        return {"source": self.source, "sets": len(self.files), "axis": self.axis,
                "places": dict(self.places),
                "failed": [{"file": f, "error": e} for f, e in self.failed],
                "onsets": [o.to_json() for o in self.onsets],
                "present_from_start": list(self.from_start),
                "parameters": {k: {"first": _finite(v[0]), "last": _finite(v[-1]),
                                   "min": _finite(np.nanmin(v)) if np.any(np.isfinite(v))
                                   else None,
                                   "max": _finite(np.nanmax(v)) if np.any(np.isfinite(v))
                                   else None}
                               for k, (v, _) in self.parameters.items()}}


def _finite(v):
    return float(v) if v is not None and np.isfinite(v) else None


def _number(v) -> float:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else np.nan


def trend(rows, source="results") -> Trend:
    """The trend of a batch table's rows."""
    if not rows:
        raise GfeInputError(str(source), None, "holds no rows")
    if "file" not in rows[0] or "status" not in rows[0]:
        raise GfeInputError(str(source), None, "not a gfe-opt batch table (no file/status "
                            "columns)")
    ok = [r for r in rows if r.get("status") == "ok"]
    failed = [(r["file"], r.get("error") or "") for r in rows if r.get("status") != "ok"]
    notes = []
    if not ok:
        raise GfeInputError(str(source), None, "every set failed: nothing to draw")
    axis, x, ok = _order(ok, notes)
    ticks = [str(r.get("time") or r.get("label") or r["file"]) for r in ok]
    keys = sorted({k for r in ok for k, v in r.items()
                   if "." in k and not k.endswith((".sigma", ".size_sigmas"))
                   and isinstance(v, (int, float)) and not isinstance(v, bool)})
    parameters = {k: (np.array([_number(r.get(k)) for r in ok]),
                      np.array([_number(r.get(k + ".sigma")) for r in ok])) for k in keys}
    onsets, from_start = _onsets(ok, ticks)
    return Trend(str(source), axis, x, ticks, [r["file"] for r in ok], parameters,
                 np.array([_number(r.get("freq_error_before_pct")) for r in ok]),
                 np.array([_number(r.get("freq_error_after_pct")) for r in ok]),
                 onsets, from_start, failed, notes, _places(ok))


#: the text columns that place an effect on a frame (batch rows), in the order printed
PLACE_KEYS = ("node", "member", "direction")


def _places(rows) -> dict:
    """Each effect's place on a frame from its text columns (``joint_spring#2.node``...),
    where every set agrees ("varies" where they do not)."""
    out = {}
    for effect in sorted({e for r in rows for e in _effects_of(r)}):
        seen = {tuple((k, r.get(f"{effect}.{k}")) for k in PLACE_KEYS
                      if isinstance(r.get(f"{effect}.{k}"), str)) for r in rows}
        seen.discard(())
        if len(seen) == 1:
            out[effect] = ", ".join(f"{k}={v}" for k, v in seen.pop())
        elif seen:
            out[effect] = "place varies between sets"
    return out


def _order(rows, notes):
    times = [r.get("time") for r in rows]
    if all(t is not None for t in times):
        try:
            stamps = [datetime.fromisoformat(str(t)) for t in times]
            order = sorted(range(len(rows)), key=lambda i: stamps[i])
            return "time", [stamps[i] for i in order], [rows[i] for i in order]
        except ValueError:
            try:
                numbers = [float(t) for t in times]
            except ValueError:
                notes.append("times are neither all ISO 8601 nor all numbers: sets in file "
                             "order")
            else:
                order = sorted(range(len(rows)), key=lambda i: numbers[i])
                return "number", [numbers[i] for i in order], [rows[i] for i in order]
    return "set", list(range(1, len(rows) + 1)), list(rows)


def _effects_of(row):
    return sorted({k.removesuffix(".size_sigmas") for k in row if k.endswith(".size_sigmas")})


def _onsets(rows, ticks):
    """First set where each effect becomes significant (after sets where it was not)."""
    diagnosing = all(r.get("task") == "diagnose" for r in rows)
    effects = sorted({e for r in rows for e in _effects_of(r)})
    onsets, from_start = [], []
    for effect in effects:
        name = effect.split("#")[0]
        if not effect_type(name).local:
            continue
        if diagnosing:
            flags = [r.get("verdict") == "effect_found" and name in (r.get("effect") or "")
                     .split(" + ") for r in rows]
        else:
            flags = [(_number(r.get(effect + ".size_sigmas")) >= SIGNIFICANT_SIGMAS)
                     for r in rows]
        if not any(flags):
            continue
        if flags[0]:
            from_start.append(effect)
            continue
        lasting = [i for i in range(len(flags)) if flags[i] and
                   (i + 1 == len(flags) or flags[i + 1])]
        if not lasting:
            continue
        i = lasting[0]
        value = {k.split(".", 1)[1]: rows[i][k] for k in rows[i]
                 if k.startswith(effect + ".") and not k.endswith((".sigma", ".size_sigmas"))}
        onsets.append(Onset(effect, i, rows[i]["file"], ticks[i], value))
    return onsets, from_start
