"""Speed and scale of gfe-opt, measured as ratios in one run; prints JSON.

    python scripts/bench.py [--max-elements 10000]

1. Generic-element equation-error update (nodal k_i, ∂k_i/∂x; 5 modes; translations at every
   node, noise-free, from a tapered reference on a twice finer mesh; default solver "auto")
   for N elements: wall time and peak resident memory (each N in a fresh process), and the
   log-log slope of time against N.
2. The same update divided by one sparse eigen solve (5 modes) of the same model, N = 2000,
   with the default solver (direct KKT, IPOPT when a constraint is active) and with IPOPT
   forced on every step.
3. Equation error by IPOPT (forced) and by the default solver, the cvxpy SDP and the
   output-error baseline at N = 50 and 200: time (best of 3 runs each) and parameter error.
4. Accuracy at scale: first five frequencies of the simply supported beam against the closed
   form at N = 10,000, and the parameter error of the update there, with the row weighting
   and the energy weighting.

Parameter errors are max |k_i / k_true - 1| over the interior nodes and over the middle 90 %
of the span (next to a pinned end the bending moment vanishes, k_i is barely determined and
the regularisation holds it at its initial value).
5. `gfe-opt diagnose` (with the generic-update realisation, as the command runs it) on the
   46-element demo beam with 5 modes, every candidate effect: wall time of the first diagnosis
   and of the check after the crack is added (best and all of 3 runs).

6. Cost with N (issue: within 10x the 46-element cost at 2000 elements, memory linear in N
   with a sensor at every node): `diagnose` and `update --add crack` on 46 and 2000 elements
   with 45 sensors, and `update --add crack` with a sensor at every node on 1000 and 2000
   elements, each in a fresh process (wall time, peak resident memory).

7. Fits (issue 22), ``--parts fits``: the issue's table measured three times side by side,
   each run in fresh processes: the fits' Jacobian from finite differences of the modal
   solves with IPOPT (``GFE_OPT_JACOBIAN=difference GFE_OPT_FIT_SOLVER=ipopt``, the first
   path), analytic (eigen-derivatives) with IPOPT (``GFE_OPT_FIT_SOLVER=ipopt``, the second)
   and analytic with the damped Newton steps alone (the default): ``diagnose`` on 46
   elements in process (best of 3, first and after adding the crack), from the shell
   (``gfe-opt diagnose --json``, wall, best of 3, a 46-element beam with a point mass), on
   2000 elements; ``update --add crack`` on 46 elements (best of 3); one set of a campaign
   (``batch --add material --add crack``, 2 workers, wall per set); ``gfe-opt --version``
   (best of 3); peak resident memory of each run.  Every fit (every candidate of every
   diagnosis, the updates, the demo's and the shipped real data's diagnoses, every batch
   row) is compared with the first path's: largest relative difference of the parameters,
   in σ, and of χ², over the fits both paths converged; a fit one path left short of its
   optimum (IPOPT at its iteration limit) is listed apart with both statuses and χ²
   (``fits_a_side_left_unconverged``): it measures that path's stopping, not its Jacobian.

8. Frames (issue 24), ``--parts frames``: ``diagnose`` (noise stated) on the shipped
   semi-rigid portal (60 elements) and on the three-storey frame (120 elements, 6 modes,
   36 sensors: x and y at two points a member) with a 0.3 kg floor mass, its data from the
   package's frame on a 3x finer mesh with 0.3 % / 0.05 % noise; each in a fresh process
   with every grid point solved (``GFE_OPT_SCREEN=0``) and with the grids screened in bulk
   (the default, :mod:`gfe_opt.screening`): wall time, verdicts and the largest relative
   difference of every fitted parameter (0 when the screen chose every grid's start as
   the full solves do).  Before the screen the two sides were IPOPT and the Newton steps
   (README, Plane frames).

9. The shapes' refinement (stop 69), ``--parts shapes``: the dense modal solve with and
   without its inverse-iteration step (:func:`gfe_opt.modal._inverse_iteration`), side by
   side in one process: one solve of a simply supported beam of 20, 46 and 200 elements
   (5 modes, best of 200 alternated runs each); one solve of the portal frame (10 modes,
   best of 50): LAPACK alone, the step by one dense LU a mode (before stop 73) and banded in
   a reverse Cuthill-McKee order (now); and the demo's serial ``diagnose`` (46 elements,
   best of 5 alternated runs), with its verdict and the crack found either way.

10. Dense or sparse (stop 77), ``--parts dense``: a beam's and a bar's modal solve (9
    modes) and its eigen-derivatives (9 modes, 4 parameters: four elements' stiffness) by
    LAPACK on the dense matrices and by the sparse route (shift-invert Lanczos; Nelson's
    form), side by side at each size (best of alternated runs, one BLAS thread), and the
    free DOFs from which the sparse route is the faster at every size measured.

11. The reduced step's solver (stop 79), ``--parts reduced``: the generic update's small
    problems (:func:`gfe_opt.updating._solve_reduced`) by IPOPT and by Clarabel
    (``updating.REDUCED_SOLVER``), side by side in one process, alternated: the semi-rigid
    portal's generic update (best of 3); the updates of its realisation's 12 noisy copies
    (the model's own modes and the finding's, as ``gfe-opt diagnose`` runs them: the
    copies taken from one diagnosis; serial, one BLAS thread; best of 2); the whole
    ``diagnose`` with the realisation on the portal (as the command runs it, in the pool;
    one run each); the 2 000-element beam's ``diagnose`` with the realisation (one run
    each).  Each row: time, reduced steps by solver and steps sent whole to IPOPT, and the
    largest difference of the updated parameters (relative to the largest) between the
    two; the diagnoses' verdicts and words.

``--parts`` runs a subset: update, ratio, solvers, accuracy, diagnose, scale, fits, frames,
shapes, dense, reduced (the default: all but shapes, dense and reduced).
"""

import argparse
import json
import multiprocessing as mp
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPEATS = 3


def _taper_problem(n):
    from gfe_opt.measured import make_measured
    from gfe_opt.model import load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import full_shapes_at_nodes, reference_with_rigidity

    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(n)
    ei0 = model.bending_rigidity

    def rigidity(x):
        return ei0 * (1 + 0.3 * x / model.length)

    reference = reference_with_rigidity(model, rigidity, 2 * n)
    freqs, shapes = full_shapes_at_nodes(reference, model, 5)
    measured = make_measured(model.nodes[1:-1], "w", freqs, shapes[2:-2:2], "taper")
    return model, measured, rigidity(model.nodes)


def _errors(q, truth):
    n = truth.size - 1
    e = np.abs(q[:n + 1] / truth - 1)
    return {"interior_k_error": float(np.max(e[1:-1])),
            "middle90_k_error": float(np.max(e[n // 20:n + 1 - n // 20]))}


def _update_run(n, queue, weighting="rows"):
    from gfe_opt.parameterisation import derive_nodal_coefficients
    from gfe_opt.updating import update_generic

    derive_nodal_coefficients()  # the one-off sympy derivation (~1 s) is not the update
    model, measured, truth = _taper_problem(n)
    start = time.perf_counter()
    result = update_generic(model, measured, noise=0.0, weighting=weighting)
    seconds = time.perf_counter() - start
    queue.put({"elements": n, "weighting": weighting, "seconds": seconds, "ok": result.ok,
               "steps": result.stats.get("steps"),
               "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
               **_errors(result.q, truth)})


def _in_process(n, weighting="rows"):
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_update_run, args=(n, queue, weighting))
    proc.start()
    row = queue.get()
    proc.join()
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-elements", type=int, default=10000)
    parser.add_argument("--parts",
                        default="update,ratio,solvers,accuracy,diagnose,scale,fits,frames")
    parser.add_argument("--fits-child", nargs=2, metavar=("SIDE", "DIR"),
                        help=argparse.SUPPRESS)
    parser.add_argument("--frames-child", choices=("every_point", "screened"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.fits_child:
        print(json.dumps(_fits_child(Path(args.fits_child[1]))))
        return
    if args.frames_child:
        print(json.dumps(_frames_child(args.frames_child)))
        return
    parts = set(args.parts.split(","))
    out = {}
    sizes = [n for n in (100, 300, 1000, 3000, 10000) if n <= args.max_elements]
    rows = [_in_process(n) for n in sizes] if "update" in parts else []
    if rows:
        slope = float(np.polyfit(np.log([r["elements"] for r in rows]),
                                 np.log([r["seconds"] for r in rows]), 1)[0])
        out["update_scaling"] = {"rows": rows, "loglog_slope": slope, "target": "<= 1.2"}
    if "ratio" in parts:
        _ratio(out)
    if "solvers" in parts:
        _solvers(out)
    if "accuracy" in parts:
        _accuracy(out, rows, sizes)
    if "diagnose" in parts:
        _diagnose(out)
    if "scale" in parts:
        _scale(out)
    if "fits" in parts:
        _fits(out)
    if "frames" in parts:
        _frames(out)
    if "shapes" in parts:
        _shapes(out)
    if "dense" in parts:
        _dense_or_sparse(out)
    if "reduced" in parts:
        _reduced(out)
    print(json.dumps(out, indent=1))


def _alternated(fns, repeats):
    """Best time of each of ``fns`` over ``repeats`` rounds, the functions run in turn (so
    that a change of the machine's speed falls on each alike), and each one's last result."""
    best, results = [np.inf] * len(fns), [None] * len(fns)
    for _ in range(repeats):
        for i, fn in enumerate(fns):
            start = time.perf_counter()
            results[i] = fn()
            best[i] = min(best[i], time.perf_counter() - start)
    return best, results


def _shapes(out):
    """Part 9 (module docstring)."""
    import gfe_opt.diagnosis as diagnosis
    import gfe_opt.modal as modal
    from gfe_opt.assembly import discretise
    from gfe_opt.measured import load_measured
    from gfe_opt.model import load_model, model_from_dict
    from gfe_opt.problems import problem_file

    sys.path.insert(0, str(ROOT))
    from tests.conftest import STEEL_BEAM

    refine = modal._inverse_iteration

    def side(refined, fn):
        def run():
            modal._inverse_iteration = refine if refined else (lambda A, B, lam, vec: vec)
            try:
                return fn()
            finally:
                modal._inverse_iteration = refine
        return run

    rows = []
    for n in (20, 46, 200):
        disc = discretise(model_from_dict({**STEEL_BEAM, "elements": n}, "bench"))
        K, M = disc.global_matrices()

        def solve(K=K, M=M, disc=disc):
            return modal.solve_modes(K, M, 5, disc.constrained, disc.eigenvalue_scale,
                                     dense=True, free=disc.free)
        (alone, refined), (a, b) = _alternated([side(False, solve), side(True, solve)], 200)
        rows.append({"elements": n, "lapack_alone_ms": 1e3 * alone,
                     "refined_ms": 1e3 * refined, "ratio": refined / alone,
                     "frequencies_rel_diff": float(np.max(np.abs(
                         b.frequencies_hz / a.frequencies_hz - 1)))})
    # a frame's pencil is not banded in its own order: the step solves it banded in a
    # reverse Cuthill-McKee order (stop 73), before that by one dense LU a mode
    portal = discretise(load_model(problem_file("portal-frame.toml"), frames=True))
    K, M = portal.global_matrices()

    def portal_solve():
        return modal.solve_modes(K, M, 10, portal.constrained, portal.eigenvalue_scale,
                                 dense=True, free=portal.free)

    def dense_lu():
        modal._inverse_iteration = lambda A, B, lam, vec: refine(A, B, lam, vec, False)
        try:
            return portal_solve()
        finally:
            modal._inverse_iteration = refine
    (alone, lu, banded), (a, b, c) = _alternated(
        [side(False, portal_solve), dense_lu, side(True, portal_solve)], 50)
    portal_row = {"free_dofs": int(portal.free.size), "lapack_alone_ms": 1e3 * alone,
                  "refined_dense_lu_ms": 1e3 * lu, "refined_banded_ms": 1e3 * banded,
                  "banded_over_dense_lu": banded / lu,
                  "shapes_banded_vs_dense_lu": float(np.max(np.abs(c.shapes - b.shapes))
                                                     / np.max(np.abs(b.shapes)))}
    model = load_model(problem_file("ss-steel-beam.toml"))
    demo = load_measured(problem_file("demo-measured.json"))
    serial, diagnosis.SERIAL_FITS = diagnosis.SERIAL_FITS, True
    try:
        def run():
            d = diagnosis.diagnose(model, demo, freq_noise=0.0005, shape_noise=0.003)
            found = d.together if d.together is not None else d.best
            return d.verdict, [(e.name, e.parameters) for e in found.effects]
        (alone, refined), (a, b) = _alternated([side(False, run), side(True, run)], 5)
    finally:
        diagnosis.SERIAL_FITS = serial
    out["shape_refinement"] = {
        "one_solve": rows, "portal_one_solve": portal_row,
        "demo_diagnose_serial": {"lapack_alone_s": alone, "refined_s": refined,
                                 "ratio": refined / alone, "lapack_alone": a, "refined": b}}


def _dense_or_sparse(out):
    """Part 10 (module docstring)."""
    import scipy.sparse as sparse

    import gfe_opt.modal as modal
    from gfe_opt.assembly import discretise
    from gfe_opt.model import model_from_dict
    from gfe_opt.sensitivity import eigen_derivatives
    from gfe_opt.threads import one_thread_limits

    sys.path.insert(0, str(ROOT))
    from tests.conftest import STEEL_BAR, STEEL_BEAM

    rows, first = [], {}
    for kind, base, sizes in (("beam", STEEL_BEAM, (20, 30, 46, 60, 64, 68, 72, 76, 80, 100, 150,
                                                     200)),
                              ("bar", STEEL_BAR, (20, 50, 100, 120, 140, 160, 180, 200, 400, 800,
                                                   1500))):
        for n in sizes:
            disc = discretise(model_from_dict({**base, "elements": n}, "bench"))
            K, M = disc.global_matrices()
            free = disc.free

            def solve(dense, K=K, M=M, disc=disc):
                return modal.solve_modes(K, M, 9, disc.constrained, disc.eigenvalue_scale,
                                         dense=dense, free=disc.free)
            repeats = 30 if free.size <= 400 else 5
            with one_thread_limits():
                (t_dense, t_sparse), (a, b) = _alternated(
                    [lambda: solve(True), lambda: solve(False)], repeats)
            lam = (2 * np.pi * a.frequencies_hz) ** 2
            # four elements' stiffness: each one's entries of K
            per = disc.dofs_per_node
            dK = []
            for e in np.linspace(1, n - 2, 4).astype(int):
                dofs = np.arange(e * per, (e + 2) * per)
                block = sparse.lil_matrix(K.shape)
                block[np.ix_(dofs, dofs)] = K[np.ix_(dofs, dofs)].toarray()
                dK.append(block.tocsr())
            dM = [sparse.csr_matrix(K.shape)] * len(dK)

            def derivatives(dense, K=K, M=M, free=free, lam=lam, a=a, dK=dK, dM=dM):
                return eigen_derivatives(K, M, free, lam, a.shapes, dK, dM, dense=dense)
            with one_thread_limits():
                (d_dense, d_sparse), (da, db) = _alternated(
                    [lambda: derivatives(True), lambda: derivatives(False)], repeats)
            scale = np.max(np.abs(da[1]))
            rows.append({"kind": kind, "elements": n, "free_dofs": int(free.size),
                         "solve_dense_ms": 1e3 * t_dense, "solve_sparse_ms": 1e3 * t_sparse,
                         "derivatives_dense_ms": 1e3 * d_dense,
                         "derivatives_sparse_ms": 1e3 * d_sparse,
                         "frequencies_rel_diff": float(np.max(np.abs(
                             b.frequencies_hz / a.frequencies_hz - 1))),
                         "shape_derivatives_rel_diff": float(
                             np.max(np.abs(db[1] - da[1])) / scale)})
    for kind in ("beam", "bar"):
        mine = [r for r in rows if r["kind"] == kind]
        for what in ("solve", "derivatives"):
            faster = [r[f"{what}_sparse_ms"] < r[f"{what}_dense_ms"] for r in mine]
            # the smallest size from which the sparse route is faster at every size measured
            at = next((r["free_dofs"] for i, r in enumerate(mine) if all(faster[i:])), None)
            first[f"{kind}_{what}"] = at
    out["dense_or_sparse"] = {"rows": rows, "sparse_faster_from_free_dofs": first}


def _reduced(out):
    """Part 11 (module docstring)."""
    from collections import Counter

    import gfe_opt.diagnosis as diagnosis
    import gfe_opt.updating as updating
    from gfe_opt.diagnosis import diagnose
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import portal_frame, problem_file
    from gfe_opt.structure import structure
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement
    from gfe_opt.threads import one_thread_limits

    portal = portal_frame()
    layout = structure(portal)
    measured, _, _ = layout.prepared(
        layout.load_measured(problem_file("portal-frame-semirigid.json")))
    noise = diagnosis.noise_of(None, None)
    tally, solve_step, chosen = Counter(), updating._solve_step, updating.REDUCED_SOLVER

    def counted(*args, **kwargs):
        step = solve_step(*args, **kwargs)
        info = step[0][2] or {}
        tally[step[2]] += 1
        tally.update(f"reduced by {s}" for s in info.get("reduced_solvers", []))
        return step

    updating._solve_step = counted
    copies, draw = [], diagnosis._draw

    def keep(model, data, noise_):   # the copies one diagnosis reads, to time them again
        copies.append((model, data, noise_))
        return draw(model, data, noise_)

    diagnosis._draw, serial = keep, diagnosis.SERIAL_FITS
    diagnosis.SERIAL_FITS = True
    try:
        diagnose(portal, layout.load_measured(problem_file("portal-frame-semirigid.json")),
                 realise=True)
    finally:
        diagnosis._draw, diagnosis.SERIAL_FITS = draw, serial
    beam = load_model(problem_file("ss-steel-beam.toml"))
    big = beam.with_elements(2000)
    truth = beam.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    big_measured = synthetic_measurement(truth.with_elements(2000), 5,
                                         interior_sensors(beam.length, 45), shape_noise=0.003,
                                         freq_noise=0.0005, seed=2002, reference_elements=4000)

    def side(solver):
        def run(fn):
            def timed():
                updating.REDUCED_SOLVER = solver
                tally.clear()
                result = fn()
                return result, dict(tally)
            return timed
        return run

    rows = {}
    solvers = ("ipopt", "clarabel")

    def ratios(results):
        return [None if r is None else np.asarray(r) for r in results]

    def compare(label, fn, repeats, read):
        best, results = _alternated([side(s)(fn) for s in solvers], repeats)
        values = [read(r[0]) for r in results]
        diff = None
        if all(v is not None for v in values):
            scale = max(float(np.nanmax(np.abs(values[0]))), 1e-300)   # (a failed draw: nan)
            diff = float(np.nanmax(np.abs(values[0] - values[1]))) / scale
        rows[label] = {**{f"{s}_s": round(b, 3) for s, b in zip(solvers, best)},
                       "speedup": round(best[0] / best[1], 2),
                       "steps": {s: r[1] for s, r in zip(solvers, results)},
                       "max_rel_difference": diff}
        return [r[0] for r in results]

    with one_thread_limits():
        compare("portal_generic_update", lambda: layout.generic_update(measured, noise), 3,
                lambda r: r.q)
        compare("portal_realisation_draws",
                lambda: [diagnosis._draw(*c) for c in copies], 2,
                lambda r: np.concatenate([np.full(1, np.nan) if d is None else d
                                          for d in ratios(r)]))
    for label, model, data, stated in (
            ("portal_diagnose", portal,
             layout.load_measured(problem_file("portal-frame-semirigid.json")), {}),
            ("diagnose_2000", big, big_measured,
             {"freq_noise": 0.0005, "shape_noise": 0.003})):
        done = compare(label, lambda m=model, d=data, k=stated: diagnose(m, d, realise=True,
                                                                         **k),
                       1, lambda r: None)
        rows[label]["steps"] = "in the pool's workers (not counted)"
        rows[label]["verdicts"] = [d.verdict for d in done]
        rows[label]["same_words"] = done[0].realisation == done[1].realisation
    updating._solve_step, updating.REDUCED_SOLVER = solve_step, chosen
    out["reduced"] = {"rows": rows, "copies": len(copies)}


def _ratio(out):
    from gfe_opt.modal import model_modes
    from gfe_opt.parameterisation import derive_nodal_coefficients
    from gfe_opt.updating import update_generic


    derive_nodal_coefficients()
    model, measured, truth = _taper_problem(2000)
    model_modes(model, 5)  # warm-up
    start = time.perf_counter()
    model_modes(model, 5)
    t_eig = time.perf_counter() - start
    ratio = {"eigensolve_s": t_eig, "target": "<= 20"}
    for solver in ("auto", "ipopt"):
        start = time.perf_counter()
        result = update_generic(model, measured, noise=0.0, solver=solver)
        seconds = time.perf_counter() - start
        ratio[solver] = {"update_s": seconds, "ratio": seconds / t_eig, "ok": result.ok,
                         "status": result.status, "steps": result.stats.get("steps")}
    out["update_over_eigensolve_N2000"] = ratio


def _solvers(out):
    from gfe_opt.output_error import update_output_error
    from gfe_opt.updating import update_generic, update_sdp

    def forced_ipopt(*args, **kwargs):
        return update_generic(*args, solver="ipopt", **kwargs)

    solvers = []
    for n in (50, 200):
        model, measured, truth = _taper_problem(n)
        for name, run, noise in (("ipopt", forced_ipopt, 0.0), ("auto", update_generic, 0.0),
                                 ("sdp", update_sdp, 0.0),
                                 ("output_error", update_output_error, 1e-4)):
            seconds = np.inf
            for _ in range(REPEATS):  # best of REPEATS: the fast solves are timer-noisy
                start = time.perf_counter()
                result = run(model, measured, noise=noise)
                seconds = min(seconds, time.perf_counter() - start)
            solvers.append({"elements": n, "method": name, "seconds": seconds,
                            "ok": result.ok, **_errors(result.q, truth)})
    by = {(r["elements"], r["method"]): r for r in solvers}
    oe = by[(200, "output_error")]["seconds"]
    out["solvers"] = {"rows": solvers,
                      "output_error_over_ipopt_time_N200": oe / by[(200, "ipopt")]["seconds"],
                      "output_error_over_auto_time_N200": oe / by[(200, "auto")]["seconds"],
                      "target": "ipopt >= 50x faster with equal or better accuracy"}


def _accuracy(out, rows, sizes):
    from gfe_opt.modal import model_modes
    from gfe_opt.model import load_model
    from gfe_opt.problems import problem_file

    big = load_model(problem_file("ss-steel-beam.toml")).with_elements(10000)
    exact = (np.arange(1, 6) * np.pi / big.length) ** 2 * np.sqrt(
        big.bending_rigidity / big.mass_per_length) / (2 * np.pi)
    f = model_modes(big, 5).frequencies_hz
    energy = _in_process(10000, "energy") if 10000 in sizes else None
    out["accuracy_N10000"] = {"max_rel_freq_error": float(np.max(np.abs(f / exact - 1))),
                              "target": "<= 1e-4",
                              "update_rows_weighting": next(
                                  (r for r in rows if r["elements"] == 10000), None),
                              "update_energy_weighting": energy}



def _diagnose(out):
    from gfe_opt.diagnosis import diagnose, update
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    model = load_model(problem_file("ss-steel-beam.toml"))
    truth = model.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    measured = synthetic_measurement(truth, 5, interior_sensors(model.length, 45),
                                     shape_noise=0.003, freq_noise=0.0005, seed=2002)
    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    updated = update(model, measured, ["crack"], **noise).model
    result = {}
    for label, m in (("first", model), ("after_adding_the_crack", updated)):
        runs = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            d = diagnose(m, measured, realise=True, **noise)
            runs.append(time.perf_counter() - start)
        result[label] = {"best_s": min(runs), "runs_s": runs, "verdict": d.verdict,
                         "candidates": len(d.fits) + len(d.failed)}
    out["diagnose_46_elements"] = {**result, "target": "first < 3 s"}


def _scale_run(n, sensors, what, queue):
    from gfe_opt.diagnosis import diagnose, update
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(n)
    truth = model.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    x = model.nodes[1:-1] if sensors == "every node" else interior_sensors(model.length, 45)
    measured = synthetic_measurement(truth, 5, x, shape_noise=0.003, freq_noise=0.0005,
                                     seed=2002, reference_elements=max(400, 2 * n))
    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    start = time.perf_counter()
    if what == "diagnose":
        result = diagnose(model, measured, realise=True, **noise).verdict
    else:
        result = update(model, measured, ["crack"], **noise).fit.describe()
    queue.put({"elements": n, "sensors": sensors, "command": what,
               "seconds": time.perf_counter() - start, "result": result,
               "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024})


def _scale(out):
    ctx = mp.get_context("spawn")
    rows = []
    for n, sensors, what in ((46, "45", "diagnose"), (2000, "45", "diagnose"),
                             (46, "45", "update"), (2000, "45", "update"),
                             (1000, "every node", "update"), (2000, "every node", "update")):
        queue = ctx.Queue()
        proc = ctx.Process(target=_scale_run, args=(n, sensors, what, queue))
        proc.start()
        rows.append(queue.get())
        proc.join()
    by = {(r["elements"], r["sensors"], r["command"]): r for r in rows}
    ratio = {what: by[(2000, "45", what)]["seconds"] / by[(46, "45", what)]["seconds"]
             for what in ("diagnose", "update")}
    out["scale"] = {"rows": rows, "ratio_2000_over_46": ratio, "target": "<= 10"}


# -------------------------------------------------------------------------------------------
# 7. fits: finite-difference and analytic Jacobians side by side
# -------------------------------------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[1]


def _fit_rows(label, fits):
    """(label/effect, parameters as a flat list, their σ, χ², its solver's status and
    whether it converged) of each fit."""
    rows = []
    for fit in fits:
        values, sigmas = [], []
        for effect, sigma in zip(fit.effects, fit.sigma):
            for key, v in effect.parameters.items():
                if not isinstance(v, str):
                    values += [float(x) for x in np.atleast_1d(v)]
                    s = sigma.get(key)
                    sigmas += ([float("nan")] * np.atleast_1d(v).size if s is None
                               else [float(x) for x in np.atleast_1d(s)])
        rows.append((f"{label}/{fit.name}", values, sigmas, float(fit.misfit.chi2),
                     str(fit.status), bool(fit.success)))
    return rows


def _diagnosis_rows(label, d):
    """Every fit of a diagnosis (the failed ones marked: a fit may converge on one path and
    not on the other)."""
    fits = list(d.fits) + ([d.together] if d.together is not None else [])
    return _fit_rows(label, fits) + [(f"{label}/{f.name} (failed)", [], [], float("nan"),
                                      str(f.status), bool(f.success)) for f in d.failed]


def _best_of(fn, repeats=REPEATS):
    runs, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        runs.append(time.perf_counter() - start)
    return min(runs), runs, result


def _fits_child(work: Path) -> dict:
    """One side of part 7 (the Jacobian and the solver chosen by GFE_OPT_JACOBIAN and
    GFE_OPT_FIT_SOLVER), in this process."""
    from gfe_opt import fitting
    from gfe_opt.batch import read_table, run_batch
    from gfe_opt.diagnosis import diagnose, update
    from gfe_opt.measured import load_measured
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    out, rows = {"jacobian": fitting.JACOBIAN, "solver": fitting.FIT_SOLVER}, []
    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    model = load_model(problem_file("ss-steel-beam.toml"))
    truth = model.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    measured = synthetic_measurement(truth, 5, interior_sensors(model.length, 45),
                                     shape_noise=0.003, freq_noise=0.0005, seed=2002)
    best, runs, upd = _best_of(lambda: update(model, measured, ["crack"], **noise))
    out["update_46"] = {"best_s": best, "runs_s": runs}
    rows += _fit_rows("update_46", [upd.fit])
    for label, m in (("diagnose_46", model), ("diagnose_46_after_crack", upd.model)):
        best, runs, d = _best_of(lambda m=m: diagnose(m, measured, realise=True, **noise))
        out[label] = {"best_s": best, "runs_s": runs, "verdict": d.verdict}
        rows += _diagnosis_rows(label, d)
    big = model.with_elements(2000)
    big_measured = synthetic_measurement(truth.with_elements(2000), 5,
                                         interior_sensors(model.length, 45),
                                         shape_noise=0.003, freq_noise=0.0005, seed=2002,
                                         reference_elements=4000)
    best, runs, d = _best_of(lambda: diagnose(big, big_measured, realise=True, **noise), 1)
    out["diagnose_2000"] = {"best_s": best, "verdict": d.verdict}
    rows += _diagnosis_rows("diagnose_2000", d)
    demo = load_measured(problem_file("demo-measured.json"))
    best, runs, d = _best_of(lambda: diagnose(model, demo, realise=True, **noise), 1)
    out["diagnose_demo"] = {"best_s": best, "verdict": d.verdict}
    rows += _diagnosis_rows("diagnose_demo", d)
    real_model = load_model(problem_file("hr-cantilever.toml"))
    real = load_measured(problem_file("hr-cantilever.csv"))
    best, runs, d = _best_of(lambda: diagnose(real_model, real, realise=True), 1)
    out["diagnose_real"] = {"best_s": best, "verdict": d.verdict}
    rows += _diagnosis_rows("diagnose_real", d)
    table = work / f"batch-{fitting.JACOBIAN}-{fitting.FIT_SOLVER}.csv"
    sets = sorted((work / "sets").glob("*.json"))
    start = time.perf_counter()
    run_batch(problem_file("ss-steel-beam.toml"), work / "sets", table,
              add=["material", "crack"], workers=2, force=True)
    out["batch_per_set"] = {"wall_s_per_set": (time.perf_counter() - start) / len(sets),
                            "sets": len(sets), "workers": 2}
    for row in read_table(table):
        values = [float(v) for k, v in sorted(row.items())
                  if k.endswith((".E", ".position", ".depth_ratio")) and v is not None]
        rows.append((f"batch/{row['file']}", values, [float("nan")] * len(values),
                     float(row["chi2_per_residual"]), "", True))
    shell = [sys.executable, "-m", "gfe_opt", "diagnose", str(work / "mass-model.toml"),
             str(work / "mass-measured.json"), "--json"]
    best, runs, _ = _best_of(lambda: subprocess.run(shell, capture_output=True, check=True))
    out["shell_diagnose_46"] = {"best_s": best, "runs_s": runs}
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    out["fits"] = rows
    return out


def _matched_fits(rows_a, rows_b):
    """The fit rows of two runs paired by label (and parameter count), and the labels of
    the rows without a namesake on the other side."""
    by_label = {row[0]: row for row in rows_b}
    pairs, alone = [], []
    for row in rows_a:
        other = by_label.pop(row[0], None)
        if other is None or len(other[1]) != len(row[1]):
            alone.append(row[0])
        else:
            pairs.append((row, other))
    return pairs, alone + sorted(by_label)


def _fits(out):
    with tempfile.TemporaryDirectory(prefix="gfe-bench-fits-") as tmp:   # (removed after)
        _fits_sides(out, Path(tmp))


def _fits_sides(out, work: Path):
    """Part 7's sides, each in a fresh process, in the folder ``work``."""
    from gfe_opt.measured import save_measured
    from gfe_opt.model import Effect, load_model, save_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    sys.path.insert(0, str(ROOT))
    from tests.truths import write_campaign

    model = load_model(problem_file("ss-steel-beam.toml"))
    write_campaign(model, work / "sets", 10, seed=3)
    save_model(model.with_effects([]), work / "mass-model.toml")
    mass = model.with_effects([Effect("point_mass", {"position": 0.41, "mass": 0.05})])
    save_measured(synthetic_measurement(mass, 5, interior_sensors(model.length, 45),
                                        shape_noise=0.003, freq_noise=0.0005, seed=5),
                  work / "mass-measured.json")
    sides = {}
    for side, (jacobian, solver) in FIT_SIDES.items():
        env = {**os.environ, "GFE_OPT_JACOBIAN": jacobian, "GFE_OPT_FIT_SOLVER": solver}
        run = subprocess.run([sys.executable, __file__, "--fits-child", side, str(work)],
                             capture_output=True, text=True, env=env, check=True)
        sides[side] = json.loads(run.stdout.strip().splitlines()[-1])
        print(f"fits ({side}): done", file=sys.stderr, flush=True)
    version = [sys.executable, "-m", "gfe_opt", "--version"]
    best, runs, _ = _best_of(lambda: subprocess.run(version, capture_output=True, check=True))
    first = sides["difference"]
    table = {}
    for key, goal in (("diagnose_46", 0.5), ("diagnose_46_after_crack", 0.5),
                      ("shell_diagnose_46", 1.2), ("diagnose_2000", 3.0), ("update_46", 0.1),
                      ("batch_per_set", 0.15)):
        field = "wall_s_per_set" if key == "batch_per_set" else "best_s"
        table[key] = {f"{side}_s": round(sides[side][key][field], 3) for side in sides}
        table[key].update(speedup=round(first[key][field] / sides["newton"][key][field], 2),
                          goal_s=goal)
    table["version_startup"] = {"best_s": round(best, 3), "goal_s": 0.3}
    out["fits"] = {"table": table, "sides": {k: {"jacobian": j, "solver": v}
                                             for k, (j, v) in FIT_SIDES.items()},
                   "target_parameters": 1e-6, "target_chi2": 1e-9,
                   "peak_rss_mb": {k: round(v["peak_rss_mb"], 1) for k, v in sides.items()}}
    for side in ("analytic", "newton"):
        out["fits"][f"{side}_against_difference"] = _fit_differences(first, sides[side])


#: the sides of part 7: name -> (GFE_OPT_JACOBIAN, GFE_OPT_FIT_SOLVER)
FIT_SIDES = {"difference": ("difference", "ipopt"), "analytic": ("analytic", "ipopt"),
             "newton": ("analytic", "newton")}


#: two ends of one fit whose χ² differ by more than this (relative; 1000 times the χ²
#: target of part 7) lie in different valleys: compared apart (:func:`_fit_differences`)
ENDS_APART = 1e-6


def _fit_differences(a, b) -> dict:
    """Every fit of side ``b`` against its namesake of side ``a``: the largest relative
    difference of the parameters, in σ (of ``a``), and of χ², over the fits both sides
    converged to one end (those a side left unconverged or ended in another valley listed
    apart, with both statuses and χ²); the verdicts."""
    worst_param, worst_sigma, worst_chi2, where = 0.0, 0.0, 0.0, None
    pairs, differ = _matched_fits(a["fits"], b["fits"])
    # a fit that one side left unconverged, or that the two sides ended in different
    # valleys (χ² apart by more than ENDS_APART: the real cantilever's section loss, 419
    # after IPOPT's iteration limit against 309), measures the paths' stopping, not their
    # Jacobians: listed apart, with both ends (rows of failed fits carry no parameters)
    def apart(ra, rb):
        return bool(ra[1]) and (not (ra[5] and rb[5]) or abs(ra[3] - rb[3]) > ENDS_APART
                                * max(abs(ra[3]), abs(rb[3]), 1e-300))

    short = [{"fit": ra[0], "status": [ra[4], rb[4]], "chi2": [ra[3], rb[3]]}
             for ra, rb in pairs if apart(ra, rb)]
    pairs = [(ra, rb) for ra, rb in pairs if not apart(ra, rb)]
    for (label, va, sa, ca, *_), (_, vb, _, cb, *_) in pairs:
        for x, y, s in zip(va, vb, sa):
            rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
            if rel > worst_param:
                worst_param, where = rel, label
            if np.isfinite(s) and s > 0:
                worst_sigma = max(worst_sigma, abs(x - y) / s)
        if np.isfinite(ca) and np.isfinite(cb):
            worst_chi2 = max(worst_chi2, abs(ca - cb) / max(abs(ca), abs(cb), 1e-300))
    return {"fits_compared": len(pairs), "fits_on_one_side_only": differ,
            "fits_ended_apart": short,
            "max_parameter_rel_difference": worst_param, "worst_fit": where,
            "max_parameter_difference_in_sigma": worst_sigma,
            "max_chi2_rel_difference": worst_chi2,
            "verdicts": {k: (a[k].get("verdict"), b[k].get("verdict"))
                         for k in a if isinstance(a[k], dict) and "verdict" in a[k]}}


def _storey_measured(model):
    """Three-storey frame data: a 0.3 kg mass at 0.2 m along floor-2, the package's frame on
    a 3x finer mesh, x and y at 0.33 and 0.71 of every member, 0.3 % / 0.05 % noise."""
    from dataclasses import replace

    from gfe_opt.frame import frame_mesh, frame_modes
    from gfe_opt.frame_data import frame_measured_from_dict, observation
    from gfe_opt.model import Effect

    fine = replace(model, members=tuple(replace(m, elements=3 * m.elements)
                                        for m in model.members))
    truth = fine.with_effects([Effect("point_mass", {"member": "floor-2", "position": 0.2,
                                                     "mass": 0.3})], check=False)
    modes = frame_modes(truth, 6)
    sensors = [{"member": m.id, "position": round(t * model.member_length(m), 4),
                "direction": d} for m in model.members for t in (0.33, 0.71)
               for d in ("x", "y")]
    shapes = observation(truth, frame_mesh(truth), sensors) @ modes.shapes
    rng = np.random.default_rng(1)
    return frame_measured_from_dict({"sensors": sensors, "modes": [
        {"frequency": float(f * (1 + 5e-4 * rng.standard_normal())),
         "shape": [float(v) for v in y + 0.003 * np.abs(y).max() * rng.standard_normal(y.size)]}
        for f, y in zip(modes.frequencies_hz, shapes.T)]}, model, "three-storey")


def _frames_child(side: str) -> dict:
    """One side of part 8 (grids screened or not, by GFE_OPT_SCREEN), in this process."""
    from gfe_opt.diagnosis import diagnose
    from gfe_opt.frame_data import load_frame_measured
    from gfe_opt.problems import portal_frame, problem_file, three_storey_frame

    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    out, rows = {}, []
    portal = portal_frame()
    storey = three_storey_frame()
    for label, model, measured in (
            ("portal_semirigid", portal,
             load_frame_measured(problem_file("portal-frame-semirigid.json"), portal)),
            ("three_storey_floor_mass", storey, _storey_measured(storey))):
        best, _, d = _best_of(lambda m=model, x=measured: diagnose(m, x, **noise), 1)
        found = d.together if d.together is not None else d.best
        out[label] = {"seconds": best, "verdict": d.verdict, "suggested": d.suggested,
                      "found": None if found is None else [
                          {"effect": e.name, **{k: v for k, v in e.parameters.items()}}
                          for e in found.effects]}
        rows += _diagnosis_rows(label, d)
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    out["fits"] = [(f"{r[0]} #{i}", *r[1:]) for i, r in enumerate(rows)]   # one name a fit
    return out


def _frames(out):
    sides = {}
    for side, screen in (("every_point", "0"), ("screened", "1")):
        env = {**os.environ, "GFE_OPT_SCREEN": screen}
        run = subprocess.run([sys.executable, __file__, "--frames-child", side],
                             capture_output=True, text=True, env=env, check=True)
        sides[side] = json.loads(run.stdout.strip().splitlines()[-1])
        print(f"frames ({side}): done", file=sys.stderr, flush=True)
    a, b = sides["every_point"], sides["screened"]
    worst = 0.0
    pairs, differ = _matched_fits(a["fits"], b["fits"])
    for (_, va, *_), (_, vb, *_) in pairs:
        for x, y in zip(va, vb):
            worst = max(worst, abs(x - y) / max(abs(x), abs(y), 1e-300))
    table = {key: {"every_point_s": round(a[key]["seconds"], 2),
                   "screened_s": round(b[key]["seconds"], 2),
                   "speedup": round(a[key]["seconds"] / b[key]["seconds"], 2),
                   "verdicts": [a[key]["verdict"], b[key]["verdict"]],
                   "found": b[key]["found"], "found_every_point": a[key]["found"]}
             for key in ("portal_semirigid", "three_storey_floor_mass")}
    table["three_storey_floor_mass"]["goal_s"] = 5.0
    out["frames"] = {"table": table, "max_parameter_rel_difference": worst,
                     "fits_on_one_side_only": differ,
                     "peak_rss_mb": {"every_point": round(a["peak_rss_mb"], 1),
                                     "screened": round(b["peak_rss_mb"], 1)}}


if __name__ == "__main__":
    main()
