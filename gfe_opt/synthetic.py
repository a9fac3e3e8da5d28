"""Synthetic measurements from an *independent* reference model.

The reference is the true structure on a much finer mesh.  A crack in the reference is built
another way than in the models being compared or updated: element stiffness integrated from
the Christides–Barr rigidity with Hermite curvatures (:func:`~gfe_opt.elements.
beam_stiffness_from_rigidity`) instead of the exact-flexibility element that
:func:`~gfe_opt.assembly.discretise` uses.  Noise is Gaussian: shape noise relative to each
mode's largest amplitude, frequency noise relative to each frequency.
"""

from __future__ import annotations

import numpy as np

from . import elements as el
from .assembly import builder, discretise, rigidity_function
from .measured import MeasuredModes, make_measured, sensor_matrix
from .modal import discretisation_modes
from .model import Effect, Model


def reference_discretisation(truth: Model, elements: int):
    """Fine-mesh discretisation of ``truth``; a beam's varying EI(x) (cracks, zones,
    profiles) integrated with Hermite curvatures instead of exact-flexibility elements."""
    fine = truth.with_elements(elements)
    build = builder(fine)
    disc = build.discretisation()
    if fine.kind != "beam" or not build.rigidity:
        return disc
    if build.shear_rigidity is not None:
        raise NotImplementedError("reference with both a varying EI and shear is not provided")
    rigidity, breakpoints = rigidity_function(fine)
    L = fine.element_length
    k = np.array([el.beam_stiffness_from_rigidity(rigidity, e * L, L, breakpoints, L / 64)
                  for e in range(elements)])
    return disc.with_stiffness({"k_ww": k[:, 0], "k_wt": k[:, 1], "k_tt": k[:, 2]})


def reference_with_rigidity(model: Model, rigidity, elements: int):
    """Fine-mesh discretisation of ``model`` with bending rigidity EI(x) = ``rigidity(x)``
    integrated element by element with Hermite curvatures (an independent route from the
    parameterisations being updated)."""
    fine = model.with_elements(elements)
    disc = discretise(fine)
    L = fine.element_length
    k = np.array([el.beam_stiffness_from_rigidity(rigidity, e * L, L)
                  for e in range(elements)])
    return disc.with_stiffness({"k_ww": k[:, 0], "k_wt": k[:, 1], "k_tt": k[:, 2]})


def full_shapes_at_nodes(reference, model: Model, n_modes: int):
    """Frequencies [Hz] and all-DOF shapes of a fine ``reference`` sampled at the nodes of
    ``model`` (whose element count must divide the reference's)."""
    ratio = reference.n_elements // model.elements
    if ratio * model.elements != reference.n_elements:
        raise ValueError("reference elements must be a multiple of the model's")
    modes = discretisation_modes(reference, n_modes)
    nodes = np.arange(model.elements + 1) * ratio
    per = reference.dofs_per_node
    dofs = (nodes[:, None] * per + np.arange(per)).ravel()
    return modes.frequencies_hz, modes.shapes[dofs]


def synthetic_measurement(truth: Model, n_modes: int, sensors, *, shape_noise=0.0,
                          freq_noise=0.0, seed=0, reference_elements: int | None = None,
                          ) -> MeasuredModes:
    """Measured modes of ``truth`` at ``sensors`` [m] (translations), with noise.

    ``reference_elements`` defaults to the larger of 400 and 8 x the model's elements.
    """
    n_ref = reference_elements or max(400, 8 * truth.elements)
    disc = reference_discretisation(truth, n_ref)
    modes = discretisation_modes(disc, n_modes)
    dof = "w" if truth.kind == "beam" else "u"
    C = sensor_matrix(disc.nodes, disc.kind, sensors, dof, "synthetic", shear_g=disc.shear_g)
    shapes = C @ modes.shapes
    rng = np.random.default_rng(seed)
    shapes = shapes + shape_noise * np.max(np.abs(shapes), axis=0) * rng.standard_normal(
        shapes.shape)
    freqs = modes.frequencies_hz * (1.0 + freq_noise * rng.standard_normal(n_modes))
    return make_measured(np.asarray(sensors, float), dof, freqs, shapes,
                         f"synthetic({truth.name})")


def interior_sensors(length: float, count: int) -> np.ndarray:
    """``count`` equally spaced sensors strictly inside (0, length)."""
    return np.linspace(0.0, length, count + 2)[1:-1]


def closed_form_measurement(model: Model, effect: Effect | None, n_modes: int, sensors, *,
                            shape_noise=0.0, freq_noise=0.0, seed=0) -> MeasuredModes:
    """Measured modes of a *simply supported* uniform beam from closed forms (shapes
    sin(nπx/L) at the sensors), with ``effect`` one of ``material``, ``axial_load``
    (ω² = (EI α⁴ + T α²)/ρA), ``foundation`` (ω² = (EI α⁴ + k_f)/ρA) or ``shear``
    (Timoshenko with rotary inertia: the lower root of the 2x2 determinant), α = nπ/L."""
    if model.kind != "beam" or model.supports != ("pinned", "pinned"):
        raise ValueError("closed forms are for simply supported beams")
    EI, rho_a, length = model.bending_rigidity, model.mass_per_length, model.length
    n = np.arange(1, n_modes + 1)
    alpha = n * np.pi / length
    name = effect.name if effect else None
    p = effect.parameters if effect else {}
    if name == "material":
        omega2 = p["E"] * model.inertia * alpha**4 / rho_a
    elif name == "axial_load":
        omega2 = (EI * alpha**4 + p["tension"] * alpha**2) / rho_a
    elif name == "foundation":
        omega2 = (EI * alpha**4 + p["stiffness"]) / rho_a
    elif name == "shear":
        kga, rho_i = p["shear_rigidity"], model.rho * model.inertia
        # det [[kGA a² - ρA ω², -kGA a], [-kGA a, EI a² + kGA - ρI ω²]] = 0, quadratic in ω²
        a2 = rho_a * rho_i
        a1 = -(rho_a * (EI * alpha**2 + kga) + rho_i * kga * alpha**2)
        a0 = kga * alpha**2 * (EI * alpha**2 + kga) - (kga * alpha) ** 2
        omega2 = (-a1 - np.sqrt(a1**2 - 4 * a2 * a0)) / (2 * a2)
    elif name is None:
        omega2 = EI * alpha**4 / rho_a
    else:
        raise ValueError(f"no closed form for {name!r}")
    sensors = np.asarray(sensors, float)
    shapes = np.sin(np.outer(sensors, alpha))
    rng = np.random.default_rng(seed)
    shapes = shapes + shape_noise * np.max(np.abs(shapes), axis=0) * rng.standard_normal(
        shapes.shape)
    freqs = np.sqrt(omega2) / (2 * np.pi) * (1 + freq_noise * rng.standard_normal(n_modes))
    return make_measured(sensors, "w", freqs, shapes, f"closed-form({name})")
