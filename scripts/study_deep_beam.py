"""Deep beams on fine meshes: the modal route a shear beam takes and what its loop costs
(``python scripts/study_deep_beam.py``).

* ``route``: simply supported Timoshenko beams (κGA = 5/6 G A, rotary inertia) of L/h 12,
  40 and 100, 6 and 10 modes, at 200 to 8 000 elements: the route
  :func:`gfe_opt.modal.discretisation_modes` takes (``d`` direct, ``c`` condensed; stop 81:
  a shear beam of 201 to ``SHEAR_DIRECT_ELEMENTS`` elements is condensed only where its
  pencil is conditioned worse than the Euler–Bernoulli beam's at ``CONDENSE_ABOVE``
  elements, ``DIRECT_CONDITIONING``; a longer one always), its
  conditioning over that limit, the largest relative frequency error against the closed
  form (``tests/reference.py``: not the package's elements) and the solve's time.
* ``smooth``: how rough each route leaves a fit's χ² (what chose
  ``SHEAR_DIRECT_ELEMENTS``): χ² along κGA (±1e-3 in 11 steps around the fitted value) of a
  shear model of the ``ss-steel-beam`` data (5 modes, 45 sensors, a crack of a/d 0.5 at
  0.19 m from a 4 000-element reference; ``scripts/bench.py``'s 2 000-element data) at
  300 to 1 000 elements, direct against condensed (forced): the spread of its second
  differences over their mean.
* ``loop``: the campaign's continuum case ``--seed`` (``tests/truths.py``: a 2-D
  plane-stress beam, scikit-fem) with its model at ``--elements``: the loop a user runs
  (:func:`gfe_opt.diagnosis.diagnose`, then :func:`gfe_opt.diagnosis.follow`), timed, in
  process (the fits use both cores).

Measured (stop 81, this machine): see the README's Modal analysis paragraph.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gfe_opt.assembly import discretise  # noqa: E402
from gfe_opt.modal import (  # noqa: E402
    DIRECT_CONDITIONING,
    condensed,
    discretisation_modes,
    pencil_conditioning,
)
from gfe_opt.model import Effect  # noqa: E402


def route(sizes) -> None:
    from tests.conftest import make_model
    from tests.reference import timoshenko_ss

    length = 0.575
    for slenderness in (12, 40, 100):
        model = make_model(section={"b": 0.02, "h": length / slenderness})
        kga = 5 / 6 * model.E / (2 * (1 + model.nu)) * model.area
        model = model.with_effects([Effect("shear", {"shear_rigidity": kga})])
        for n_modes in (6, 10):
            exact = timoshenko_ss(n_modes, model.bending_rigidity, model.mass_per_length,
                                  model.rho * model.inertia, kga, length)
            cells = []
            for n in sizes:
                disc = discretise(model.with_elements(n))
                K, M = disc.global_matrices()
                ratio = pencil_conditioning(disc, K, M) / DIRECT_CONDITIONING
                start = time.perf_counter()
                f = discretisation_modes(disc, n_modes).frequencies_hz
                seconds = time.perf_counter() - start
                cells.append(f"{n}{'c' if condensed(disc) else 'd'} {ratio:.2g} "
                             f"{np.max(np.abs(f / exact - 1)):.1e} {seconds * 1e3:.0f}ms")
            print(f"L/h {slenderness}, {n_modes} modes: " + " | ".join(cells), flush=True)


def smooth(sizes) -> None:
    from gfe_opt import fitting, modal
    from gfe_opt.model import load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    model = load_model(problem_file("ss-steel-beam.toml"))
    truth = model.with_effects([Effect("crack", {"position": 0.19, "depth_ratio": 0.5})])
    measured = synthetic_measurement(truth.with_elements(2000), 5,
                                     interior_sensors(model.length, 45), shape_noise=0.003,
                                     freq_noise=0.0005, seed=2002, reference_elements=4000)
    noise = fitting.noise_of(0.0005, 0.003)
    limit = modal.DIRECT_CONDITIONING, modal.SHEAR_DIRECT_ELEMENTS
    try:
        for n in sizes:
            cells = []
            for route, (conditioning, elements) in (("direct", (np.inf, n)),
                                                    ("condensed", (0.0, 0))):
                modal.DIRECT_CONDITIONING, modal.SHEAR_DIRECT_ELEMENTS = conditioning, elements
                chi2 = []
                for t in np.linspace(-1e-3, 1e-3, 11):
                    shear = Effect("shear", {"shear_rigidity": 4.9243e7 * (1 + t)})
                    point = fitting.evaluate(model.with_elements(n).with_effects([shear]),
                                             measured, noise)
                    chi2.append(float(point.r @ point.r))
                second = np.diff(chi2, 2)
                cells.append(f"{route} {np.ptp(second) / abs(second.mean()):.2%}")
            print(f"{n} elements: " + " | ".join(cells), flush=True)
    finally:
        modal.DIRECT_CONDITIONING, modal.SHEAR_DIRECT_ELEMENTS = limit


def loop(seed: int, elements: int) -> None:
    from gfe_opt.diagnosis import diagnose, follow
    from gfe_opt.measured import make_measured
    from gfe_opt.model import model_from_dict
    from tests.truths import continuum_case

    case = continuum_case(seed)
    model = model_from_dict({**case.model, "elements": elements}, case.name)
    measured = make_measured(case.x, "w", case.frequencies, case.shapes, case.name)
    noise = ({"freq_noise": case.stated[0], "shape_noise": case.stated[1]}
             if case.stated else {})
    print(f"{case.name} at {elements} elements; hidden: {case.hidden}", flush=True)
    start = time.perf_counter()
    first = diagnose(model, measured, **noise)
    print(f"first diagnosis {time.perf_counter() - start:.1f} s: {first.verdict}", flush=True)
    start = time.perf_counter()
    done = follow(model, measured, first, **noise)
    print(f"the loop after it {time.perf_counter() - start:.1f} s: verdicts "
          f"{done.verdicts}, added {done.added}")
    for effect in done.model.effects:
        print("  ", effect.name, {k: (round(v, 6) if isinstance(v, float) else v)
                                  for k, v in effect.parameters.items()})
    print(f"final χ²/n {done.diagnosis.current.chi2_per_residual:.3g}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--parts", nargs="*", default=["route", "smooth", "loop"],
                        choices=["route", "smooth", "loop"])
    parser.add_argument("--smooth-sizes", type=int, nargs="*",
                        default=[300, 400, 600, 800, 1000])
    parser.add_argument("--sizes", type=int, nargs="*",
                        default=[200, 400, 1000, 2000, 4000, 8000])
    parser.add_argument("--seed", type=int, default=3004, help="the continuum case")
    parser.add_argument("--elements", type=int, default=400, help="the loop's model")
    args = parser.parse_args(argv)
    if "route" in args.parts:
        route(args.sizes)
    if "smooth" in args.parts:
        smooth(args.smooth_sizes)
    if "loop" in args.parts:
        loop(args.seed, args.elements)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
