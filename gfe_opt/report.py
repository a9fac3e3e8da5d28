"""Figures for each command and a self-contained HTML report (figures embedded as PNG)."""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

from . import plots
from .effects import effect_type
from .names import COMPARE_FIGURES, DIAGNOSIS_FIGURES  # noqa: F401 (the figures a command may write)
from .outputs import atomic_write


def compare_figures(result, model) -> dict:
    """MAC matrix, paired frequencies and the localisation of a comparison."""
    pairs = [(p.test_mode - 1, p.model_mode - 1) for p in result.pairs]
    if result.mac_matrix is None:  # frequency-only test: no MAC, no localisation
        return {"frequencies.png": plots.paired_frequencies(result.pairs)}
    return {
        "mac.png": plots.mac_matrix(result.mac_matrix, pairs),
        "frequencies.png": plots.paired_frequencies(result.pairs),
        "localisation.png": plots.localisation(result.sensor_x, result.residual, result.comac,
                                               model.length, model.supports,
                                               places=result.failure_places()),
    }


def findings(diagnosis, model) -> list:
    """The effects a diagnosis found, as (effect type, model, parameters, σ, parameters on a
    bound) for the structure sketch: the suggested pair when there is one, else the effect
    found."""
    fit = diagnosis.together or diagnosis.best
    if fit is None:
        return []
    held = len(model.effects)
    return [(effect_type(e.name), model, e.parameters, s, fit.bound_of(i))
            for i, (e, s) in enumerate(zip(fit.effects, fit.sigma)) if i >= held]


def elsewhere(diagnosis) -> list:
    """Where on a beam or bar an effect fits as well as the one found (its mirror place,
    another effect's place: :attr:`~gfe_opt.diagnosis.Diagnosis.drawn_alternatives`), as
    (x, effect name)."""
    out = []
    for e in diagnosis.drawn_alternatives:
        x = effect_type(e.name).position(e.parameters)
        if isinstance(x, (int, float)):
            out.append((float(x), e.name))
    return out


def deciding(diagnosis) -> list:
    """Where on a beam or bar one more sensor would tell the finding from what fits as well
    (:attr:`~gfe_opt.diagnosis.Diagnosis.deciding_sensors`), as x."""
    return [float(s["x"]) for s in diagnosis.deciding_sensors if "x" in s]


def verdict_title(diagnosis) -> str:
    """``crack missing`` (with what the text says remains after it, ``crack missing; a
    difference remains after it: χ²/n 8.2, ...``), else the verdict in the words the text
    prints."""
    from .text import remaining_words, verdict_words

    if diagnosis.verdict == "effect_found":
        remaining = getattr(diagnosis, "remaining", None)
        return " + ".join(diagnosis.suggested) + " missing" + (
            "" if remaining is None else "; " + remaining_words(remaining))
    return verdict_words(diagnosis)


def withheld_title(diagnosis) -> str | None:
    """What a diagnosis did not name for its share (:func:`~gfe_opt.text.withheld_words`,
    as the text says it), or None."""
    from .text import withheld_words

    withheld = getattr(diagnosis, "withheld", None)
    return None if withheld is None else withheld_words(withheld)


def diagnosis_figures(diagnosis, model) -> dict:
    """Candidate errors; with the generic update: its stiffness profile against the noise
    band and what the effect found would show, the structure with the located place and
    the fitted effects, the nodal equation coefficients and (for a crack) the identified
    Q_i against Christides–Barr Q(x); drawn along the line or on the frame
    (:meth:`~gfe_opt.structure.Line.diagnosis_figures`)."""
    from .structure import structure

    return structure(model).diagnosis_figures(diagnosis)


def line_diagnosis_figures(diagnosis, model) -> dict:
    """:func:`diagnosis_figures` of a beam or bar: along x."""
    found = findings(diagnosis, model)
    figs = {"candidates.png": plots.candidate_errors(
        diagnosis.fits, diagnosis.current.freq_error_rms_pct, diagnosis.together,
        verdict=verdict_title(diagnosis), length=model.length, supports=model.supports,
        findings=found, elsewhere=elsewhere(diagnosis), note=withheld_title(diagnosis),
        deciding=deciding(diagnosis))} \
        if diagnosis.fits else {}
    band = diagnosis.profile_band
    best = diagnosis.best
    if band is not None:
        figs["stiffness_change.png"] = plots.profile_with_band(
            band, label=best.name if best else None, length=model.length,
            supports=model.supports, places=diagnosis.localisation or (), findings=found,
            elsewhere=elsewhere(diagnosis))
        if best is not None:
            figs.update(effect_type(best.name).figures(model, best.parameters, band))
    if diagnosis.nodal:
        figs["nodal_equations.png"] = plots.nodal_coefficients(
            diagnosis.nodal, model.bending_rigidity, model.length)
    return figs


def frame_diagnosis_figures(diagnosis, model) -> dict:
    """:func:`diagnosis_figures` of a frame: the effects on the frame, the generic update
    member by member."""
    from .frame_data import frame_diagnosis_figures as on_frame

    figs = {"candidates.png": plots.candidate_errors(
        diagnosis.fits, diagnosis.current.freq_error_rms_pct, diagnosis.together,
        verdict=verdict_title(diagnosis), note=withheld_title(diagnosis))} \
        if diagnosis.fits else {}
    figs.update(on_frame(diagnosis, model, verdict_title(diagnosis),
                         findings(diagnosis, model)))
    if diagnosis.profile_band is not None:
        best = diagnosis.best
        figs["stiffness_change.png"] = plots.frame_profiles(
            diagnosis.profile_band, label=best.name if best else None)
    if diagnosis.nodal:
        figs["nodal_equations.png"] = plots.frame_nodal_coefficients(diagnosis.nodal)
    return figs


def update_figures(outcome) -> dict:
    """The frequency error before and after the added effects."""
    names = " + ".join(e.name for e in outcome.model.effects) or "none"
    return {"error.png": plots.error_history([("before", outcome.before.freq_error_rms_pct),
                                              (f"after ({names})",
                                               outcome.after.freq_error_rms_pct)])}



def save_figures(figs: dict, folder) -> list[Path]:
    """Write every figure as PNG into ``folder``; returns the paths."""
    return [plots.save(fig, Path(folder) / name) for name, fig in figs.items()]


#: The question each figure answers (its caption in reports; the README's table says more).
FIGURE_QUESTIONS = {
    "mac.png": "Which model mode is which test mode? MAC, pairs in bold.",
    "frequencies.png": "How far off is each frequency? Paired frequencies and the signed "
                       "error of each.",
    "localisation.png": "Where does the model fail? Residual force and COMAC per sensor, "
                        "the place marked on the structure.",
    "candidates.png": "Which effect is missing? The error each candidate leaves, best first.",
    "stiffness_change.png": "How does the structure differ, with no effect assumed? The "
                            "generic update's stiffness against what noise alone gives, and "
                            "the fitted effects on the structure.",
    "frame_diagnosis.png": "Which effect, where on the frame? The effects found at their "
                           "places with their values, hollow where one fits as well, and "
                           "where the model as it stands fails most.",
    "disturbance.png": "Is it a crack? Identified Q_i against Christides–Barr Q(x).",
    "nodal_equations.png": "What does each node's updated equation say? Stiffness and mass "
                           "ratios, axial force, foundation.",
    "error.png": "Did the error fall? Frequency error before and after.",
    "stabilisation.png": "Which poles are modes? Stable poles per model order.",
    "trend.png": "How do the parameters move over the campaign? ±1σ bands, onsets marked.",
}


def caption(name: str) -> str:
    """The caption of figure file ``name``: its question, or its name."""
    return FIGURE_QUESTIONS.get(name, name.removesuffix(".png").replace("_", " "))


class Report:
    """A self-contained HTML page: headings, text, tables, figures, commands."""

    def __init__(self, title: str):
        self.title = title
        self.parts: list[str] = []
        self.figures = 0

    def heading(self, text: str) -> None:
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def paragraph(self, text: str) -> None:
        self.parts.append(f"<p>{html.escape(text)}</p>")

    def preformatted(self, text: str) -> None:
        self.parts.append(f"<pre>{html.escape(text)}</pre>")

    def table(self, headers, rows) -> None:
        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
        body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row)
                       + "</tr>" for row in rows)
        self.parts.append(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def add_figures(self, figs: dict) -> None:
        """Every figure of ``figs`` (file name -> figure), captioned with its question."""
        for name, fig in figs.items():
            self.figure(fig, caption(name))

    def figure(self, fig, caption: str) -> None:
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=110)
        data = base64.b64encode(buffer.getvalue()).decode("ascii")
        self.figures += 1
        self.parts.append(f'<figure><img alt="{html.escape(caption)}" '
                          f'src="data:image/png;base64,{data}"/>'
                          f"<figcaption>{html.escape(caption)}</figcaption></figure>")

    def html(self) -> str:
        style = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}"
                 "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 8px;"
                 "text-align:right}th{background:#eee}img{max-width:100%}"
                 "pre{background:#f6f6f6;padding:.5em;white-space:pre-wrap}"
                 "figcaption{color:#444;font-style:italic}")
        return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"/>"
                f"<title>{html.escape(self.title)}</title><style>{style}</style></head>"
                f"<body><h1>{html.escape(self.title)}</h1>{''.join(self.parts)}</body></html>\n")

    def save(self, path) -> None:
        text = self.html()
        atomic_write(Path(path), lambda p: p.write_text(text, encoding="utf-8"))
