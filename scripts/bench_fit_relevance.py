"""Where a diagnosis spends its fits: each candidate's fit a member (a frame's group of
starts, a beam's one) timed, with the best χ² of its grid, its final χ² and status, and the
share of the time spent on fits that end far above the best fit of the diagnosis.

    python scripts/bench_fit_relevance.py [--case storey|portal|beam] [--factor 100] [--json out]
    python scripts/bench_fit_relevance.py --campaign frame|beam [--seed S] [--cases N] [--json out]

``storey``: ``scripts/bench.py``'s three-storey frame with a 0.3 kg floor mass (36 sensors,
6 modes); ``portal``: the shipped semi-rigid portal's test; ``beam``: the 46-element demo
beam with a crack (45 sensors, 5 modes).  The fits run one after another (one core, one
BLAS thread): the times add up to the serial cost.  A measurement, not a rule: a fit that
ends at ``--factor`` times the best χ² cannot change the verdict, but which fits may be cut
short, and when, is for a campaign to judge.

Each Newton finish of a fit (:func:`gfe_opt.fitting._finish`; a fit may finish several
starts) is followed step by step: its χ² after 1, 2, 3, 5 and 8 Jacobians (the lowest χ² it
had evaluated by then: a step is taken only where χ² falls) and at its end.  With
``--campaign`` the first diagnosis of each generated case of the frame campaign
(``bench_frame_diagnosis.make_case``, ``--cases`` a class) or of the beam campaign
(``truths.campaign(seed, subset)``, ``--cases`` its subset) is followed so, and the summary
tries the rule "after k Jacobians, cut a finish whose χ² is above F times the lowest any
finish of the same diagnosis had after k" (yardstick ``lowest_then``), and the same against
the diagnosis's best final χ² (``best_end``, the most a rule could know): the Jacobians it
would save, and the cut finishes that would have ended within ``--factor`` of the
diagnosis's best fit (the contenders a rule must never cut)."""

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

import numpy as np  # noqa: E402

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


#: the Jacobian counts after which a finish's χ² is recorded
AFTER = (1, 2, 3, 5, 8)


class _Followed:
    """A finish's residual, as :func:`gfe_opt.fitting._finish` calls it, with the lowest
    χ² evaluated so far after each Jacobian count (the rest delegated to the residual)."""

    def __init__(self, residual, count):
        self._residual, self._count, self._start = residual, count, count[0]
        self.lowest = np.inf
        self.at = {}

    def __call__(self, z):
        r = self._residual(z)
        value = float(r @ r)
        if np.isfinite(value):
            self.lowest = min(self.lowest, value)
        self.at[self._count[0] - self._start] = self.lowest
        return r

    def __getattr__(self, name):
        return getattr(self._residual, name)

    def after(self, k: int) -> float:
        """The lowest χ² evaluated before the (k+1)-th Jacobian (the end's, if it ended
        sooner)."""
        seen = [v for j, v in self.at.items() if j <= k]
        return min(seen) if seen else np.inf


def _followed_finishes(run):
    """Run ``run()`` with every finish followed: returns its result and the finishes,
    each {"after": {k: χ²}, "end": χ², "jacobians": n}."""
    finish, jacobian = fitting._finish, fitting._jacobian
    count, finishes = [0], []

    def counted(*args, **kwargs):
        count[0] += 1
        return jacobian(*args, **kwargs)

    def followed(residual, z, value, lower, upper, *args, **kwargs):
        start = count[0]
        proxy = _Followed(residual, count)
        out = finish(proxy, z, value, lower, upper, *args, **kwargs)
        finishes.append({"after": {k: proxy.after(k) for k in AFTER}, "end": float(out[1]),
                         "jacobians": count[0] - start})
        return out

    fitting._finish, fitting._jacobian = followed, counted
    try:
        return run(), finishes
    finally:
        fitting._finish, fitting._jacobian = finish, jacobian


def _campaign_cases(kind: str, seed: int, cases: int):
    """(name, model, measured, noise) of the campaign's generated cases."""
    if kind == "frame":
        import bench_frame_diagnosis as frames

        for s, group in frames.case_seeds(seed, cases):
            case = frames.make_case(s, group)
            yield case["name"], case["model"], case["measured"], case["noise"]
        return
    from bench_diagnosis import make_measured, model_from_dict

    from tests import truths

    for case in truths.campaign(seed, cases):
        model = model_from_dict(case.model, case.name)
        x = [] if case.shapes is None else case.x
        measured = make_measured(x, "w", case.frequencies, case.shapes, case.name)
        noise = ({"freq_noise": case.stated[0], "shape_noise": case.stated[1]}
                 if case.stated else {})
        yield case.name, model, measured, noise


def _rules(diagnoses, factor: float, yardstick: str = "lowest_then") -> list:
    """The rule "after k Jacobians cut a finish above F times the diagnosis's yardstick"
    tried on the followed finishes of every diagnosis: per (k, F), the finishes cut, the
    Jacobians saved, and the cut ones that would have ended within ``factor`` of the
    diagnosis's best final χ².  ``yardstick``: ``"lowest_then"`` the lowest χ² any finish
    had after k Jacobians (what a diagnosis running its finishes side by side knows), or
    ``"best_end"`` the best final χ² (the most any rule could know)."""
    out = []
    for k in AFTER:
        for F in (10.0, 100.0, 1000.0):
            cut = saved = harmful = 0
            worst = []
            for d in diagnoses:
                finishes = d["finishes"]
                if not finishes:
                    continue
                best_end = min(f["end"] for f in finishes)
                lowest_k = (min(f["after"][k] for f in finishes) if yardstick == "lowest_then"
                            else best_end)
                for f in finishes:
                    if f["jacobians"] > k and f["after"][k] > F * lowest_k:
                        cut += 1
                        saved += f["jacobians"] - k
                        if f["end"] <= factor * best_end:
                            harmful += 1
                            worst.append((d["name"], f["after"][k] / lowest_k,
                                          f["end"] / best_end))
            total = sum(f["jacobians"] for d in diagnoses for f in d["finishes"])
            out.append({"yardstick": yardstick, "after_jacobians": k, "F": F,
                        "finishes_cut": cut,
                        "jacobians_saved": saved, "jacobians_total": total,
                        "cut_contenders": harmful, "contenders": worst[:5]})
    return out


def _campaign(args) -> int:
    diagnosis.SERIAL_FITS = True
    diagnoses = []
    seed = args.seed if args.seed is not None else {"frame": 3100, "beam": 2100}[args.campaign]
    for name, model, measured, noise in _campaign_cases(args.campaign, seed, args.cases):
        start = time.perf_counter()
        d, finishes = _followed_finishes(
            lambda m=model, x=measured, n=noise: diagnosis.diagnose(m, x, **n))
        diagnoses.append({"name": name, "verdict": d.verdict, "finishes": finishes,
                          "seconds": time.perf_counter() - start})
        print(f"[{len(diagnoses)}] {name}: {d.verdict}, {len(finishes)} finishes, "
              f"{sum(f['jacobians'] for f in finishes)} Jacobians "
              f"({diagnoses[-1]['seconds']:.1f} s)", file=sys.stderr, flush=True)
    rules = _rules(diagnoses, args.factor) + _rules(diagnoses, args.factor, "best_end")
    if args.json:
        Path(args.json).write_text(json.dumps({"campaign": args.campaign, "seed": seed,
                                               "diagnoses": diagnoses, "rules": rules},
                                              indent=1, default=float) + "\n")
    print(f"{'yardstick':>11} {'k':>3} {'F':>6} {'cut':>6} {'saved':>7} {'of':>7} "
          f"{'contenders cut':>15}")
    for r in rules:
        print(f"{r['yardstick']:>11} {r['after_jacobians']:3d} {r['F']:6g} "
              f"{r['finishes_cut']:6d} {r['jacobians_saved']:7d} {r['jacobians_total']:7d} "
              f"{r['cut_contenders']:15d}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=("storey", "portal", "beam"), default="storey")
    ap.add_argument("--factor", type=float, default=100.0)
    ap.add_argument("--json", help="write the rows and the summary to this file too")
    ap.add_argument("--campaign", choices=("frame", "beam"),
                    help="follow the finishes of a campaign's first diagnoses instead")
    ap.add_argument("--seed", type=int, help="the campaign's seed (frame 3100, beam 2100)")
    ap.add_argument("--cases", type=int, default=1,
                    help="frame: cases a class; beam: every N-th case (truths.campaign)")
    args = ap.parse_args(argv)
    if args.campaign:
        return _campaign(args)
    model, measured, noise = _case(args.case)
    diagnosis.SERIAL_FITS = True
    grid_start, fit_group = fitting._grid_start, diagnosis._fit_group
    grid = []

    def recording_grid(chi2, grids, nulls=None, bulk=None, **kwargs):
        def seen(z):
            value = chi2(z)
            grid.append(value)
            return value

        def seen_in_bulk(zs, null):   # a screened grid's values (its best ones exact)
            values = bulk(zs, null)
            if values is not None:
                grid.extend(values)
            return values
        return grid_start(seen, grids, nulls, None if bulk is None else seen_in_bulk,
                          **kwargs)

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
