"""Solver comparison on the named problems: IPOPT equation error, the cvxpy SDP variant and
the classic output-error approach (eigen-sensitivities + scipy least_squares).

    python scripts/compare_solvers.py

Prints a table and then JSON: wall time, iterations (IPOPT iterations; least-squares
function evaluations, each an eigen solve), parameter error against the truth mapped onto
the same mesh (rms of k_ww over the elements, relative) and the rms frequency error of the
updated model against the measurement (%).
"""

import json

import numpy as np

from gfe_opt.assembly import discretise
from gfe_opt.modal import discretisation_modes
from gfe_opt.model import Effect
from gfe_opt.output_error import update_output_error
from gfe_opt.problems import christides_barr_problem, tapered_beam_problem
from gfe_opt.synthetic import reference_with_rigidity
from gfe_opt.updating import cross_check, update_generic, update_sdp


def _true_k_ww(problem):
    """The truth in the generic parameters of the problem's own mesh."""
    model = problem.model
    if "crack" in problem.truth:
        return discretise(model.with_effects([Effect("crack", problem.truth["crack"])])
                          ).stiffness_params["k_ww"]
    k, slope = np.split(problem.truth["nodal"], 2)
    ei0 = k[0]
    taper = slope[0] * model.length / ei0
    ref = reference_with_rigidity(model, lambda x: ei0 * (1 + taper * x / model.length),
                                  model.elements)
    return ref.stiffness_params["k_ww"]


def main():
    problems = {
        "tapered-beam (all DOFs, 4 modes)": (tapered_beam_problem(), 0.0),
        "christides-barr (translations, 1 mode, 0.5 % noise)":
            (christides_barr_problem(noise=0.005, seed=1), 0.005),
        "christides-barr (translations, 3 modes, 0.5 % noise)":
            (christides_barr_problem(noise=0.005, n_modes=3, seed=1), 0.005),
    }
    rows, checks = [], []
    for label, (problem, noise) in problems.items():
        full = {"full_shapes": problem.full_shapes} if problem.full_shapes is not None else {}
        truth = _true_k_ww(problem)
        runs = {
            "ipopt equation error": lambda p=problem, f=full, n=noise: update_generic(
                p.model, p.measured, noise=max(n, 1e-4), solver="ipopt", **f),
            "equation error (auto: direct KKT)": lambda p=problem, f=full, n=noise:
                update_generic(p.model, p.measured, noise=max(n, 1e-4), **f),
            "cvxpy SDP (one convex step)": lambda p=problem, f=full, n=noise: update_sdp(
                p.model, p.measured, noise=max(n, 1e-4), **f),
            "output error (least_squares)": lambda p=problem, n=noise: update_output_error(
                p.model, p.measured, noise=max(n, 1e-4)),
        }
        same_step = update_generic(problem.model, problem.measured, noise=max(noise, 1e-4),
                                   refinements=0, solver="ipopt", **full)
        check = cross_check(same_step, runs["cvxpy SDP (one convex step)"]())
        checks.append({"problem": label, **check})
        for method, run in runs.items():
            result = run()
            k_ww = result.element_parameters["k_ww"]
            f = discretisation_modes(result.discretisation,
                                     problem.measured.n_modes).frequencies_hz
            rows.append({
                "problem": label, "method": method, "ok": result.ok,
                "seconds": round(result.seconds, 3),
                "iterations": result.stats.get("iter_count"),
                "parameter_error_rms": float(np.sqrt(np.mean((k_ww / truth - 1) ** 2))),
                "freq_error_rms_pct": float(100 * np.sqrt(np.mean(
                    (f / problem.measured.frequencies_hz - 1) ** 2))),
            })
    header = f"{'problem':54} {'method':33} {'ok':>3} {'time s':>7} {'iter':>5} " \
             f"{'param err':>9} {'f err %':>8}"
    print(header)
    for r in rows:
        print(f"{r['problem']:54} {r['method']:33} {'yes' if r['ok'] else 'NO':>3} "
              f"{r['seconds']:7.3f} {r['iterations']!s:>5} {r['parameter_error_rms']:9.4f} "
              f"{r['freq_error_rms_pct']:8.4f}")
    print("\nIPOPT (one convex step) against the SDP on the same data:")
    for c in checks:
        print(f"  {c['problem']:54} agree={c['agree']} parameters {c['parameter_difference']:.1e}"
              f" objective {c['objective_difference']:.1e} active ipopt {c['active_ipopt']}"
              f" sdp {c['active_sdp']}")
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
