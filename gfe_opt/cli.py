"""The ``gfe-opt`` command line.

Exit codes: 0 success, 1 a solver failed (its status is printed), 2 bad input (one line on
stderr naming the file, the field and the fault; no traceback), 130 interrupted (Ctrl-C), 70
an internal error (a bug: one line, never a traceback).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
from pathlib import Path

from .errors import GfeInputError, GfeSolverError
from .names import BUILTIN_EFFECTS as EFFECTS
from .names import DEFAULT_COMPARE_SHAPE_NOISE as DEFAULT_SHAPE_NOISE
from .names import (
    DEFAULT_FIT_SHAPE_NOISE,
    DEFAULT_FREQ_NOISE,
    DEFAULT_MAC_THRESHOLD,
    DIAGNOSIS_FIGURES,
    FRF_FORMS,
)
from .outputs import check_distinct, check_output_folder, check_output_path

# numerical modules are imported by the commands that use them: --version, --help and
# usage errors load no numerical library (CasADi, cvxpy, matplotlib: not even on bad input)


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not 0.0 <= value < 1.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 1), got {text}")
    return value


def _noise(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"must lie between 0 and 1 (relative, e.g. 0.003 "
                                         f"for 0.3 %%), got {text}")
    return value


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr, exit code 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="gfe-opt",
        description="Finite-element model updating with generic elements: compare a beam or "
                    "bar model with measured modes and see where it fails.")
    parser.add_argument("--version", action="version", version=f"gfe-opt {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser,
                                metavar="COMMAND")

    p = sub.add_parser("compare", help="pair model and measured modes; localise the error")
    p.add_argument("model", help="model file (.toml)")
    p.add_argument("measured", help="measured modes (.json, .csv, .uff, .unv)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--mac-threshold", type=_fraction, default=DEFAULT_MAC_THRESHOLD,
                   help="lowest MAC for a pair (default %(default)s)")
    p.add_argument("--shape-noise", "--noise", dest="shape_noise", type=_fraction,
                   default=DEFAULT_SHAPE_NOISE,
                   help="shape noise relative to each mode's largest amplitude; here it "
                        "regularises the expansion of the shapes, for which a generous "
                        "value is safe (default %(default)s; --noise is the old name)")

    def output_options(p):
        p.add_argument("--plot", metavar="DIR", help="write the figures as PNG into DIR")
        p.add_argument("--report", metavar="FILE.html",
                       help="write a self-contained HTML report")
        p.add_argument("--force", action="store_true",
                       help="overwrite existing output files")

    output_options(p)

    def noise_options(p):
        p.add_argument("--freq-noise", type=_noise, default=None,
                       help="relative frequency noise σ_f of the test (not given: "
                            f"{DEFAULT_FREQ_NOISE} is assumed and the data's own level is "
                            "estimated and reported)")
        p.add_argument("--shape-noise", type=_noise, default=None,
                       help="shape noise σ_s relative to each mode's largest amplitude (not "
                            f"given: {DEFAULT_FIT_SHAPE_NOISE} is assumed and estimated)")

    g = sub.add_parser("diagnose", help="which physical effect is missing (or none)")
    g.add_argument("model", help="model file (.toml)")
    g.add_argument("measured", help="measured modes (.json, .csv, .uff, .unv)")
    g.add_argument("--json", action="store_true", help="print the result as JSON")
    g.add_argument("--candidates", default=None, metavar="NAME,...",
                   help="comma-separated effects to try (default: every one that applies; "
                        f"known: {', '.join(EFFECTS)})")
    noise_options(g)
    output_options(g)

    u = sub.add_parser("update", help="add effects, fit their parameters, see the error fall "
                       "(with neither --add nor --drop: re-estimate the model's effects)")
    u.add_argument("model", help="model file (.toml)")
    u.add_argument("measured", help="measured modes (.json, .csv, .uff, .unv)")
    u.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="effect instance to add, e.g. crack or crack:position=0.2 "
                        "(repeatable; local effects may be added several times; known: "
                        f"{', '.join(EFFECTS)})")
    u.add_argument("--drop", action="append", default=[], metavar="EFFECT",
                   help="take a present effect out first: its index in the model's effects "
                        "(from 0, as diagnose's 'replace') or its name (repeatable)")
    u.add_argument("--out", help="write the updated model (with its [[effects]]) here")
    u.add_argument("--json", action="store_true", help="print the result as JSON")
    noise_options(u)
    output_options(u)

    o = sub.add_parser("modes", help="write a model's modes at its nodes (UFF 2411 + 55, "
                       "JSON or CSV)")
    o.add_argument("model", help="model file (.toml)")
    o.add_argument("--out", required=True, help="output file (.uff, .unv, .json or .csv)")
    o.add_argument("--modes", type=int, default=5, help="number of modes (default 5)")
    o.add_argument("--force", action="store_true", help="overwrite an existing --out file")

    b = sub.add_parser("batch", help="diagnose (or update) every measured set of a folder; "
                       "one table row per set (Parquet or CSV), resumable, local or on Dask")
    b.add_argument("model", help="model file (.toml)")
    b.add_argument("measured_dir", help="folder of measured files (.json, .csv, .uff, .unv)")
    b.add_argument("--out", required=True, help="results table (.parquet or .csv); a rerun "
                   "with the same --out skips the sets already done")
    b.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="update these effects in every set instead of diagnosing "
                        "(repeatable, as for update)")
    b.add_argument("--loop", action="store_true",
                   help="follow each diagnosis: add what it suggests and diagnose again "
                        "until nothing more is found (at most 4 additions; the loop the "
                        "validation campaigns score); the row holds the final verdict")
    b.add_argument("--scheduler", metavar="tcp://HOST:8786",
                   help="run the sets on this Dask distributed scheduler (default: a local "
                        "pool of processes on this machine)")
    b.add_argument("--workers", type=int, default=None,
                   help="local processes (default: every core)")
    b.add_argument("--force", action="store_true",
                   help="start over: discard an existing --out and its journal")
    noise_options(b)

    t = sub.add_parser("trend", help="draw a batch table: each parameter against time or "
                       "label with its band, the error before and after")
    t.add_argument("results", help="results table of gfe-opt batch (.parquet or .csv)")
    t.add_argument("--plot", metavar="DIR", help="write trend.png and error.png into DIR")
    t.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")
    t.add_argument("--json", action="store_true", help="print the trend summary as JSON")
    t.add_argument("--force", action="store_true", help="overwrite existing output files")

    i = sub.add_parser("identify", help="identify modes (frequencies, damping, shapes) from "
                       "measured FRFs (UFF 58 or CSV)")
    i.add_argument("frf", nargs="+", help="FRF files (.uff/.unv with dataset 58 and node "
                   "coordinates, or .csv: a header of positions, then frequency rows)")
    i.add_argument("--out", required=True, help="measured modes to write (.json with damping, "
                   ".csv or .uff)")
    i.add_argument("--band", metavar="LOW:HIGH", default=None,
                   help="frequency band in Hz (default: the measured range without its first "
                        "and last 2 %%)")
    i.add_argument("--modes", type=int, default=None,
                   help="number of modes to keep, the most stable (default: every mode stable "
                        "over a fifth of the model orders)")
    i.add_argument("--order", type=int, default=60,
                   help="highest LSCF model order (default %(default)s)")
    i.add_argument("--frf-form", choices=FRF_FORMS, default=None,
                   help="what the CSV values are (default accelerance; UFF files say it)")
    i.add_argument("--json", action="store_true", help="print the modes as JSON")
    i.add_argument("--plot", metavar="DIR", help="write the stabilisation chart into DIR")
    i.add_argument("--force", action="store_true", help="overwrite existing output files")

    d = sub.add_parser("demo", help="the whole story on a synthetic cracked beam (--frame: "
                       "on a portal frame with semi-rigid joints)")
    d.add_argument("--frame", action="store_true",
                   help="the portal frame's demo instead of the beam's")
    d.add_argument("--out", default=None,
                   help="folder for the demo's files (default gfe-opt-demo, with --frame "
                        "gfe-opt-frame-demo)")
    d.add_argument("--force", action="store_true", help="overwrite the demo's own files")
    return parser


def _check_outputs(args, names) -> None:
    """Refuse, before any work, outputs that would overwrite inputs or existing files, that
    are not ordinary files, or that share a path (gfe_opt.outputs)."""
    inputs = [a for a in (getattr(args, "model", None), getattr(args, "measured", None)) if a]
    paths = {"--out": getattr(args, "out", None), "--report": getattr(args, "report", None)}
    if getattr(args, "plot", None) is not None:
        folder = check_output_folder(args.plot)
        for name in names:
            check_output_path(folder / name, args.force, inputs, kind="figure",
                              where="--plot")
            paths[f"--plot {name}"] = folder / name
    if getattr(args, "report", None) is not None:
        check_output_path(args.report, args.force, inputs, kind="report", where="--report")
    check_distinct(paths)


def _write_outputs(args, figs, fill_report, title) -> None:
    """Figures into --plot DIR, and the report (``fill_report(report)`` adds its body)."""
    from .report import Report, save_figures

    if not figs:
        return
    if args.plot:
        paths = save_figures(figs, args.plot)
        if not args.json:
            print(f"figures: {', '.join(str(p) for p in paths)}")
    if args.report:
        report = Report(title)
        fill_report(report)
        report.add_figures(figs)
        report.heading("Reproduce")
        report.preformatted(" ".join(["gfe-opt", *args.argv]))
        report.save(args.report)
        if not args.json:
            print(f"report: {args.report}")


def _figures(build, *args) -> dict:
    """Figures from ``build``; a missing matplotlib is an input problem with a fix."""
    try:
        return build(*args)
    except ImportError as exc:
        raise GfeInputError("--plot/--report", None, str(exc)) from None



def _inputs(args, frames: bool = False):
    """The model and measured files of a command (input errors before any solver loads);
    ``frames``: the command takes a plane frame too."""
    from .model import load_model
    from .structure import structure

    model = load_model(args.model, frames=frames)
    return model, structure(model).load_measured(args.measured)


def cmd_compare(args) -> int:
    from .structure import structure

    model, measured = _inputs(args, frames=True)
    shape = structure(model)
    _check_outputs(args, shape.compare_figures)
    result = shape.compare(measured, mac_threshold=args.mac_threshold, noise=args.shape_noise)
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(shape.headline(measured))
        print(shape.format_comparison(result))
    if args.plot or args.report:
        _write_outputs(args, _figures(shape.comparison_figures, result, measured),
                       lambda r: shape.comparison_report(r, result, measured),
                       f"gfe-opt compare: {model.name}")
    return 0


def cmd_modes(args) -> int:
    from .model import load_model
    from .structure import structure

    check_output_path(args.out, args.force, (args.model,), kind="modes")
    model = load_model(args.model, frames=True)
    if args.modes < 1:
        raise GfeInputError("--modes", None, f"must be >= 1, got {args.modes}")
    for line in structure(model).write_modes(args.modes, args.out, force=args.force,
                                             protect=(args.model,)):
        print(line)
    return 0


def cmd_diagnose(args) -> int:
    model, measured = _inputs(args, frames=True)
    candidates = None
    if args.candidates is not None:
        candidates = [c.strip() for c in args.candidates.split(",") if c.strip()]
        if not candidates:
            raise GfeInputError("--candidates", None, "no effect named")
    _check_outputs(args, DIAGNOSIS_FIGURES)
    from .diagnosis import diagnose
    from .text import format_diagnosis, terminal_progress

    result = diagnose(model, measured, candidates=candidates, freq_noise=args.freq_noise,
                      shape_noise=args.shape_noise, progress=terminal_progress(not args.json),
                      realise=True)
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(format_diagnosis(result, model))
    if args.plot or args.report:
        from .report import diagnosis_figures

        def body(report):
            report.heading("Diagnosis")
            report.preformatted(format_diagnosis(result, model))

        _write_outputs(args, _figures(diagnosis_figures, result, model), body,
                       f"gfe-opt diagnose: {model.name}")
    return 0




def cmd_update(args) -> int:
    model, measured = _inputs(args, frames=True)
    if not args.add and not args.drop and not model.effects:
        raise GfeInputError("update", None, "nothing to do: give an effect to add (--add) or "
                            "a present one to take out (--drop); with neither, update "
                            "re-estimates the model's effects, and this model has none")
    from .model import parse_effect, save_model

    effects = [parse_effect(a, model) for a in args.add]
    if args.out is not None:  # refuse before the work, not after
        check_output_path(args.out, args.force, (args.model, args.measured), kind="model")
    _check_outputs(args, ("error.png",))
    from .diagnosis import update
    from .text import format_update

    outcome = update(model, measured, effects, freq_noise=args.freq_noise,
                     shape_noise=args.shape_noise, drop=args.drop)
    if args.out is not None:
        save_model(outcome.model, args.out, force=args.force,
                   protect=(args.model, args.measured))
    if args.json:
        print(json.dumps(outcome.to_json(), indent=1))
    else:
        print(format_update(outcome))
        if args.out:
            print(f"updated model written to {args.out}; continue with: gfe-opt diagnose "
                  f"{args.out} {args.measured}")
    if args.plot or args.report:
        from .report import update_figures

        def body(report):
            report.heading("Update")
            report.preformatted(format_update(outcome))

        _write_outputs(args, _figures(update_figures, outcome), body,
                       f"gfe-opt update: {model.name}")
    return 0


def _band(text):
    """``LOW:HIGH`` in Hz."""
    if text is None:
        return None
    low, sep, high = text.partition(":")
    try:
        band = (float(low), float(high))
    except ValueError:
        raise GfeInputError("--band", text, "must be LOW:HIGH in Hz, e.g. 10:1000") from None
    if not sep or not all(map(math.isfinite, band)) or not 0 <= band[0] < band[1]:
        raise GfeInputError("--band", text, "must be LOW:HIGH in Hz with 0 <= LOW < HIGH")
    return band


def cmd_identify(args) -> int:
    from .identify import identify, load_frfs
    from .measured import save_measured
    from .text import format_identification

    band = _band(args.band)
    if args.modes is not None and args.modes < 1:
        raise GfeInputError("--modes", None, f"must be >= 1, got {args.modes}")
    if not 4 <= args.order <= 400:
        raise GfeInputError("--order", None, f"must lie in [4, 400], got {args.order}")
    check_output_path(args.out, args.force, args.frf, kind="modes")
    _check_outputs(args, ("stabilisation.png",))
    frfs = load_frfs(args.frf, args.frf_form)
    result = identify(frfs, band=band, modes=args.modes, order=args.order)
    save_measured(result.measured, args.out, force=args.force, protect=args.frf)
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(format_identification(result))
        print(f"modes written to {args.out}")
    if args.plot:
        from . import plots
        from .report import save_figures

        paths = save_figures({"stabilisation.png": _figures(plots.stabilisation, result)},
                             args.plot)
        if not args.json:
            print(f"figures: {', '.join(str(p) for p in paths)}")
    return 0


def cmd_batch(args) -> int:
    from .batch import run_batch
    from .text import batch_progress, format_batch

    result = run_batch(args.model, args.measured_dir, args.out, add=args.add,
                       scheduler=args.scheduler, workers=args.workers,
                       freq_noise=args.freq_noise, shape_noise=args.shape_noise,
                       force=args.force, progress=batch_progress(), loop=args.loop)
    print(format_batch(result))
    return 1 if result.failed else 0


def cmd_trend(args) -> int:
    from .batch import read_table
    from .inputs import check_input_file
    from .text import format_trend
    from .trend import trend

    check_input_file(Path(args.results), "results")
    _check_outputs(args, ("trend.png", "error.png"))
    result = trend(read_table(args.results), args.results)
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(format_trend(result))
    from . import plots

    figs = {"trend.png": _figures(plots.trend_parameters, result),
            "error.png": _figures(plots.trend_errors, result)} \
        if args.plot or args.report else {}
    _write_outputs(args, figs, lambda report: report.preformatted(format_trend(result)),
                   f"gfe-opt trend: {Path(args.results).name}")
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    out = args.out or ("gfe-opt-frame-demo" if args.frame else "gfe-opt-demo")
    return run_demo(Path(out), force=args.force, frame=args.frame)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("gfe-opt")
    except PackageNotFoundError:
        return "(not installed)"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        parser = build_parser()
        if not argv:  # a bare call: what the tool does and its commands, not a usage error
            parser.print_help()
            print("gfe-opt: error: no command given (one of those above)", file=sys.stderr)
            return 2
        try:
            args = parser.parse_args(argv)
        except SystemExit as exc:  # usage errors (2) and --help (0) from argparse
            return int(exc.code or 0)
        args.argv = argv
        import numpy as np

        with np.errstate(all="ignore"):
            from .outputs import replacing

            # an output that did not exist at the checks is claimed, not replaced, unless
            # --force: of two runs writing one new file, one wins
            with replacing(bool(getattr(args, "force", False))):
                return {"compare": cmd_compare, "diagnose": cmd_diagnose,
                        "update": cmd_update, "modes": cmd_modes, "identify": cmd_identify,
                        "batch": cmd_batch, "trend": cmd_trend,
                        "demo": cmd_demo}[args.command](args)
    except GfeInputError as exc:
        print(f"gfe-opt: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except GfeSolverError as exc:
        print(f"gfe-opt: solver failed: {_one_line(exc)}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into a reader that stopped (| head): not an error
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt:
        print("gfe-opt: interrupted (nothing half-written: outputs are written whole or not "
              "at all)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except MemoryError:
        print("gfe-opt: error: out of memory: use fewer elements, sensors or modes (README "
              "\"Limits\")", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug: one line, not a traceback; the fuzzer looks for these
        print(f"gfe-opt: internal error (a bug, please report it with the command): "
              f"{type(exc).__name__}: {_one_line(exc)}", file=sys.stderr)
        return EXIT_INTERNAL_ERROR


#: exit codes besides 0 (success), 1 (a solver failed) and 2 (bad input)
EXIT_INTERRUPTED = 130
EXIT_INTERNAL_ERROR = 70


def _one_line(exc) -> str:
    return " ".join(str(exc).split())


if __name__ == "__main__":
    sys.exit(main())
