"""The ``gfe-opt`` command line.

Exit codes: 0 success, 1 a solver failed (its status is printed), 2 bad input (one line on
stderr naming the file, the field and the fault; no traceback).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .correlation import DEFAULT_MAC_THRESHOLD, DEFAULT_SHAPE_NOISE, Comparison, compare
from .errors import GfeInputError, GfeSolverError
from .measured import load_measured
from .model import load_model

SPARK = " ▁▂▃▄▅▆▇█"


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not 0.0 <= value < 1.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 1), got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gfe-opt",
        description="Finite-element model updating with generic elements: compare a beam or "
                    "bar model with measured modes and see where it fails.")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("compare", help="pair model and measured modes; localise the error")
    p.add_argument("model", help="model file (.toml)")
    p.add_argument("measured", help="measured modes (.json, .csv, .uff, .unv)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--mac-threshold", type=_fraction, default=DEFAULT_MAC_THRESHOLD,
                   help="lowest MAC for a pair (default %(default)s)")
    p.add_argument("--noise", type=_fraction, default=DEFAULT_SHAPE_NOISE,
                   help="relative shape noise that regularises the expansion "
                        "(default %(default)s)")

    d = sub.add_parser("demo", help="the whole story on a synthetic cracked beam")
    d.add_argument("--out", default="gfe-opt-demo",
                   help="folder for the demo's files (default %(default)s)")
    d.add_argument("--force", action="store_true", help="overwrite the demo's own files")
    return parser


def format_comparison(result: Comparison, length: float) -> str:
    """Readable table of paired modes and the localisation summary."""
    lines = [f"{'mode':>4}  {'f_test [Hz]':>12}  {'f_model [Hz]':>12}  {'Δf %':>8}  {'MAC':>6}"]
    for p in result.pairs:
        model = f"{p.model_hz:12.2f}"
        lines.append(f"{p.test_mode:>4}  {p.test_hz:12.2f}  {model}  {p.error_pct:+8.2f}  "
                     f"{p.mac:6.3f}")
    for t in result.unpaired_test_modes:
        lines.append(f"{t + 1:>4}  (no model mode with MAC >= threshold)")
    lines.append(f"frequency error (rms) {result.freq_error_rms_pct:.2f} %, "
                 f"mean MAC {result.mac_mean:.3f}")
    places = result.failure_places()
    lines.append("")
    if not places:
        lines.append("no residual force: the model reproduces the measured shapes")
        lines.extend(f"note: {n}" for n in result.notes)
        return "\n".join(lines)
    r = result.residual / result.residual.max()
    spark = "".join(SPARK[int(round(v * (len(SPARK) - 1)))] for v in r)
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


def cmd_compare(args) -> int:
    model = load_model(args.model)
    measured = load_measured(args.measured, dof="w" if model.kind == "beam" else "u")
    result = compare(model, measured, mac_threshold=args.mac_threshold, noise=args.noise)
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(f"{model.name}: {model.kind}, {model.elements} elements, "
              f"{measured.n_modes} measured modes at {measured.n_sensors} sensors")
        print(format_comparison(result, model.length))
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    return run_demo(Path(args.out), force=args.force)


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    np.seterr(all="ignore")
    try:
        return {"compare": cmd_compare, "demo": cmd_demo}[args.command](args)
    except GfeInputError as exc:
        print(f"gfe-opt: error: {exc}", file=sys.stderr)
        return 2
    except GfeSolverError as exc:
        print(f"gfe-opt: solver failed: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
