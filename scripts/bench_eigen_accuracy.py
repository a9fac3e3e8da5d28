"""Eigenvalue accuracy on fine meshes: raw shift-invert eigenvalues against the element-wise
Rayleigh quotient that gfe-opt reports (simply supported steel beam, first five modes).

Prints JSON: per mesh, the largest relative frequency error of each against the closed form
and the wall time of the modal solve.

    python scripts/bench_eigen_accuracy.py
"""

import json
import time

import numpy as np

from gfe_opt.assembly import discretise
from gfe_opt.modal import discretisation_modes, solve_modes
from gfe_opt.model import load_model
from gfe_opt.problems import problem_file


def main():
    base = load_model(problem_file("ss-steel-beam.toml"))
    rows = []
    for n in (100, 300, 1000, 3000, 10000):
        model = base.with_elements(n)
        exact = (np.arange(1, 6) * np.pi / model.length) ** 2 * np.sqrt(
            model.bending_rigidity / model.mass_per_length) / (2 * np.pi)
        disc = discretise(model)
        K, M = disc.global_matrices()
        raw = solve_modes(K, M, 5, disc.constrained, disc.eigenvalue_scale).frequencies_hz
        start = time.perf_counter()
        refined = discretisation_modes(disc, 5).frequencies_hz
        seconds = time.perf_counter() - start
        rows.append({"elements": n,
                     "raw_shift_invert_max_rel_error": float(np.max(np.abs(raw / exact - 1))),
                     "gfe_opt_max_rel_error": float(np.max(np.abs(refined / exact - 1))),
                     "modal_solve_seconds": round(seconds, 4)})
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
