"""Grid starts screened in bulk (gfe_opt.screening): the reduced solve's χ² against the
exact solve's, and fits that end exactly where the point-by-point grid ends them, on frame
members and along a beam."""

import numpy as np
import pytest

from gfe_opt import fitting, modal, screening
from gfe_opt.frame_data import load_frame_measured
from gfe_opt.model import Effect, load_model
from gfe_opt.problems import portal_frame, problem_file
from gfe_opt.synthetic import interior_sensors, synthetic_measurement

NOISE = fitting.noise_of(0.0005, 0.003)


@pytest.fixture(scope="module")
def portal():
    model = portal_frame()
    return model, load_frame_measured(problem_file("portal-frame-semirigid.json"), model)


def _grid(problem):
    """The added effect's grid points (full z vectors) as the fit searches them."""
    slot = problem.slots[-1]
    grid = [fitting._with_null(slot.effect, v, problem.base) for v in slot.variables]
    points = np.array(np.meshgrid(*grid, indexing="ij")).reshape(len(grid), -1).T
    return [np.clip(p, problem.lower, problem.upper) for p in points]


@pytest.mark.parametrize("name,place", [("crack", {"member": "beam"}),
                                        ("point_mass", {"member": "left-column"}),
                                        ("section_loss", {"member": "right-column"})])
def test_screened_chi2_is_the_exact_one_to_1e_6(portal, name, place):
    """The screen's χ² on a member's grid agrees with the full modal solve to 1e-6
    relative (the static response at the member's DOFs completes the first point's
    modes)."""
    model, measured = portal
    problem = fitting.fit_problem(model, measured, [Effect(name, place)], noise=NOISE)
    zs = _grid(problem)

    def chi2(z):
        return float(np.sum(problem.residual(z) ** 2))


    exact = np.array([chi2(z) for z in zs])
    screened = screening.screen(problem.residual, zs)
    assert len(zs) >= 57
    assert np.max(np.abs(screened / exact - 1)) < 1e-6
    assert np.argmin(screened) == np.argmin(exact)


def _same(a, b):
    assert a.misfit.chi2 == b.misfit.chi2
    assert a.status == b.status
    assert [e.parameters for e in a.effects] == [e.parameters for e in b.effects]


def _screened_as_every_point(monkeypatch, model, measured, name):
    """``name`` fitted with its grid screened: it was screened, without falling back, and
    the fit is the one with every point solved, to the last bit, in under half its full
    solves."""
    monkeypatch.setattr(fitting, "SCREEN", False)
    plain = fitting.fit_effects(model, measured, [Effect(name, {})], noise=NOISE)
    monkeypatch.setattr(fitting, "SCREEN", True)
    before = dict(screening.TALLY)
    fit = fitting.fit_effects(model, measured, [Effect(name, {})], noise=NOISE)
    assert screening.TALLY["screened"] > before["screened"]
    assert screening.TALLY["fallback"] == before["fallback"]
    _same(plain, fit)
    assert fit.evaluations < plain.evaluations / 2
    return fit


@pytest.mark.parametrize("name,place", [("crack", {"member": "beam"}),
                                        ("point_spring", {"member": "left-column",
                                                          "direction": "x"})])
def test_screened_fit_ends_where_the_point_by_point_fit_ends(portal, monkeypatch, name,
                                                             place):
    """The screen only chooses which grid points are solved exactly: the fit's end is the
    same to the last bit as with every point solved, in fewer full solves."""
    model, measured = portal
    monkeypatch.setattr(fitting, "SCREEN", False)
    plain = fitting.fit_effects(model, measured, [Effect(name, place)], noise=NOISE)
    monkeypatch.setattr(fitting, "SCREEN", True)
    before = dict(screening.TALLY)
    screened = fitting.fit_effects(model, measured, [Effect(name, place)], noise=NOISE)
    assert screening.TALLY["screened"] > before["screened"]
    assert screening.TALLY["fallback"] == before["fallback"]
    _same(plain, screened)
    assert screened.evaluations < plain.evaluations / 2


def test_a_screen_that_errs_beyond_its_margin_solves_every_point(portal, monkeypatch):
    """An error above a quarter of the margin on the points solved exactly (here a margin
    of 1e-14, below the screen's 1e-9) and the whole grid is solved point by point: the
    same end again."""
    model, measured = portal
    adding = [Effect("crack", {"member": "left-column"})]
    monkeypatch.setattr(fitting, "SCREEN", False)
    plain = fitting.fit_effects(model, measured, adding, noise=NOISE)
    monkeypatch.setattr(fitting, "SCREEN", True)
    monkeypatch.setattr(screening, "MARGIN", 1e-14)
    before = dict(screening.TALLY)
    again = fitting.fit_effects(model, measured, adding, noise=NOISE)
    assert screening.TALLY["fallback"] > before["fallback"]
    _same(plain, again)
    assert again.evaluations >= plain.evaluations


@pytest.mark.parametrize("name", ["point_mass", "point_spring", "crack"])
def test_a_beam_grid_is_screened_place_by_place(monkeypatch, name):
    """Along a beam the grid's places span the whole beam, but each point differs from
    the first on a few DOFs: a basis each, the same fit as every point solved.  (A crack's
    disturbance decays without end; above 1e-12 of the largest entry it reaches 0.2 m each
    way on this beam: its basis holds more than half of the 46-element model, less than
    :data:`~gfe_opt.screening.LOCAL_FRACTION` of it.)"""
    model = load_model(problem_file("ss-steel-beam.toml"))
    # the test from a twice finer mesh: not the model being fitted
    hidden = (Effect("crack", {"position": 0.3, "depth_ratio": 0.4}) if name == "crack"
              else Effect("point_mass", {"position": 0.3, "mass": 0.2}))
    truth = model.with_elements(2 * model.elements).with_effects([hidden])
    measured = synthetic_measurement(truth, 4, interior_sensors(model.length, 15),
                                     shape_noise=0.003, freq_noise=0.0005, seed=5)
    fit = _screened_as_every_point(monkeypatch, model, measured, name)
    if name != "point_spring":
        assert fit.success and abs(fit.parameters["position"] - 0.3) < 0.01
    if name == "point_mass":
        assert abs(fit.parameters["mass"] / 0.2 - 1) < 0.05
    if name == "crack":
        assert abs(fit.parameters["depth_ratio"] / 0.4 - 1) < 0.1


def test_changed_rows_read_in_place_are_the_sparse_differences():
    """Where a point's matrix has the first point's pattern its changed rows are read from
    the entries in place; they are the rows of the sparse difference's entries above the
    threshold, in the same order (and a matrix of another pattern takes the difference)."""
    import scipy.sparse as sp

    rng = np.random.default_rng(7)
    A0 = sp.random(40, 40, density=0.2, random_state=rng, format="csr") + sp.eye(40)
    A0 = sp.csr_matrix(A0 + A0.T)
    rows_kept = {}
    for _ in range(20):
        A = A0.copy()
        touched = rng.choice(A.nnz, size=int(rng.integers(0, 12)), replace=False)
        A.data[touched] += rng.choice([1e-14, 1e-3, -2.0], size=touched.size)
        tiny = 1e-12 * abs(A0).max()
        D = sp.coo_matrix(A - A0)
        expected = D.row[np.abs(D.data) > tiny]
        got = screening._changed_rows(A, A0, tiny, rows_kept)
        assert np.array_equal(got, expected)
        row = np.repeat(np.arange(40), np.diff(A0.indptr))
        big = touched[np.abs(A.data[touched] - A0.data[touched]) > tiny]
        assert sorted(got) == sorted(row[big])   # the entries changed beyond rounding
    assert len(rows_kept) == 1   # one pattern, its rows computed once
    i, j = np.argwhere(A0.toarray() == 0)[0]   # an entry outside the pattern
    other = sp.csr_matrix(A0 + sp.csr_matrix(([5.0], ([i], [j])), shape=(40, 40)))
    assert other.nnz == A0.nnz + 1   # another pattern: the sparse difference is taken
    D = sp.coo_matrix(other - A0)
    assert np.array_equal(screening._changed_rows(other, A0, 0.0, {}), D.row[D.data != 0])


@pytest.mark.parametrize("name", ["crack", "point_mass"])
def test_a_condensed_beams_grid_is_screened_on_the_same_beam_solved_directly(monkeypatch,
                                                                             name):
    """A beam solved through condensed super-elements (here 600 elements) has its grid
    screened on the same beam at :data:`~gfe_opt.modal.CONDENSE_ABOVE` elements: the screen
    ranks every point within a quarter of its margin of the fine solve's χ², and the fit
    (which chooses its start on that stand-in: the points the screen keeps are solved
    there) ends where every point solved ends it, to the last bit, in fewer solves."""
    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(600)
    hidden = (Effect("crack", {"position": 0.3, "depth_ratio": 0.4}) if name == "crack"
              else Effect("point_mass", {"position": 0.3, "mass": 0.2}))
    # the test from a twice finer mesh: not the model being fitted
    truth = model.with_elements(1200).with_effects([hidden])
    measured = synthetic_measurement(truth, 4, interior_sensors(model.length, 15),
                                     shape_noise=0.003, freq_noise=0.0005, seed=5)
    problem = fitting.fit_problem(model, measured, [Effect(name, {})], noise=NOISE)
    zs = _grid(problem)
    exact = np.array([float(np.sum(problem.residual(z) ** 2)) for z in zs])
    screened = screening.screen(problem.residual, zs)
    assert screened is not None and len(zs) >= 15
    assert np.max(np.abs(screened / exact - 1)) < screening.MARGIN / 4
    fit = _screened_as_every_point(monkeypatch, model, measured, name)
    assert fit.success and abs(fit.parameters["position"] - 0.3) < 0.01


def test_a_condensed_beams_fit_converges_first_on_its_stand_in(monkeypatch):
    """A fit on a beam solved through condensed super-elements converges first on the same
    beam at CONDENSE_ABOVE elements (direct solves, analytic Jacobian) and finishes on its
    own mesh from there (:data:`fitting.STAND_IN`): the same optimum of its own mesh as the
    fit that runs there from the grid (χ² to 1e-9, every parameter within 1e-3 σ: the
    finish's rule leaves 3e-5 σ), in at most 60 % of the condensed modal solves (41 % when
    written)."""
    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(600)
    truth = model.with_elements(1200).with_effects(
        [Effect("crack", {"position": 0.27, "depth_ratio": 0.45})])
    measured = synthetic_measurement(truth, 5, interior_sensors(model.length, 20),
                                     shape_noise=0.003, freq_noise=0.0005, seed=11)
    solves = []
    condensed_modes = modal._condensed_modes

    def counted(*args, **kwargs):
        solves.append(1)
        return condensed_modes(*args, **kwargs)

    monkeypatch.setattr(modal, "_condensed_modes", counted)
    fits = {}
    for stand_in in (False, True):
        monkeypatch.setattr(fitting, "STAND_IN", stand_in)
        solves.clear()
        fits[stand_in] = (fitting.fit_effects(model, measured, [Effect("crack", {})],
                                              noise=NOISE), len(solves))
    (plain, fine_plain), (fit, fine) = fits[False], fits[True]
    # (converged or settled: which of the two can turn on the condensed solve's rounding)
    assert plain.success and fit.success
    assert abs(fit.misfit.chi2 / plain.misfit.chi2 - 1) < 1e-9
    for key, value in plain.effects[0].parameters.items():
        assert abs(fit.effects[0].parameters[key] - value) < 1e-3 * fit.sigma[0][key]
    assert fine <= 0.6 * fine_plain
    assert abs(fit.effects[0].parameters["position"] - 0.27) < 0.01


def test_shear_on_a_beam_the_condensation_cannot_take_is_fitted():
    """A deep beam (L/h = 12) of 400 elements measured from the Timoshenko closed form
    (six modes, 30 sensors, noise): the shear fit converges to the noise with κGA within
    1 % of the truth's 5/6 G A (0.08 % when written).  Before its modal solve fell back to
    the direct route, every shear model the fit tried at this mesh failed the condensed
    route's check and the fit ended not converged, κGA 155 % off."""
    model, measured, kga = _deep_beam_data(400)
    fit = fitting.fit_effects(model, measured, [Effect("shear", {})], noise=NOISE)
    assert fit.success   # (converged when written; settled would pass too)
    assert fit.misfit.chi2_per_residual < 1.5
    assert abs(fit.effects[0].parameters["shear_rigidity"] / kga - 1) < 0.01


def _deep_beam_data(elements):
    """A deep beam (L/h = 12) of ``elements`` and its measurement from the Timoshenko
    closed form (six modes, 30 sensors, noise): not the model being fitted."""
    from gfe_opt.measured import make_measured

    from .conftest import make_model
    from .reference import add_noise, interior, timoshenko_ss

    length = 0.575
    model = make_model(section={"b": 0.02, "h": length / 12}, elements=elements)
    kga = 5 / 6 * model.E / (2 * (1 + model.nu)) * model.area
    s = interior(length, 30)
    f = timoshenko_ss(6, model.bending_rigidity, model.mass_per_length,
                      model.rho * model.inertia, kga, length)
    f, y = add_noise(f, np.sin(np.outer(s, np.arange(1, 7) * np.pi / length)), seed=4,
                     shape_noise=0.003, freq_noise=0.0005)
    return model, make_measured(s, "w", f, y, "timoshenko"), kga


def test_a_long_shear_beams_fit_takes_the_analytic_jacobian():
    """The shear fit on a deep beam of 400 elements: its models are solved directly (their
    pencil conditioned as N², below the Euler–Bernoulli beam's at CONDENSE_ABOVE), so the
    analytic Jacobian is taken at its points though the beam without shear is condensed.
    The same optimum as the fit that differences the residual (χ² to 1e-9, κGA to 1e-6),
    in at most 60 % of its evaluations (13 against 30 when written; 22 when every point of
    a beam above CONDENSE_ABOVE elements was differenced), and κGA within 1 % of the
    truth's."""
    model, measured, kga = _deep_beam_data(400)
    assert modal.condensed(model)   # the beam without shear
    fits = {jac: fitting.fit_effects(model, measured, [Effect("shear", {})], noise=NOISE,
                                     jacobian=jac) for jac in ("analytic", "difference")}
    fit, plain = fits["analytic"], fits["difference"]
    assert fit.success and plain.success
    assert not modal.condensed(model.with_effects(fit.effects))
    assert abs(fit.misfit.chi2 / plain.misfit.chi2 - 1) < 1e-9
    found = fit.effects[0].parameters["shear_rigidity"]
    assert abs(found / plain.effects[0].parameters["shear_rigidity"] - 1) < 1e-6
    assert fit.evaluations <= 0.6 * plain.evaluations
    assert abs(found / kga - 1) < 0.01


def test_condensed_points_are_differenced_as_before(monkeypatch):
    """Where a fit's modes come from the condensed route the analytic Jacobian is not
    taken (:meth:`fitting.Objective._analytic` gives None and the caller differences with
    its own step): a crack fit on 600 Euler–Bernoulli elements (the stand-in off) ends on
    the same bits whether the analytic Jacobian is asked for or not."""
    monkeypatch.setattr(fitting, "STAND_IN", False)
    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(600)
    truth = model.with_elements(1200).with_effects(
        [Effect("crack", {"position": 0.27, "depth_ratio": 0.45})])
    measured = synthetic_measurement(truth, 4, interior_sensors(model.length, 15),
                                     shape_noise=0.003, freq_noise=0.0005, seed=11)
    fits = [fitting.fit_effects(model, measured, [Effect("crack", {})], noise=NOISE,
                                jacobian=jac) for jac in ("analytic", "difference")]
    assert fits[0].success
    assert fits[0].misfit.chi2 == fits[1].misfit.chi2
    assert fits[0].effects[0].parameters == fits[1].effects[0].parameters
    assert fits[0].sigma == fits[1].sigma
