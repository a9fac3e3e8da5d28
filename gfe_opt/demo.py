"""``gfe-opt demo``: the whole story on a synthetic cracked beam, told step by step."""

from __future__ import annotations

from pathlib import Path

from .correlation import compare
from .diagnosis import diagnose, update
from .errors import GfeInputError
from .measured import save_measured
from .model import load_model, save_model
from .outputs import atomic_write
from .plots import error_history
from .problems import problem_file
from .report import (
    COMPARE_FIGURES,
    DIAGNOSIS_FIGURES,
    Report,
    compare_figures,
    diagnosis_figures,
    save_figures,
)
from .text import (
    format_comparison,
    format_diagnosis,
    format_parameters,
    format_update,
    terminal_progress,
)

#: The hidden truth of the demo: a crack the starting model does not have.
DEMO_CRACK = {"position": 0.19, "depth_ratio": 0.5}
#: The noise the demo's test is simulated with, stated to the diagnosis.
NOISE = {"freq_noise": 0.0005, "shape_noise": 0.003}


def _indent(text: str) -> str:
    return "   " + text.replace("\n", "\n   ")


MARKER = ".gfe-opt-demo.json"
#: every file the demo may write: a second demo replaces them only as the first wrote them
DEMO_FILES = ("model.toml", "measured.json", "updated.toml", "report.html",
              *(f"figures/{name}" for name in (*COMPARE_FIGURES, *DIAGNOSIS_FIGURES,
                                                "error.png")))


def _sha1(path: Path) -> str:
    import hashlib

    return hashlib.sha1(path.read_bytes()).hexdigest()


def check_demo_folder(out: Path) -> None:
    """A second demo may overwrite what the first wrote, as it wrote it (the hashes in
    ``MARKER``); a file it did not write, or one changed since, needs ``force``."""
    import json

    marker = out / MARKER
    written = {}
    if marker.is_file():
        try:
            written = json.loads(marker.read_text())
        except (ValueError, UnicodeDecodeError):
            written = {}
    for name in DEMO_FILES:
        path = out / name
        if path.is_symlink() or path.exists() and (not path.is_file()
                                                   or written.get(name) != _sha1(path)):
            raise GfeInputError(str(path), None, "exists and is not as the demo wrote it; "
                                "pass --force to overwrite it, or choose another --out")


def check_demo_force(out: Path) -> None:
    """With --force the demo replaces files, never anything else at their names (a folder,
    a FIFO): such a path is refused before any work.  A link is replaced by the file, its
    target left as it was."""
    from .outputs import check_output_path

    for name in DEMO_FILES:
        check_output_path(out / name, True, (), where="--out")


def _mark_demo_folder(out: Path) -> None:
    import json

    hashes = {name: _sha1(out / name) for name in DEMO_FILES if (out / name).is_file()}
    atomic_write(out / MARKER, lambda tmp: Path(tmp).write_text(json.dumps(hashes, indent=1)),
                 replace=True)


def demo_measurement(model=None):
    """The demo's test: 5 modes at 45 sensors of the paper's beam with ``DEMO_CRACK``, 0.3 %
    shape and 0.05 % frequency noise (fixed seed), as shipped in
    ``problems/demo-measured.json``.  ``scripts/make_examples.py`` made it with the tests'
    independent truth generator (``tests/reference.py``: its own 1200-element Hermite beam
    with the crack's EI(x); the package does not build it and never imports the tests)."""
    from .measured import load_measured

    del model  # the file is the test; the model is only the starting point
    return load_measured(problem_file("demo-measured.json"))


def run_demo(out: Path, force: bool = False) -> int:
    """The demo into ``out``; its files (figures included) are checked first: without
    ``force`` each must be absent or as an earlier demo wrote it, and is then replaced."""
    from .outputs import replacing

    if force:
        check_demo_force(out)
    else:
        check_demo_folder(out)
    with replacing(True):
        return _run_demo(out)


def _run_demo(out: Path) -> int:
    model_path, measured_path = out / "model.toml", out / "measured.json"
    updated_path, report_path = out / "updated.toml", out / "report.html"
    out.mkdir(parents=True, exist_ok=True)
    source = problem_file("ss-steel-beam.toml").read_bytes()
    atomic_write(model_path, lambda tmp: tmp.write_bytes(source), replace=True)
    model = load_model(model_path)
    print("gfe-opt demo: a model that disagrees with a modal test\n")
    print(f"1. The model ({model_path}): a simply supported steel beam, "
          f"{1000 * model.length:.0f} mm long, {1000 * model.depth:.2f} x "
          f"{1000 * model.breadth:.3f} mm, {model.elements} Euler-Bernoulli elements.")
    measured = demo_measurement(model)
    save_measured(measured, measured_path, force=True)
    print(f"2. The test ({measured_path}): 5 modes at 45 accelerometers, simulated with an "
          "independent fine model\n   of the real beam, which has something the model lacks "
          "(0.3 % shape noise, 0.05 % frequency noise).")
    print("\n3. Compare: paired modes, and where along the beam the model fails.\n")
    result = compare(model, measured)
    print(_indent(format_comparison(result, model.length)))
    print("\n4. Diagnose: each candidate physical effect is fitted (IPOPT) and ranked by how "
          "much of\n   the error it explains; 'significant' means beyond the measurement "
          "noise.\n")
    diagnosis = diagnose(model, measured, realise=True, progress=terminal_progress(True),
                         **NOISE)
    print(_indent(format_diagnosis(diagnosis, model)))
    best = diagnosis.best
    if best is None:
        print("\nNothing significant to add.")
        _mark_demo_folder(out)
        return 0
    print(f"\n5. Add it: update --add {best.effect} fits its parameters, starting from the "
          "diagnosis.\n")
    outcome = update(model, measured, [best.effect], **NOISE)
    save_model(outcome.model, updated_path, force=True, protect=(model_path, measured_path))
    print(_indent(format_update(outcome)))
    print(f"   the hidden truth was: crack at x = {DEMO_CRACK['position']} m, "
          f"a/d = {DEMO_CRACK['depth_ratio']}")
    print("\n6. Check: diagnose the updated model; nothing significant should be left.\n")
    again = diagnose(outcome.model, measured, progress=terminal_progress(True), **NOISE)
    left = again.best
    print("   nothing significant is left: " + again.verdict if left is None else
          f"   still significant: {left.describe()}")
    try:
        figures = [compare_figures(result, model), diagnosis_figures(diagnosis, model),
                   {"error.png": error_history([
                       ("initial model", outcome.before.freq_error_rms_pct),
                       (f"+ {best.effect}", outcome.after.freq_error_rms_pct)])}]
    except ImportError as exc:
        print(f"\n(no figures or report: {exc})")
        figures = None
    if figures is not None:
        _write_report(out, report_path, figures, result, diagnosis, outcome, best, model,
                      model_path, measured_path, updated_path)
    _mark_demo_folder(out)
    print(f"\nFiles in {out}/ (a second gfe-opt demo rewrites them). Reproduce with:\n"
          f"  gfe-opt compare {model_path} {measured_path}\n"
          f"  gfe-opt diagnose {model_path} {measured_path}\n"
          f"  gfe-opt update {model_path} {measured_path} --add {best.effect} "
          f"--out {updated_path} --force\n"
          f"  gfe-opt diagnose {updated_path} {measured_path}")
    return 0


def _write_report(out, report_path, figures, result, diagnosis, outcome, best, model,
                  model_path, measured_path, updated_path):
    compared, diagnosed, updated = figures
    save_figures({**compared, **diagnosed, **updated}, out / "figures")
    report = Report("gfe-opt demo: a cracked beam the model did not know about")
    report.paragraph("Five modes measured at 45 sensors on a simply supported steel beam are "
                     "compared with an uncracked model; the missing effect is diagnosed, "
                     "added and fitted, and the error falls to the measurement noise.")
    report.heading("1. Compare")
    report.preformatted(format_comparison(result, model.length))
    report.add_figures(compared)
    report.heading("2. Diagnose")
    report.preformatted(format_diagnosis(diagnosis, model))
    report.add_figures(diagnosed)
    report.heading("3. Add the effect")
    report.table(["", "frequency error [% rms]", "mean MAC"],
                 [["before", f"{outcome.before.freq_error_rms_pct:.3f}",
                   f"{outcome.before.mac_mean:.4f}"],
                  ["after", f"{outcome.after.freq_error_rms_pct:.3f}",
                   f"{outcome.after.mac_mean:.4f}"]])
    report.table(["effect", "fitted parameters", "hidden truth"],
                 [[e.name, format_parameters(e.parameters), format_parameters(DEMO_CRACK)]
                  for e in outcome.model.effects])
    report.add_figures(updated)
    report.heading("Reproduce")
    report.preformatted(f"gfe-opt compare {model_path} {measured_path} --report compare.html\n"
                        f"gfe-opt diagnose {model_path} {measured_path}\n"
                        f"gfe-opt update {model_path} {measured_path} --add {best.effect} "
                        f"--out {updated_path} --force")
    report.save(report_path)
    print(f"\nFigures in {out / 'figures'}/, the report in {report_path}.")
