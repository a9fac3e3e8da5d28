"""Named updating problems (installed as ``gfe_opt.problems``).

Each factory states the physics and the known answer; its measured modes come from an
independent fine reference (:mod:`gfe_opt.synthetic`), never from the model being updated.
Model files live beside this module (``ss-steel-beam.toml``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from gfe_opt.measured import MeasuredModes, make_measured
from gfe_opt.model import Effect, Model, load_model
from gfe_opt.synthetic import full_shapes_at_nodes, reference_with_rigidity, synthetic_measurement


def problem_file(name: str) -> Path:
    """Path of a shipped problem file."""
    return Path(str(resources.files(__name__).joinpath(name)))


@dataclass(frozen=True)
class UpdatingProblem:
    """An initial model, measured modes and the truth the updating should find."""

    name: str
    model: Model
    measured: MeasuredModes
    truth: dict
    full_shapes: np.ndarray | None = None
    notes: list = field(default_factory=list)


def christides_barr_problem(elements: int = 46, n_modes: int = 1, noise: float = 0.0,
                            seed: int = 0) -> UpdatingProblem:
    """The paper's case study: the simply supported steel beam (575 mm, 31.75 x 9.525 mm,
    E = 206 GPa, ρ = 7800 kg/m³) with a symmetric Christides–Barr crack at mid-span,
    a/d = 2/3 (d the half-depth), which lowers the first frequency to 0.757 of its uncracked
    value.  The initial model is uncracked; ``n_modes`` modes are measured (translations) at
    the interior nodes, with Gaussian shape noise ``noise`` (relative to the largest
    amplitude) and a tenth of it on the frequencies.

    Known answer: stiffness loss centred at x = 0.2875 m with Q_i = 1 + Δk_i / k_0 following
    Q(x) for a/d = 2/3 (paper Fig. 5).
    """
    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(elements)
    crack = {"position": 0.2875, "depth_ratio": 2.0 / 3.0}
    truth = model.with_effects([Effect("crack", crack)])
    measured = synthetic_measurement(truth, n_modes, model.nodes[1:-1], shape_noise=noise,
                                     freq_noise=noise / 10, seed=seed)
    return UpdatingProblem("christides-barr", model, measured, {"crack": crack})


def tapered_beam_problem(elements: int = 24, n_modes: int = 4,
                         taper: float = 0.5) -> UpdatingProblem:
    """The steel beam with EI(x) = EI_0 (1 + taper x / L) (a linear taper the initial,
    uniform model lacks); noise-free modes with every DOF measured at the nodes.

    Known answer: nodal k_i = EI(x_i), slopes ∂k/∂x = taper EI_0 / L.
    """
    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(elements)
    ei0, length = model.bending_rigidity, model.length

    def rigidity(x):
        return ei0 * (1.0 + taper * x / length)

    reference = reference_with_rigidity(model, rigidity, 8 * elements)
    freqs, shapes = full_shapes_at_nodes(reference, model, n_modes)
    measured = make_measured(model.nodes[1:-1], "w", freqs, shapes[2:-2:2], "tapered-beam")
    k = rigidity(model.nodes)
    slope = np.full_like(k, taper * ei0 / length)
    return UpdatingProblem("tapered-beam", model, measured,
                           {"nodal": np.concatenate([k, slope])}, full_shapes=shapes)


PROBLEMS = {"christides-barr": christides_barr_problem, "tapered-beam": tapered_beam_problem}
