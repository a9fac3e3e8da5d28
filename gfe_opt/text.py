"""The words gfe-opt prints: a comparison, a diagnosis and an update as text.

One function per result, used by the command line, the demo and the HTML report, so the
API, the terminal and the report say the same thing from the same result object.
"""

from __future__ import annotations

import sys

import numpy as np

from .effects import effect_type

SPARK = " ▁▂▃▄▅▆▇█"

VERDICT_WORDS = {
    "consistent": "the model agrees with the test within the noise; nothing to add",
    "effect_found": "an effect is missing",
    "unexplained": "none of the effects I know explains the difference",
}


def verdict_words(result) -> str:
    """The verdict in words; ``consistent`` says so when it holds only with an effect the
    user modelled re-estimated (:attr:`~gfe_opt.diagnosis.Diagnosis.moved`, 3 σ or more
    from its given value), with the misfit of the model as given."""
    words = VERDICT_WORDS[result.verdict]
    moved = getattr(result, "moved", None)
    if result.verdict != "consistent" or not moved:
        return words
    which = " and ".join(f"{m['effect']} (effects[{m['index']}])" for m in moved)
    return (f"the model agrees with the test within the noise once its {which} "
            f"{'is' if len(moved) == 1 else 'are'} re-estimated (as given: χ²/n "
            f"{_ratio(result.baseline.chi2_per_residual)}; see the note); nothing to add")


def withheld_words(withheld: dict) -> str:
    """``not named: a further stiffness_profile, 0.44 % of what the present effects
    explain`` (a diagnosis's ``withheld``; the text and the candidates figure)."""
    names = " with ".join(e["effect"] for e in withheld["effects"])
    return (f"not named: a further {names}, {100 * withheld['share']:.2g} % of what the "
            "present effects explain")


def remaining_words(remaining: dict) -> str:
    """``a difference remains after it: χ²/n 8.2, frequency error 0.120 %`` (a
    diagnosis's ``remaining``; the text and the candidates figure's verdict)."""
    return (f"a difference remains after it: χ²/n {_ratio(remaining['chi2_per_residual'])}"
            f", frequency error {remaining['freq_error_rms_pct']:.3f} %")


def misfit_line(m, label: str = "") -> str:
    """``frequency error 5.591 % rms, mean MAC 0.9919, χ²/n 663.6``."""
    head = f"{label}: " if label else ""
    mac = "" if m.mac_mean is None else f", mean MAC {m.mac_mean:.4f}"
    return (f"{head}frequency error {m.freq_error_rms_pct:.3f} % rms{mac}, χ²/n "
            f"{_ratio(m.chi2_per_residual)}")


def _mac(value, width: int, digits: int) -> str:
    """A MAC in a table column; '—' where there is none (paired by frequency)."""
    return f"{'—':>{width}}" if value is None else f"{value:{width}.{digits}f}"


def _ratio(value: float) -> str:
    if not np.isfinite(value):
        return "inf"
    return f"{value:.3g}" if value < 1000 else f"{value:.0f}"


#: the widest sparkline (one terminal line with its frame and indent)
SPARK_WIDTH = 72


def sparkline(values, width: int = SPARK_WIDTH) -> str:
    """Values in [0, 1] as block characters, at most ``width`` of them: more values share a
    character, which shows their largest (a peak is never averaged away)."""
    v = np.asarray(values, dtype=float)
    if v.size > width:
        edges = np.linspace(0, v.size, width + 1).round().astype(int)
        v = np.array([v[a:b].max() for a, b in zip(edges[:-1], edges[1:])])
    return "".join(SPARK[int(round(x * (len(SPARK) - 1)))] for x in v)


def format_comparison(result, length: float) -> str:
    """Paired modes and where along the structure the model fails."""
    lines = [f"{'mode':>4}  {'f_test [Hz]':>12}  {'f_model [Hz]':>12}  {'Δf %':>8}  {'MAC':>6}"]
    for p in result.pairs:
        lines.append(f"{p.test_mode:>4}  {p.test_hz:12.2f}  {p.model_hz:12.2f}  "
                     f"{p.error_pct:+8.2f}  {_mac(p.mac, 6, 3)}")
    for t in result.unpaired_test_modes:
        lines.append(f"{t + 1:>4}  (no model mode with MAC >= threshold)")
    mac = "" if result.mac_mean is None else f", mean MAC {result.mac_mean:.3f}"
    lines.append(f"frequency error (rms) {result.freq_error_rms_pct:.2f} %{mac}")
    places = result.failure_places()
    lines.append("")
    if result.residual is None:
        lines.extend(f"note: {n}" for n in result.notes)
        return "\n".join(lines)
    if not places:
        lines.append("no residual force: the model reproduces the measured shapes")
        lines.extend(f"note: {n}" for n in result.notes)
        return "\n".join(lines)
    spark = sparkline(result.residual / result.residual.max())
    lines.append("residual force along the structure (left end -> right end):")
    lines.append(f"  |{spark}|")
    x0, _ = places[0]
    lines.append(f"the model fails most near x = {x0:.3f} m ({100 * x0 / length:.0f} % of the "
                 "length)")
    for x, rel in places[1:]:
        lines.append(f"  also near x = {x:.3f} m ({100 * x / length:.0f} %), "
                     f"{100 * rel:.0f} % of the largest residual")
    lines.extend(f"note: {n}" for n in result.notes)
    return "\n".join(lines)


def format_frame_comparison(result) -> str:
    """Paired modes of a frame and the sensors where the measured shapes differ most."""
    from .frame_data import sensor_label

    lines = [f"{'mode':>4}  {'f_test [Hz]':>12}  {'f_model [Hz]':>12}  {'Δf %':>8}  {'MAC':>6}"]
    for p in result.pairs:
        lines.append(f"{p.test_mode:>4}  {p.test_hz:12.2f}  {p.model_hz:12.2f}  "
                     f"{p.error_pct:+8.2f}  {_mac(p.mac, 6, 3)}")
    mac = "" if result.mac_mean is None else f", mean MAC {result.mac_mean:.3f}"
    lines.append(f"frequency error (rms) {result.freq_error_rms_pct:.2f} %{mac}")
    places = result.failure_places()
    if result.residual is not None and not places:
        lines += ["", "the model reproduces the measured shapes (residual at rounding level)"]
    if places:
        top = float(result.residual.max())
        lines += ["", "the shapes differ most at (rms over the pairs of the shape residual, "
                  "in each mode's largest amplitude):"]
        lines += [f"  {sensor_label(s)}: {rel * top:.2g} ({100 * rel:.0f} % of the largest)"
                  for s, rel in places]
    lines.extend(f"note: {n}" for n in result.notes)
    return "\n".join(lines)


def format_diagnosis(result, model) -> str:
    """The ranking, the verdict in words, the effect found ± its uncertainty, what the
    generic-element update shows and the noise the data imply."""
    now = result.current
    lines = [misfit_line(result.baseline, "the model as it stands")]
    if result.reference is not None:
        lines.append(misfit_line(now, "its effects re-estimated"))
    if result.fits:
        lines += ["", "candidates, best first by χ²/s² + p ln n (significant: Δχ² exceeds "
                  "'needed' and the effect lies 3 σ from nothing):",
                  f"{'rank':>4}  {'effect':<18} {'χ²/n':>8} {'f err %':>8} {'MAC':>7} "
                  f"{'Δχ²':>9} {'needed':>8} {'size σ':>7}  significant"]
    elif not result.failed:
        lines += ["", "no candidate effect could be fitted (see the notes)"]
    for i, f in enumerate(result.fits, 1):
        lines.append(f"{i:>4}  {f.name:<18} {_ratio(f.misfit.chi2_per_residual):>8} "
                     f"{f.misfit.freq_error_rms_pct:8.3f} {_mac(f.misfit.mac_mean, 7, 4)} "
                     f"{_ratio(f.gain):>9} {_ratio(f.threshold):>8} "
                     f"{min(f.size_sigmas, 999):7.1f}  "
                     f"{'no' if not f.significant else 'in the pair' if f.leads_pair else 'yes'}")
    if result.failed:
        lines.append("failed fits, not ranked: " + "; ".join(
            f"{f.name} ({'; '.join(f.notes)})" for f in result.failed))
    lines += ["", "verdict: " + verdict_words(result)]
    best = result.best
    if best is not None:
        lines.append(f"  {best.describe()}")
        lines.append(f"  frequency error {now.freq_error_rms_pct:.3f} % -> "
                     f"{best.misfit.freq_error_rms_pct:.3f} %, χ²/n "
                     f"{_ratio(now.chi2_per_residual)} -> "
                     f"{_ratio(best.misfit.chi2_per_residual)}")
        pair = result.together
        if pair is not None:
            held = len(model.effects)
            lines.append("  together, fitted with each other (what update --add gives; the "
                         "figures show these):")
            lines += [f"    {e.name}: "
                      f"{effect_type(e.name).describe(e.parameters, s, pair.bound_of(i))}"
                      for i, (e, s) in enumerate(zip(pair.effects, pair.sigma)) if i >= held]
            lines.append(f"  together: frequency error {now.freq_error_rms_pct:.3f} % -> "
                         f"{pair.misfit.freq_error_rms_pct:.3f} %, χ²/n "
                         f"{_ratio(now.chi2_per_residual)} -> "
                         f"{_ratio(pair.misfit.chi2_per_residual)}")
        remaining = getattr(result, "remaining", None)
        if remaining is not None:
            where = (" where: " + ", ".join(_place(x) for x in remaining["where"])
                     if remaining["where"] else "")
            lines.append(f"  {remaining_words(remaining)}{where} — diagnose again "
                         "after adding it")
        adds = " ".join(f"--add {a}" for a in result.add_arguments())
        them = "it" if len(result.suggested) == 1 else "them"
        swap = getattr(result, "replace", None)
        if swap is not None:
            lines.append(f"  in place of the present {swap['effect']} (effects[{swap['index']}]"
                         f"): gfe-opt update MODEL MEASURED --drop {swap['index']} {adds}")
        else:
            lines.append(f"  add {them}: gfe-opt update MODEL MEASURED {adds}")
    elif result.verdict == "unexplained":
        where = ("where the model fails: " + ", ".join(_place(x) for x, _ in
                                                       result.localisation)
                 if result.localisation else "where it fails is unknown without mode shapes")
        lines.append(f"  χ²/n {_ratio(now.chi2_per_residual)} (1 is at the noise); {where}")
        withheld = getattr(result, "withheld", None)
        if withheld is not None:
            lines.append(f"  {withheld_words(withheld)} (as likely their own form; see the "
                         "note)")
    words = list(result.realisation)
    if words and words[0].startswith("the generic-element update"):
        lines += words[:1] + [f"  {w}" for w in words[1:]]
    elif words:
        read = ("the elements' EA" if getattr(getattr(result, "profile_band", None),
                                               "quantity", "EI") == "EA" else "nodal k_i")
        lines.append(f"the generic-element update ({read}, no physical effect assumed):")
        lines += [f"  - {word}" for word in words]
    lines += [f"note: {n}" for n in result.notes]
    lines.append(f"({result.seconds:.1f} s)")
    return "\n".join(lines)


def _place(where) -> str:
    """A place where a model fails: ``x = 0.190 m`` on a beam, a sensor on a frame."""
    if isinstance(where, dict):
        from .frame_data import sensor_label

        return sensor_label(where)
    return f"x = {where:.3f} m"


def format_update(outcome) -> str:
    """Before, every effect of the updated model with its uncertainty, after."""
    lines = [misfit_line(outcome.before, "before")]
    for i, (e, sigma) in enumerate(zip(outcome.fit.effects, outcome.fit.sigma)):
        mark = "added" if i in outcome.added else "re-estimated"
        words = effect_type(e.name).describe(e.parameters, sigma, outcome.fit.bound_of(i))
        lines.append(f"  {e.name} ({mark}): {words}")
    lines.append(misfit_line(outcome.after, "after"))
    lines += [f"note: {n}" for n in outcome.notes]
    return "\n".join(lines)


def format_identification(result) -> str:
    """The modes identified from FRFs, with damping and how stable each was."""
    ident = result
    lines = [f"{ident.frfs.frf.shape[0]} FRFs ({ident.frfs.form}) at x = "
             + ", ".join(f"{x:.4g}" for x in ident.frfs.x) + " m; band "
             f"{ident.band[0]:.5g} to {ident.band[1]:.5g} Hz, LSCF orders up to {ident.order}",
             f"{'mode':>4}  {'f [Hz]':>10}  {'ζ [%]':>7}  {'stable in':>9}"]
    for j, (f, z) in enumerate(zip(ident.measured.frequencies_hz, ident.damping)):
        share = ident.persistence[j]
        lines.append(f"{j + 1:>4}  {f:10.4f}  {100 * z:7.3f}  {100 * share:8.0f}%")
    lines.append(f"FRF reconstruction error {100 * ident.fit_error:.2g} % (rms over the band, "
                 "relative to the rms FRF)")
    lines += [f"note: {n}" for n in ident.notes]
    return "\n".join(lines)


def format_parameters(params: dict) -> str:
    """``position=0.19, depth_ratio=0.5`` (no uncertainty)."""
    def one(v):
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(f"{x:.4g}" for x in v) + "]"
        return f"{v:.4g}" if isinstance(v, float) else str(v)

    return ", ".join(f"{k}={one(v)}" for k, v in params.items())


def terminal_progress(enabled: bool = True):
    """A one-line progress report on stderr when it is a terminal (else None)."""
    if not (enabled and sys.stderr.isatty()):
        return None

    width = [28]   # the longest line yet: a shorter one is padded over it

    def report(done, total, name):
        end = "\n" if done == total else ""
        line = f"fitting: {done}/{total} {name}"
        width[0] = max(width[0], len(line))
        print(f"\r{line:<{width[0]}}", end=end, file=sys.stderr, flush=True)

    return report


def batch_progress():
    """A one-line batch progress report on stderr when it is a terminal (else None)."""
    if not sys.stderr.isatty():
        return None

    def report(done, total, failed, left):
        eta = "" if left is None else f", about {_duration(left)} left"
        end = "\n" if done == total else ""
        print(f"\rbatch: {done}/{total} sets, {failed} failed{eta}    ", end=end,
              file=sys.stderr, flush=True)

    return report


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


def format_batch(result) -> str:
    """What a batch did, and where the table is."""
    lines = [f"{len(result.rows)} sets in {result.out}: {result.ran} run now, "
             f"{result.skipped} done before, {result.failed} failed "
             f"({_duration(result.seconds)})"]
    verdicts = {}
    for row in result.rows:
        if row["status"] == "ok":
            verdicts[row.get("verdict")] = verdicts.get(row.get("verdict"), 0) + 1
    if verdicts:
        lines.append("verdicts: " + ", ".join(f"{k} {v}" for k, v in sorted(verdicts.items())))
    for row in [r for r in result.rows if r["status"] != "ok"][:10]:
        lines.append(f"failed: {row['file']}: {row['error']}")
    if result.failed > 10:
        lines.append(f"... and {result.failed - 10} more failed sets (status = error in "
                     "the table)")
    lines += result.notes
    lines.append(f"next: gfe-opt trend {result.out} --plot DIR")
    return "\n".join(lines)


def format_trend(trend) -> str:
    """Onsets, parameter ranges and failures of a campaign."""
    n = len(trend.files)
    lines = [f"{n} sets ({len(trend.failed)} failed) ordered by "
             f"{'time' if trend.axis in ('time', 'number') else 'file name'}: "
             f"{trend.ticks[0]} .. {trend.ticks[-1]}"]
    for onset in trend.onsets:
        params = ", ".join(f"{k} = {v:.4g}" for k, v in onset.value.items()
                           if isinstance(v, (int, float)))
        lines.append(f"{trend.named(onset.effect)} becomes significant at set "
                     f"{onset.index + 1} "
                     f"({onset.file}, {onset.when}){': ' + params if params else ''}")
    if not trend.onsets:
        lines.append("no effect becomes significant during the campaign")
    if trend.from_start:
        lines.append("significant from the first set on: " + ", ".join(
            map(trend.named, trend.from_start)))
    if trend.parameters:
        lines += ["", f"{'parameter':<28} {'first':>12} {'last':>12} {'min':>12} {'max':>12}"]
        for key, (values, _) in trend.parameters.items():
            finite = values[np.isfinite(values)]
            if not finite.size:
                continue
            cells = [values[0], values[-1], finite.min(), finite.max()]
            lines.append(f"{key:<28} " + " ".join(f"{c:>12.5g}" for c in cells))
    for file, error in trend.failed[:10]:
        lines.append(f"failed: {file}: {error}")
    lines += [f"note: {n}" for n in trend.notes]
    return "\n".join(lines)
