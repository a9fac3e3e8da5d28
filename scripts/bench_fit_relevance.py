"""Where a diagnosis spends its fits: each candidate's fit a member (a frame's group of
starts, a beam's one) timed, with the best χ² of its grid, its final χ² and status, and the
share of the time spent on fits that end far above the best fit of the diagnosis.

    python scripts/bench_fit_relevance.py [--case storey|portal|beam] [--factor 100] [--json out]

``storey``: ``scripts/bench.py``'s three-storey frame with a 0.3 kg floor mass (36 sensors,
6 modes); ``portal``: the shipped semi-rigid portal's test; ``beam``: the 46-element demo
beam with a crack (45 sensors, 5 modes).  The fits run one after another (one core, one
BLAS thread): the times add up to the serial cost.  A measurement, not a rule: a fit that
ends at ``--factor`` times the best χ² cannot change the verdict, but which fits may be cut
short, and when, is for a campaign to judge."""

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from gfe_opt import diagnosis, fitting  # noqa: E402


def _case(name):
    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    if name == "storey":
        from bench import _storey_measured

        from gfe_opt.problems import three_storey_frame

        model = three_storey_frame()
        return model, _storey_measured(model), noise
    if name == "portal":
        from gfe_opt.frame_data import load_frame_measured
        from gfe_opt.problems import portal_frame, problem_file

        model = portal_frame()
        return model, load_frame_measured(problem_file("portal-frame-semirigid.json"),
                                          model), noise
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    model = load_model(problem_file("ss-steel-beam.toml"))
    truth = model.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    return model, synthetic_measurement(truth, 5, interior_sensors(model.length, 45),
                                        shape_noise=0.003, freq_noise=0.0005,
                                        seed=2002), noise


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=("storey", "portal", "beam"), default="storey")
    ap.add_argument("--factor", type=float, default=100.0)
    ap.add_argument("--json", help="write the rows and the summary to this file too")
    args = ap.parse_args(argv)
    model, measured, noise = _case(args.case)
    diagnosis.SERIAL_FITS = True
    grid_start, fit_group = fitting._grid_start, diagnosis._fit_group
    grid = []

    def recording_grid(chi2, grids, nulls=None, bulk=None):
        def seen(z):
            value = chi2(z)
            grid.append(value)
            return value

        def seen_in_bulk(zs, null):   # a screened grid's values (its best ones exact)
            values = bulk(zs, null)
            if values is not None:
                grid.extend(values)
            return values
        return grid_start(seen, grids, nulls, None if bulk is None else seen_in_bulk)

    rows = []

    def recording_group(model_, measured_, name, noise_, group, extra, thorough):
        grid.clear()
        start = time.perf_counter()
        fit = fit_group(model_, measured_, name, noise_, group, extra, thorough)
        place = {k: v for k, v in group[0].items() if k in ("member", "node", "direction")}
        rows.append({"effect": name, "place": place, "extra": [e.name for e in extra],
                     "grid_chi2": min(grid) if grid else None,
                     "chi2": None if fit is None else float(fit.misfit.chi2),
                     "status": None if fit is None else fit.status,
                     "seconds": time.perf_counter() - start})
        return fit

    fitting._grid_start, diagnosis._fit_group = recording_grid, recording_group
    start = time.perf_counter()
    d = diagnosis.diagnose(model, measured, **noise)
    total = time.perf_counter() - start
    done = [r for r in rows if r["chi2"] is not None]
    best = min(r["chi2"] for r in done)
    far = [r for r in done if r["chi2"] > args.factor * best]
    summary = {"case": args.case, "verdict": d.verdict, "suggested": d.suggested,
               "diagnose_seconds_serial": total, "fits": len(rows),
               "fit_seconds": sum(r["seconds"] for r in rows), "best_chi2": best,
               "factor": args.factor, "fits_far_above_best": len(far),
               "their_seconds": sum(r["seconds"] for r in far),
               "not_converged": sum(r["status"] == "not_converged" for r in rows),
               "not_converged_seconds": sum(r["seconds"] for r in rows
                                            if r["status"] == "not_converged")}
    summary["their_share_pct"] = 100 * summary["their_seconds"] / summary["fit_seconds"]
    if args.json:
        Path(args.json).write_text(json.dumps({"summary": summary, "fits": rows}, indent=1,
                                              default=float) + "\n")
    print(json.dumps(summary, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
