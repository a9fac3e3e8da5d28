"""Output-error baseline: eigen-sensitivities against finite differences, and a recovery."""

import numpy as np

from gfe_opt.assembly import discretise
from gfe_opt.modal import discretisation_modes
from gfe_opt.output_error import update_output_error
from gfe_opt.parameterisation import beam_parameterisation
from gfe_opt.problems import tapered_beam_problem
from gfe_opt.updating import stiffness_map

from .conftest import make_model


def test_eigenvalue_sensitivity_matches_finite_differences():
    model = make_model(elements=12)
    disc = discretise(model)
    par = beam_parameterisation("nodal", 12, model.element_length)
    q = par.fit(disc.stiffness_params)
    direction = np.random.default_rng(1).standard_normal(q.size) * np.abs(q).max() * 1e-3
    direction[13:] /= model.element_length  # slopes
    kmap = stiffness_map(disc, par)
    modes = discretisation_modes(disc, 3, params=par.element_parameters(q))
    phi = modes.shapes[disc.free]
    analytic = np.array([phi[:, j] @ (kmap.jacobian_times(phi[:, j]) @ direction)
                         for j in range(3)])
    eps = 1e-3
    lam = [(2 * np.pi * discretisation_modes(disc, 3, params=par.element_parameters(
        q + s * eps * direction)).frequencies_hz) ** 2 for s in (1, -1)]
    fd = (lam[0] - lam[1]) / (2 * eps)
    assert np.allclose(analytic, fd, rtol=1e-5)


def test_output_error_reduces_frequency_error_on_the_taper():
    problem = tapered_beam_problem()
    result = update_output_error(problem.model, problem.measured, noise=1e-4)
    assert result.ok, result.summary()
    f0 = discretisation_modes(discretise(problem.model), 4).frequencies_hz
    f = discretisation_modes(result.discretisation, 4).frequencies_hz
    measured = problem.measured.frequencies_hz
    assert np.max(np.abs(f / measured - 1)) < 0.05 * np.max(np.abs(f0 / measured - 1))
