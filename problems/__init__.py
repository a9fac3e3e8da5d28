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


def portal_frame(elements: int | None = None):
    """The steel portal frame of ``portal-frame.toml`` (a :class:`~gfe_opt.frame.FrameModel`):
    columns 0.3 m, beam 0.4 m, all 50 x 10 mm (h = 10 mm in the plane), E = 210 GPa,
    ρ = 7850 kg/m³, both bases clamped; ``elements`` per member (the file: 20).

    Known answer (exact Euler–Bernoulli members with axial motion, dynamic stiffness method,
    ``tests/frame_reference.py``): 74.479366, 219.086479, 488.282804, 520.766524,
    783.875943, 1312.670049 Hz.  The sway estimate of the textbook (stiffness
    24EI/h³ (6ρ+1)/(6ρ+4), ρ = I_b h/(I_c b), the beam's mass and 13/35 of the columns')
    gives 72.2 Hz for the first.  At 20 elements a member the file's model is within 2e-5
    (the sway mode converges as h², the axial elements' rate; the bending modes as h⁴).
    """
    return _frame_problem("portal-frame.toml", elements)


def three_storey_frame(elements: int | None = None):
    """The aluminium three-storey plane frame of ``three-storey-frame.toml``: storeys 0.3 m,
    span 0.4 m, columns 25 x 6 mm, floor beams 25 x 12 mm (h in the plane), E = 70 GPa,
    ρ = 2700 kg/m³, clamped bases; 120 elements (12 a column, 16 a beam), or ``elements``
    per member.

    Known answer (dynamic stiffness method, as for :func:`portal_frame`): 15.238141,
    45.145030, 69.993806, 171.160094, 189.416956, 209.076568 Hz; the file's mesh is within
    2e-6 of them.
    """
    return _frame_problem("three-storey-frame.toml", elements)


def _frame_problem(name, elements):
    from dataclasses import replace

    model = load_model(problem_file(name), frames=True)
    if elements is None:
        return model
    return replace(model, members=tuple(replace(m, elements=elements) for m in model.members))
