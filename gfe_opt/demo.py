"""``gfe-opt demo``: the whole story on a synthetic cracked beam, told step by step;
``gfe-opt demo --frame`` the same on a portal frame whose beam-to-column joints are
semi-rigid."""

from __future__ import annotations

from pathlib import Path

from .correlation import compare
from .diagnosis import diagnose, update
from .errors import GfeInputError
from .measured import save_measured
from .model import load_model, save_model
from .names import FRAME_COMPARE_FIGURES
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
#: the same for ``demo --frame``
FRAME_DEMO_FILES = ("model.toml", "measured.json", "updated.toml", "report.html",
                    *(f"figures/{name}" for name in (*FRAME_COMPARE_FIGURES,
                                                      *DIAGNOSIS_FIGURES, "error.png")))
#: the frame demo's test: the portal's beam tied to both columns through 2000 N m/rad
FRAME_DEMO_TEST = "portal-frame-semirigid.json"
FRAME_DEMO_TRUTH = "joint springs of 2000 N m/rad at B and at C (the beam's ends)"


def _sha1(path: Path) -> str:
    import hashlib

    return hashlib.sha1(path.read_bytes()).hexdigest()


def check_demo_folder(out: Path, files=DEMO_FILES) -> None:
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
    for name in files:
        path = out / name
        if path.is_symlink() or path.exists() and (not path.is_file()
                                                   or written.get(name) != _sha1(path)):
            raise GfeInputError(str(path), None, "exists and is not as the demo wrote it; "
                                "pass --force to overwrite it, or choose another --out")


def check_demo_force(out: Path, files=DEMO_FILES) -> None:
    """With --force the demo replaces files, never anything else at their names (a folder,
    a FIFO): such a path is refused before any work.  A link is replaced by the file, its
    target left as it was."""
    from .outputs import check_output_path

    for name in files:
        check_output_path(out / name, True, (), where="--out")


def _mark_demo_folder(out: Path, files=DEMO_FILES) -> None:
    import json

    hashes = {name: _sha1(out / name) for name in files if (out / name).is_file()}
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


def run_demo(out: Path, force: bool = False, frame: bool = False) -> int:
    """The demo into ``out`` (``frame``: the portal frame's); its files (figures included)
    are checked first: without ``force`` each must be absent or as an earlier demo wrote
    it, and is then replaced."""
    from .outputs import replacing

    files = FRAME_DEMO_FILES if frame else DEMO_FILES
    if force:
        check_demo_force(out, files)
    else:
        check_demo_folder(out, files)
    with replacing(True):
        return _run_frame_demo(out) if frame else _run_demo(out)


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
    _check(outcome.model, measured, **NOISE)
    figures = _story_figures(lambda: compare_figures(result, model), diagnosis, model,
                             outcome, best.effect)
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


def _check(model, measured, **noise) -> None:
    """Step 6: the updated model diagnosed again, and what is left said in one line."""
    again = diagnose(model, measured, progress=terminal_progress(True), **noise)
    left = again.best
    print("   nothing significant is left: " + again.verdict if left is None else
          f"   still significant: {left.describe()}")


def _story_figures(compared, diagnosis, model, outcome, label):
    """The demo's figures: ``compared()``'s, the diagnosis's and the error before and after
    adding ``label``; None (said in a line) where matplotlib is missing."""
    try:
        return [compared(), diagnosis_figures(diagnosis, model),
                {"error.png": error_history([
                    ("initial model", outcome.before.freq_error_rms_pct),
                    (f"+ {label}", outcome.after.freq_error_rms_pct)])}]
    except ImportError as exc:
        print(f"\n(no figures or report: {exc})")
        return None


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


def _run_frame_demo(out: Path) -> int:
    """The story on the portal frame of ``problems/portal-frame.toml`` and its test
    ``problems/portal-frame-semirigid.json`` (the exact solution of a portal whose beam is
    tied to both columns by rotational springs, with noise; ``tests/test_frame.py``
    regenerates it): compare, diagnose with the noise not stated, add what the diagnosis
    says at the places it names, compare again and diagnose again."""
    from .frame_data import compare_frame, frame_figures, load_frame_measured
    from .text import format_frame_comparison

    model_path, measured_path = out / "model.toml", out / "measured.json"
    updated_path, report_path = out / "updated.toml", out / "report.html"
    out.mkdir(parents=True, exist_ok=True)
    for source, path in (("portal-frame.toml", model_path), (FRAME_DEMO_TEST, measured_path)):
        data = problem_file(source).read_bytes()
        atomic_write(path, lambda tmp, data=data: tmp.write_bytes(data), replace=True)
    model = load_model(model_path, frames=True)
    measured = load_frame_measured(measured_path, model)
    lengths = ", ".join(f"{m.id} {1000 * model.member_length(m):.0f} mm"
                        for m in model.members)
    print("gfe-opt demo --frame: a frame model that disagrees with a modal test\n")
    print(f"1. The model ({model_path}): a steel portal frame, {lengths}, clamped at both "
          f"feet,\n   rigid joints, {model.n_elements} elements.")
    print(f"2. The test ({measured_path}): {measured.n_modes} modes at "
          f"{len(measured.sensors)} sensors, computed exactly for a portal that has\n"
          "   something the model lacks (0.3 % shape noise, 0.05 % frequency noise; not "
          "told to the diagnosis).")
    print("\n3. Compare: paired modes, and where on the frame the shapes differ most.\n")
    result = compare_frame(model, measured)
    print(_indent(format_frame_comparison(result)))
    print("\n4. Diagnose: each candidate effect is fitted at every place of the frame it "
          "can take\n   and ranked; 'significant' means beyond the measurement noise.\n")
    diagnosis = diagnose(model, measured, progress=terminal_progress(True))
    print(_indent(format_diagnosis(diagnosis, model)))
    add = diagnosis.add_arguments()
    if diagnosis.verdict != "effect_found" or not add:
        print(f"\nNothing to add: {diagnosis.verdict}.")
        _mark_demo_folder(out, FRAME_DEMO_FILES)
        return 0
    print(f"\n5. Add {'them' if len(add) > 1 else 'it'}: update --add "
          + " --add ".join(add) + "\n")
    outcome = update(model, measured, add)
    save_model(outcome.model, updated_path, force=True, protect=(model_path, measured_path))
    print(_indent(format_update(outcome)))
    print(f"   the hidden truth was: {FRAME_DEMO_TRUTH}")
    print("\n6. Check: compare and diagnose the updated model; nothing significant should "
          "be left.\n")
    after = compare_frame(outcome.model, measured)
    print(_indent(format_frame_comparison(after)) + "\n")
    _check(outcome.model, measured)
    figures = _story_figures(lambda: frame_figures(result, model, measured), diagnosis, model,
                             outcome, " + ".join(e.name for e in outcome.model.effects))
    if figures is not None:
        save_figures({k: v for f in figures for k, v in f.items()}, out / "figures")
        report = Report("gfe-opt demo: a portal frame with semi-rigid joints")
        report.paragraph(f"{measured.n_modes} modes measured at {len(measured.sensors)} "
                         "sensors on a steel portal frame are compared with a rigid-jointed "
                         "model; the missing effect is diagnosed on the frame, added at its "
                         "places and fitted, and the error falls to the measurement noise.")
        for heading, text, figs in (
                ("1. Compare", format_frame_comparison(result), figures[0]),
                ("2. Diagnose", format_diagnosis(diagnosis, model), figures[1]),
                ("3. Add the effects", format_update(outcome) + "\n\n"
                 + format_frame_comparison(after), figures[2])):
            report.heading(heading)
            report.preformatted(text)
            report.add_figures(figs)
        report.paragraph(f"The hidden truth: {FRAME_DEMO_TRUTH}.")
        report.save(report_path)
        print(f"\nFigures in {out / 'figures'}/, the report in {report_path}.")
    _mark_demo_folder(out, FRAME_DEMO_FILES)
    adds = " ".join(f"--add {a}" for a in add)
    print(f"\nFiles in {out}/ (a second gfe-opt demo --frame rewrites them). Reproduce "
          f"with:\n  gfe-opt compare {model_path} {measured_path}\n"
          f"  gfe-opt diagnose {model_path} {measured_path}\n"
          f"  gfe-opt update {model_path} {measured_path} {adds} --out {updated_path} "
          f"--force\n  gfe-opt compare {updated_path} {measured_path}")
    return 0
