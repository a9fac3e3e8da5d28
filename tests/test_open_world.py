"""The open world: truths the library holds only approximately or not at all, with data
from the independent reference beam (tests/reference.py), and the uncertainty of fits.

Targets (issue 10): two crack-like losses found within 15 mm and then ``consistent``; a
linear taper becomes EI(x) within 3 % over the middle 90 % with no local effect, axial load
or foundation; a mid-span spring is a ``point_spring`` (15 mm, 10 %), not a foundation;
corrosion is a local loss with a mass decrease, not a point mass; data no single structure
produces, or noise ten times the stated level, are never called ``consistent`` with a
wrong effect; the truth lies within 2σ in at least 90 % of noise realisations."""

import numpy as np
import pytest

from gfe_opt.assembly import rigidity_function
from gfe_opt.diagnosis import diagnose, update
from gfe_opt.fitting import fit_effects, noise_of
from gfe_opt.measured import make_measured
from gfe_opt.model import Effect

from .conftest import make_model
from .reference import ReferenceBeam, add_noise, christides_barr, interior, product, zone
from .test_diagnosis import NOISE, loop, reference_data

L = 0.575
EI = ReferenceBeam().EI
LOCAL_LOSSES = {"crack", "section_loss"}


def test_two_cracks_are_two_local_losses_then_consistent():
    measured = reference_data(rigidity=product(christides_barr(0.12, 0.4),
                                               christides_barr(0.42, 0.4)))
    added, last, model = loop(make_model(), measured, steps=4)
    assert last.verdict == "consistent"
    losses = sorted(e.parameters["position"] for e in model.effects if e.name in LOCAL_LOSSES)
    assert len(losses) == 2 and {e.name for e in model.effects} <= LOCAL_LOSSES
    assert abs(losses[0] - 0.12) <= 0.015 and abs(losses[1] - 0.42) <= 0.015


def test_the_pairs_after_the_candidates_are_reported_as_progress():
    # two cracks: the first alone does not explain the data, so the diagnosis fits it with
    # each other candidate (its lookahead) after the candidates' batch; those fits report
    # to the same progress as the candidates, each batch counted to its end
    measured = reference_data(rigidity=product(christides_barr(0.12, 0.4),
                                               christides_barr(0.42, 0.4)))
    calls = []
    result = diagnose(make_model(), measured, progress=lambda *a: calls.append(a), **NOISE)
    assert result.suggested[0] in LOCAL_LOSSES
    pairs = [name for _, _, name in calls if name.startswith(f"{result.best.name} + ")]
    assert pairs and f"{result.best.name} + {result.best.name}" in pairs
    ends = [(done, total) for done, total, _ in calls if done == total]
    assert len(ends) >= 2 and all(total > 0 for _, total in ends)   # the candidates, pairs


def test_a_taper_becomes_a_stiffness_profile_not_local_effects():
    measured = reference_data(rigidity=lambda x: 1.0 - 0.2 * x / L)
    added, last, model = loop(make_model(), measured, steps=3)
    assert last.verdict == "consistent"
    assert {e.name for e in model.effects} <= {"material", "stiffness_profile"}
    x = np.linspace(0.05 * L, 0.95 * L, 200)
    rigidity, _ = rigidity_function(model)
    assert np.max(np.abs(rigidity(x) / (model.E * model.inertia) / (1 - 0.2 * x / L) - 1)) < 0.03
    # the generic update calls it a taper, and the fit reproduces it
    assert any("a taper" in w for w in loop_words(make_model(), measured))


def test_a_step_over_the_outer_part_is_one_zone_reaching_the_end():
    """EI 12 % lower from 0.6 L to the right end (a beam of two sections): one section loss
    whose zone ends on the end, inner edge within 2 % of the length and the ratio within 2σ,
    its σ finite (on the end, centre and length move together: not a trade)."""
    measured = reference_data(rigidity=lambda x: np.where(x > 0.6 * L, 0.88, 1.0))
    diagnosis = diagnose(make_model(), measured, **NOISE)
    assert diagnosis.verdict == "effect_found" and diagnosis.suggested == ["section_loss"]
    outcome = update(make_model(), measured, ["section_loss"], **NOISE)
    p, sigma = outcome.fit.effects[0].parameters, outcome.fit.sigma[0]
    assert p["position"] + p["length"] / 2 == pytest.approx(L, abs=1e-9)
    assert abs(p["position"] - p["length"] / 2 - 0.6 * L) <= 0.02 * L
    assert abs(p["stiffness_ratio"] - 0.88) <= 2 * sigma["stiffness_ratio"]
    assert np.isfinite(sigma["length"]) and sigma["length"] < 0.1 * p["length"]
    # both from the inner edge a: centre (a + L)/2, length L - a
    assert sigma["length"] == pytest.approx(2 * sigma["position"], rel=1e-9)
    assert not outcome.fit.unidentified
    assert diagnose(outcome.model, measured, **NOISE).verdict == "consistent"


def test_a_quadratic_taper_with_no_noise_given_is_a_profile_not_a_long_zone():
    """A smooth taper, no noise stated: one long zone leaves residuals that may look white,
    but a free profile explains significantly more, and it is the finding."""
    s = interior(L, 17)
    beam = ReferenceBeam(elements=600, supports=("clamped", "clamped"),
                         rigidity=lambda x: 1.0 + 0.25 * (x / L) ** 2)
    f, y = beam.measure(3, s, shape_noise=0.006, freq_noise=0.001, seed=24)
    measured = make_measured(s, "w", f, y, "reference")
    model = make_model(supports={"left": "clamped", "right": "clamped"})
    diagnosis = diagnose(model, measured)
    assert diagnosis.verdict == "effect_found"
    assert diagnosis.suggested == ["stiffness_profile"]


@pytest.mark.xfail(strict=True, reason="known weakness (stop 77): the profile's knots are "
                   "judged on the named candidates' noise floor; judging them on the profiles' "
                   "own changed the real cantilever's first diagnosis (README, Validation "
                   "campaign)")
def test_a_quadratic_taper_read_on_its_profiles_own_floor_is_found_with_its_knots():
    """EI falling as a quadratic to 0.73 of the model's at the pinned end of a
    clamped–pinned beam, 3 modes at 10 sensors, the noise stated: no named effect fits
    (a long zone to χ²/n 13), a free profile does.  Its 3 knots (χ² 35.6) beat its 2 (76.3)
    by more than the significance asks of the noise floor the profiles themselves set (the
    most flexible fit's χ²/dof, 1.2), though not of the floor the named effects set (14.7):
    judged on that one, the 2 knots (χ²/n 2.3) are kept, do not explain, and the taper is
    said unexplained (the seed-2600 beam campaign's taper-quadratic-clamped-pinned-2720).
    The profile's ratios would follow the taper."""
    from .truths import _node_sensors

    taper = -0.266
    beam = ReferenceBeam(elements=800, supports=("clamped", "pinned"),
                         rigidity=lambda x: 1.0 + taper * (x / L) ** 2)
    s = _node_sensors(L, 60, 10)
    f, y = beam.measure(3, s, shape_noise=0.003, freq_noise=0.0005, seed=2721)
    measured = make_measured(s, "w", f, y, "reference")
    model = make_model(elements=60, supports={"left": "clamped", "right": "pinned"})
    diagnosis = diagnose(model, measured, **NOISE)
    assert diagnosis.verdict == "effect_found", diagnosis.notes
    assert diagnosis.suggested == ["stiffness_profile"]
    profile = diagnosis.best.parameters
    assert len(profile["x"]) >= 3
    x = np.asarray(profile["x"])
    truth = 1.0 + taper * (x / L) ** 2
    assert np.max(np.abs(np.asarray(profile["ratio"]) / truth - 1)) < 0.05


@pytest.mark.xfail(strict=True, reason="known weakness (stop 78): an undetermined pair "
                   "sets the profile aside; setting such pairs aside fixed this taper but "
                   "changed the real cantilever's first diagnosis to material with a 15 N "
                   "compression (README, Validation campaign)")
def test_a_taper_whose_profile_only_an_undetermined_pair_rivals_is_no_crack():
    """EI falling as a quadratic to 0.68 of the model's at the pinned end of a clamped–pinned
    beam (the held-out seed-2600 campaign's taper-quadratic-clamped-pinned-2719, drawn by
    tests/truths.py's own reference beam).  A crack alone fits 21 times worse than a free
    linear profile; a crack with a long zone fits a little better than the profile, but
    two such pairs 0.04 m apart fit as well: the data do not determine it.  That pair
    rivals the profile all the same, the profile is set aside, and the crack alone is said
    missing (then added: the campaign's one false alarm on that seed).  Were such a pair no
    rival, the diagnosis would name nothing (``unexplained``), say the crack explains a
    part, and offer the profile, falling towards the pinned end; but on the real
    cantilever (tests/test_real_data.py) the same rule turns material alone, with a zone
    the frequencies do not place, into material with a further axial load of -15 ± 4 N."""
    from gfe_opt.model import model_from_dict

    from . import truths

    case = truths.draw("taper", 2719)
    assert case.hidden[0].law == "quadratic" and case.stated is not None
    model = model_from_dict(case.model, case.name)
    measured = make_measured(case.x, "w", case.frequencies, case.shapes, case.name)
    d = diagnose(model, measured, freq_noise=case.stated[0], shape_noise=case.stated[1])
    assert d.verdict == "unexplained" and d.suggested == [], (d.suggested, d.notes)
    assert d.offered == ["stiffness_profile"]
    profile = next(f for f in d.fits if f.name == "stiffness_profile").parameters["ratio"]
    assert profile[-1] < profile[0] - 0.2   # softer towards the pinned end
    assert any(n.startswith("crack explains part of the difference") for n in d.notes)


def loop_words(model, measured):
    from gfe_opt.diagnosis import diagnose

    return diagnose(model, measured, realise=True, **NOISE).realisation


def test_a_mid_span_spring_is_a_point_spring_not_a_foundation():
    measured = reference_data(point_springs=[(L / 2, 2e5)])
    added, last, model = loop(make_model(), measured, steps=3)
    assert [e.name for e in model.effects] == ["point_spring"] and last.verdict == "consistent"
    spring = model.effects[0].parameters
    assert abs(spring["position"] - L / 2) <= 0.015 and abs(spring["stiffness"] / 2e5 - 1) < 0.1


def test_a_zone_stiffer_than_the_rest_is_found_alone_not_beside_a_uniform_change():
    """A free-free aluminium beam (0.8 m, 21 sensors from end to end, 5 elastic modes) with
    a bonded doubler: EI 1.4 and ρA 1.15 times over 0.45-0.65 m, from the independent
    reference beam.  The section loss's own fit (started from losses) ends in another
    valley, the uniform E fits best alone, and E with a section loss explains the data to
    the noise, E ending at the model's own.  Before stop 82 the diagnosis suggested both
    (on other seeds an axial load of 0.2 N with the zone): the second effect alone, fitted
    from where the pair put it, explains as well with a lower information criterion, and
    is now the finding; update started there (the suggestion's values) ends there too, and
    after it the model is consistent."""
    length = 0.8
    model = make_model(name="ff-al", length=length, elements=40,
                       material={"E": 70e9, "rho": 2700.0, "nu": 0.33},
                       section={"b": 0.02, "h": 0.008},
                       supports={"left": "free", "right": "free"})
    beam = ReferenceBeam(length=length, EI=70e9 * 0.02 * 0.008**3 / 12,
                         rho_a=2700 * 0.02 * 0.008, supports=("free", "free"), elements=800,
                         rigidity=zone(0.55, 0.2, 1.4), mass=zone(0.55, 0.2, 1.15))
    x = np.linspace(0.0, length, 21)
    f, y = beam.measure(7, x, seed=5, shape_noise=0.001, freq_noise=0.0001)
    measured = make_measured(x, "w", f[2:], y[:, 2:], "doubler")
    d = diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["section_loss"], d.suggested
    assert d.together is None
    zone_fit = d.best.parameters
    assert abs(zone_fit["position"] - 0.55) <= 0.02 * length
    assert abs(zone_fit["length"] / 0.2 - 1) < 0.1
    assert abs(zone_fit["stiffness_ratio"] / 1.4 - 1) < 0.05
    assert abs(zone_fit["mass_ratio"] / 1.15 - 1) < 0.05
    # its own fit from the grid ends elsewhere: the suggestion starts update at the finding
    add = d.add_arguments()
    assert d.from_pair == ("section_loss",) and add[0].startswith("section_loss:position=")
    assert d.to_json()["add"] == add
    assert any(n.startswith("section_loss was found in a pair with material, which then "
                            "stood for nothing") for n in d.notes)
    after = update(model, measured, add, **NOISE)
    assert after.fit.parameters == pytest.approx(zone_fit, rel=1e-4)
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


def test_a_spring_the_data_do_not_want_has_no_place():
    """A point spring added to a beam whose data hold none (the reference beam with a
    crack; a spring of negative stiffness would help, none of positive) ends at the soft end
    of its range, where it does nothing: its position is then not determined by the data.
    Before, the σ of the position came from the curvature of χ² along it with the spring
    held at that end, ± 1e14 m, and the text rounded the position to its σ (0.575 m printed
    as 1).  Beside it, a real spring keeps a σ of its position well inside the beam."""
    measured = reference_data(rigidity=christides_barr(0.19, 0.5))
    fit = update(make_model(), measured, ["point_spring"], **NOISE).fit
    assert fit.bound == {"stiffness": "at most"}
    assert np.isinf(fit.uncertainty["position"])
    assert fit.to_json()["uncertainty"]["position"] is None
    assert f"position = {fit.parameters['position']:.4g} m (not determined by the data)" \
        in fit.describe()
    assert fit.unidentified == ["point_spring.position: not determined: "
                                "point_spring.stiffness is at the end of its range where "
                                "the point_spring vanishes"]
    real = update(make_model(), reference_data(point_springs=[(L / 2, 2e5)]),
                  ["point_spring"], **NOISE).fit
    assert real.bound == {} and not real.unidentified
    assert abs(real.parameters["position"] - L / 2) <= 3 * real.uncertainty["position"] \
        + 0.005 * L and real.uncertainty["position"] < 0.01 * L


def test_a_roller_partway_along_is_a_stiff_point_spring_at_its_place():
    """An intermediate support that holds the beam still (a spring 10⁴ times stiffer than the
    fifth mode's modal stiffness): the start grid spans flexible to rigid springs, so the
    spring is found at its place, stiffer than the fifth mode's modal stiffness."""
    k = 1e4 * (5 * np.pi) ** 4 * EI / L**3 / 2
    measured = reference_data(point_springs=[(0.19, k)])
    diagnosis = diagnose(make_model(), measured, **NOISE)
    assert diagnosis.verdict == "effect_found" and diagnosis.suggested == ["point_spring"]
    spring = diagnosis.best.parameters
    assert abs(spring["position"] - 0.19) <= 0.02 * L
    assert spring["stiffness"] > (5 * np.pi) ** 4 * EI / L**3 / 2
    # rigid as far as the modes tell: the stiffness ends on the top of its range, where a σ
    # from the curvature means nothing; it is said to be a lower bound, in text and JSON
    assert diagnosis.best.bound == {"stiffness": "at least"}
    assert "stiffness ≥ " in diagnosis.best.describe()
    assert diagnosis.best.to_json()["bounds"] == {"stiffness": "at_least"}
    # ... and on the structure sketch of the figures and the report
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gfe_opt.plots import structure_sketch
    from gfe_opt.report import findings

    fig, ax = plt.subplots()
    structure_sketch(ax, L, findings=findings(diagnosis, make_model()))
    assert any(t.get_text().startswith("≥ ") for t in ax.texts)
    plt.close(fig)
    outcome = update(make_model(), measured, ["point_spring"], **NOISE)
    entry = outcome.to_json()["effects"][0]
    assert entry["bounds"] == {"stiffness": "at_least"} and entry["uncertainty"]["stiffness"] \
        is None


def test_corrosion_is_a_local_loss_of_stiffness_and_mass():
    measured = reference_data(rigidity=zone(0.3, 0.04, 0.7), mass=zone(0.3, 0.04, 0.7))
    added, last, model = loop(make_model(), measured, steps=3)
    assert "point_mass" not in {e.name for e in model.effects}
    loss = next(e.parameters for e in model.effects if e.name == "section_loss")
    assert abs(loss["position"] - 0.3) <= 0.015 and loss["mass_ratio"] < 0.9
    assert loss["stiffness_ratio"] < 0.9 and last.verdict == "consistent"


def test_data_no_single_structure_produces_are_unexplained():
    """Each mode from a beam with its crack somewhere else: a stiffness that depends on
    the mode, which no structure has."""
    s = interior(L, 45)
    freqs, shapes = [], []
    for n, xc in enumerate((0.08, 0.2, 0.33, 0.45, 0.52)):
        f, y = ReferenceBeam(elements=600, rigidity=christides_barr(xc, 0.35)).measure(
            5, s, seed=20 + n)
        freqs.append(f[n])
        shapes.append(y[:, n])
    measured = make_measured(s, "w", freqs, np.array(shapes).T, "mode-dependent")
    model, verdicts = make_model(), []
    for _ in range(3):
        d = diagnose(model, measured, **NOISE)
        verdicts.append(d.verdict)
        if d.verdict != "effect_found":
            break
        # a finding here (a pair that fits as well as the free profile) must say that a
        # difference remains, and how much: far above the noise, correlated
        assert d.remaining is not None and d.remaining["chi2_per_residual"] > 20, d.remaining
        model = update(model, measured, list(d.suggested), **NOISE).model
    assert verdicts[-1] == "unexplained" and "consistent" not in verdicts, verdicts
    assert any("correlated from sensor to sensor" in n for n in d.notes)
    assert d.current.chi2_per_residual > 20


def test_a_notch_in_a_pinned_continuum_with_noise_above_the_stated_is_found():
    """A 2-D plane-stress beam on pins at mid-height (tests/continuum.py) with a real notch,
    noise twice the assumed level, no noise given (the first such case of the held-out
    generator above seed 3000).  No named effect alone comes near the free profile (the
    continuum's shear and E absorb into it); E fits best alone and no second effect
    completes it, but shear with a crack explains the data (the continuum's own shear
    deformation and the notch; before the uniform change's rule of the selection E with a
    crack, which fits as well as the profile and leaves a difference, was the finding):
    that pair is the finding, and the loop ends with the crack at the notch.  What the pair
    leaves (the continuum's pins at mid-height, which a support that translates fitted and
    the loop then ended ``consistent``) is below 1 % of what the pair explains: since stop
    57 it is withheld as the present effects' own form, and the loop ends ``unexplained``
    (right for a truth outside the family, as the campaign scores it)."""
    from gfe_opt.diagnosis import FORM_SHARE
    from gfe_opt.model import model_from_dict

    from .truths import continuum_case

    case = continuum_case(3017)
    assert case.group == "continuum" and case.stated is None and case.noise_factor == 2.0
    notch = case.hidden[0].position
    model = model_from_dict(case.model, case.name)
    measured = make_measured(case.x, "w", case.frequencies, case.shapes, case.name)
    first = None
    for _ in range(5):
        d = diagnose(model, measured)
        first = first or d
        if d.verdict != "effect_found":
            break
        swap = d.replace
        model = update(model, measured, list(d.suggested),
                       drop=[swap["index"]] if swap else ()).model
    assert sorted(first.suggested) == ["crack", "shear"], first.notes
    assert d.verdict == "unexplained", (d.verdict, d.notes)
    assert 0 < d.withheld["share"] < FORM_SHARE
    assert sorted(e.name for e in model.effects) == ["crack", "shear"]
    cracks = [e.parameters["position"] for e in model.effects if e.name == "crack"]
    assert len(cracks) == 1 and abs(cracks[0] - notch) <= 0.02 * L, (cracks, notch)


def test_noise_ten_times_the_stated_level_is_said_not_explained():
    s = interior(L, 45)
    f, y = ReferenceBeam(elements=600).measure(5, s, seed=3, shape_noise=0.03,
                                               freq_noise=0.005)
    added, last, _ = loop(make_model(), make_measured(s, "w", f, y, "noisy"), steps=2)
    assert added == [] and last.verdict == "unexplained"
    assert 0.02 < last.noise.implied_shape < 0.04  # 3 % was drawn
    assert abs(last.noise.correlation) < 0.3  # white: noise, not a structure


@pytest.mark.slow  # a 60-realisation study (70 s): python -m pytest -m slow (.ci/run runs it)
@pytest.mark.parametrize("truth,effect,keys", [
    ({"point_masses": [(0.4, 0.2)]}, "point_mass", ("position", "mass")),
    ({"rigidity": christides_barr(0.3, 0.4)}, "crack", ("position", "depth_ratio")),
])
def test_two_standard_deviations_cover_the_truth(truth, effect, keys):
    """60 noise realisations; the truth within 2σ in at least 90 % of them, and |error|/σ
    about 0.8 on average (σ neither too small nor inflated)."""
    want = {"point_mass": {"position": 0.4, "mass": 0.2},
            "crack": {"position": 0.3, "depth_ratio": 0.4}}[effect]
    s = interior(L, 45)
    f0, y0 = ReferenceBeam(elements=1200, **truth).measure(5, s, shape_noise=0,
                                                           freq_noise=0)
    z = {k: [] for k in keys}
    model = make_model()
    for seed in range(60):
        f, y = add_noise(f0, y0, seed=100 + seed, **NOISE)
        fit = fit_effects(model, make_measured(s, "w", f, y, "mc"), [Effect(effect, {})],
                          noise=noise_of(**NOISE))
        for k in keys:
            z[k].append((fit.parameters[k] - want[k]) / fit.uncertainty[k])
    for k in keys:
        z_k = np.abs(z[k])
        assert np.mean(z_k <= 2) >= 0.9, (k, np.round(z_k, 2))
        assert 0.5 < np.mean(z_k) < 1.2, (k, np.mean(z_k))



def test_a_notch_near_the_clamp_of_a_continuum_is_a_determined_crack_with_shear():
    """A 2-D plane-stress cantilever (tests/continuum.py, a clamped end face) with a real
    double-edged notch near the clamp, 3 modes: the Euler–Bernoulli model lacks shear, so a
    crack *with* shear is what brings the misfit to the noise.  Near a clamp a crack's place
    and depth are correlated beyond 0.99 (a deeper crack a little further out bends the modes
    alike), yet both are determined to a fraction of a percent: the fit must not call them
    "not estimable" for the correlation alone (that withheld the pair, and a free profile
    that absorbed notch and shear together won)."""
    from gfe_opt.model import model_from_dict

    from .continuum import continuum_modes
    from .truths import BEAM, model_dict

    L, h, b = BEAM["length"], BEAM["h"], BEAM["b"]
    s = np.linspace(0.04, 0.96, 25) * L
    f, y = continuum_modes(L, h, b, BEAM["E"], BEAM["nu"], BEAM["rho"], n_modes=3, sensors=s,
                           supports=("clamp", "free"), notch=(0.08, 0.002, 0.45))
    f, y = add_noise(f, y, NOISE["shape_noise"], NOISE["freq_noise"], 7)
    measured = make_measured(s, "w", f, y, "continuum")
    model = model_from_dict(model_dict(("clamped", "free"), 46), "cantilever")
    fit = fit_effects(model, measured, [Effect("crack", {}), Effect("shear", {})],
                      noise=noise_of(NOISE["freq_noise"], NOISE["shape_noise"]))
    assert fit.unidentified == []
    crack, sigma = fit.effects[0].parameters, fit.sigma[0]
    assert abs(crack["position"] - 0.08) <= 0.02 * L
    assert sigma["position"] < 0.005 * L and sigma["depth_ratio"] < 0.1 * crack["depth_ratio"]
    assert fit.misfit.chi2_per_residual < 1.5   # the noise: the pair explains


def test_a_heavy_zone_standing_for_an_attached_mass_is_replaced_by_a_point_mass():
    """The model holds a heavy zone where the structure carries an attached mass (a user's
    guess, or an early pick that absorbed another missing effect): re-estimated, it ends on
    the edge of its range (mass ratio at its largest), the diagnosis says to replace it
    with a point mass, and that replacement lands on the mass (place within 1 % of the
    length, size within 3 %) and at the noise.  Data: the independent reference beam."""
    mass, at = 0.12, 0.31   # 9 % of the beam's mass
    measured = reference_data(point_masses=[(at, mass)])
    model = make_model().with_effects([Effect("section_loss", {
        "position": 0.30, "length": 0.05, "stiffness_ratio": 1.0, "mass_ratio": 2.0})])
    diagnosis = diagnose(model, measured, **NOISE)
    assert diagnosis.verdict == "effect_found" and diagnosis.suggested == ["point_mass"]
    assert diagnosis.replace == {"effect": "section_loss", "index": 0, "by": "point_mass"}
    assert diagnosis.to_json()["replace"] == diagnosis.replace
    # the replacement is the finding the table and JSON show first, with its own gain
    assert diagnosis.best.name == "point_mass" and diagnosis.best.gain > 0
    assert diagnosis.best.size_sigmas > 3
    assert any("ends on the edge of its range" in n and "--drop 0" in n
               for n in diagnosis.notes)
    outcome = update(model, measured, ["point_mass"], drop=[diagnosis.replace["index"]],
                     **NOISE)
    assert [e.name for e in outcome.model.effects] == ["point_mass"]
    assert "taken out first: section_loss (effects[0])" in outcome.notes
    p = outcome.model.effects[0].parameters
    assert abs(p["position"] - at) <= 0.01 * L and abs(p["mass"] / mass - 1) <= 0.03
    assert outcome.after.chi2_per_residual < 2.0
    assert diagnose(outcome.model, measured, **NOISE).verdict == "consistent"


def test_a_zone_inside_its_range_is_not_replaced():
    """A real heavy zone (ρA × 1.5 over 60 mm) is kept: its refit stays inside its range."""
    measured = reference_data(mass=zone(0.31, 0.06, 1.5))
    model = make_model().with_effects([Effect("section_loss", {
        "position": 0.30, "length": 0.05, "stiffness_ratio": 1.0, "mass_ratio": 1.3})])
    diagnosis = diagnose(model, measured, **NOISE)
    assert diagnosis.replace is None and diagnosis.verdict == "consistent"


def test_a_body_that_turns_with_the_beam_is_found_with_its_rotary_inertia():
    """A block on a cantilever's tip (mass 0.3 ρAL, radius of gyration 4 % of L), from the
    independent reference beam (its inertia on the slope there), 20 sensors between the
    nodes, noise as stated.  Before ``attached_body`` the first diagnosis named a point mass
    9 % heavy with a difference left, the next a section loss by the tip (EI × 0.74) that
    is not there, and the loop ended "unexplained" with it in the model.  Now the body is
    found at once, its mass and J, and the model is consistent after it.  Beside it: a mass
    with no rotary inertia stays a point mass (the body's J vanishes: it is significant
    only by J), and a model that holds the block's mass lacks only its J, which
    ``rotary_inertia`` finds at the mass."""
    rho_a = make_model().mass_per_length
    mass, radius = 0.3 * rho_a * L, 0.04 * L
    inertia = mass * radius**2
    x = np.linspace(0.0, L, 22)[1:-1] + 0.004
    cantilever = make_model(supports={"left": "clamped", "right": "free"})

    def data(**body):
        beam = ReferenceBeam(supports=("clamped", "free"), elements=600, **body)
        f, y = beam.measure(5, x, seed=17)
        return make_measured(x, "w", f, y, "tip-block")

    block = data(point_masses=[(L, mass)], point_inertias=[(L, inertia)])
    d = diagnose(cantilever, block, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["attached_body"], d.suggested
    found = d.best.parameters
    assert abs(found["position"] - L) <= 0.02 * L
    assert abs(found["mass"] / mass - 1) < 0.03
    assert abs(found["inertia"] / inertia - 1) < 0.1
    assert abs(found["inertia"] - inertia) < 3 * d.best.uncertainty["inertia"] + 0.02 * inertia
    after = update(cantilever, block, d.add_arguments(), **NOISE)
    assert diagnose(after.model, block, **NOISE).verdict == "consistent"

    plain = data(point_masses=[(0.4, mass)])
    assert diagnose(cantilever, plain, **NOISE).suggested == ["point_mass"]

    known_mass = cantilever.with_effects([Effect("point_mass", {"position": L, "mass": mass})])
    d = diagnose(known_mass, block, **NOISE)
    assert d.suggested == ["rotary_inertia"], d.suggested
    assert abs(d.best.effects[-1].parameters["inertia"] / inertia - 1) < 0.1
    assert abs(d.best.effects[-1].parameters["position"] - L) <= 0.02 * L


def test_a_body_inside_an_element_is_said_to_need_a_node_and_reads_exactly_on_one():
    """A heavy body (0.24 ρAL, 0.33 kg; r 5.9 % of L) at 0.32 m of a free-free beam, half
    an element from the nodes of 46: found within 5 % of its J, but its moment inside the
    element (the curvature jumps there; the cubic cannot follow) leaves the frequencies
    0.4 % from converged, and the next diagnosis is not consistent.  The note says so and
    names a mesh with a node by the body; on that mesh the same loop ends consistent, J
    within 2 % (the tip-body study's case 8117)."""
    rho_a = make_model().mass_per_length
    mass, inertia, x0 = 0.242 * rho_a * L, 3.72e-4, 0.32
    x = np.linspace(0.0, L, 17)[1:-1] + 0.003
    beam = ReferenceBeam(supports=("free", "free"), elements=600, point_masses=[(x0, mass)],
                         point_inertias=[(x0, inertia)])
    f, y = beam.measure(7, x, seed=8117)
    measured = make_measured(x, "w", f[2:], y[:, 2:], "body-inside")

    def loop_on(elements):
        model = make_model(supports={"left": "free", "right": "free"}, elements=elements)
        first = diagnose(model, measured, **NOISE)
        assert first.suggested == ["attached_body"], first.suggested
        after = update(model, measured, first.add_arguments(), **NOISE)
        return after.fit.parameters, diagnose(after.model, measured, **NOISE)

    body, d = loop_on(46)
    assert abs(body["inertia"] / inertia - 1) < 0.1
    assert d.verdict != "consistent"
    (note,) = [n for n in d.notes if "lies inside an element" in n]
    elements = int(note.split("elements = ")[1].split()[0])
    assert 46 < elements <= 4 * 46
    place = body["position"] / L * elements   # the mesh has a node by the body found
    assert abs(place - round(place)) < 0.05
    body, d = loop_on(elements)
    assert d.verdict == "consistent", d.notes
    assert abs(body["inertia"] / inertia - 1) < 0.02
    assert abs(body["mass"] / mass - 1) < 0.01
