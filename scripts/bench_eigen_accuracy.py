"""Eigenvalue accuracy on fine meshes: raw shift-invert eigenvalues against what gfe-opt
reports (direct route up to 200 elements, condensed super-elements above; module docstring
of gfe_opt.modal), for the simply supported, clamped and cantilever steel beams, first five
modes, against the closed forms; and the refusal above the verified ceiling.

Prints JSON: per support and mesh, the largest relative frequency error of each and the wall
time of gfe-opt's modal solve.

    python scripts/bench_eigen_accuracy.py [--max-elements 30000]
"""

import argparse
import json
import time
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from gfe_opt.assembly import discretise
from gfe_opt.errors import GfeInputError, GfeSolverError
from gfe_opt.modal import MAX_BEAM_ELEMENTS, discretisation_modes, solve_modes
from gfe_opt.model import load_model
from gfe_opt.problems import problem_file


def _roots(f, count):
    grid = np.linspace(0.1, 4 * count + 4, 4000)
    vals = f(grid)
    idx = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[:count]
    return np.array([brentq(f, grid[i], grid[i + 1]) for i in idx])


SUPPORTS = {
    "simply supported": (("pinned", "pinned"), np.arange(1, 6) * np.pi),
    "clamped": (("clamped", "clamped"), _roots(lambda b: np.cos(b) * np.cosh(b) - 1, 5)),
    "cantilever": (("clamped", "free"), _roots(lambda b: np.cos(b) * np.cosh(b) + 1, 5)),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-elements", type=int, default=MAX_BEAM_ELEMENTS)
    args = parser.parse_args()
    base = load_model(problem_file("ss-steel-beam.toml"))
    rows = []
    sizes = [n for n in (100, 1000, 3000, 10000, 20000, 30000) if n <= args.max_elements]
    for name, (supports, beta_l) in SUPPORTS.items():
        for n in sizes:
            model = replace(base.with_elements(n), supports=supports)
            exact = (beta_l / model.length) ** 2 * np.sqrt(
                model.bending_rigidity / model.mass_per_length) / (2 * np.pi)
            disc = discretise(model)
            K, M = disc.global_matrices()
            try:
                raw = solve_modes(K, M, 5, disc.constrained, disc.eigenvalue_scale)
                raw_error = float(np.max(np.abs(raw.frequencies_hz / exact - 1)))
            except GfeSolverError as exc:
                raw_error = f"failed: {exc}"
            start = time.perf_counter()
            f = discretisation_modes(disc, 5).frequencies_hz
            seconds = time.perf_counter() - start
            rows.append({"supports": name, "elements": n,
                         "raw_shift_invert_max_rel_error": raw_error,
                         "gfe_opt_max_rel_error": float(np.max(np.abs(f / exact - 1))),
                         "modal_solve_seconds": round(seconds, 4)})
    try:
        discretisation_modes(discretise(base.with_elements(MAX_BEAM_ELEMENTS + 1)), 5)
        refusal = "not refused"
    except GfeInputError as exc:
        refusal = str(exc)
    print(json.dumps({"rows": rows, "above_ceiling": refusal}, indent=1))


if __name__ == "__main__":
    main()
