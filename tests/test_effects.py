"""Effects as registered objects: the contract names, the physics of each new effect against
an independent reference beam, instances (local effects repeat, global ones do not), and an
effect a user registers."""

import numpy as np
import pytest
import scipy.optimize

import gfe_opt
from gfe_opt.diagnosis import diagnose, parse_effect, update
from gfe_opt.effects import EFFECTS, EffectType, Parameter, Variable, effect_type
from gfe_opt.errors import GfeInputError
from gfe_opt.fitting import fit_effects, noise_of
from gfe_opt.measured import make_measured
from gfe_opt.modal import model_modes
from gfe_opt.model import Effect, model_from_dict

from .conftest import STEEL_BEAM, make_model
from .reference import ReferenceBeam, christides_barr, interior, product, zone

NOISE = {"freq_noise": 0.0005, "shape_noise": 0.003}
L = 0.575


def test_effect_names_and_keys_are_the_contract():
    keys = {name: EFFECTS[name].keys for name in EFFECTS}
    assert keys["point_spring"] == ("position", "stiffness")
    assert keys["section_loss"] == ("position", "length", "stiffness_ratio", "mass_ratio")
    assert keys["stiffness_profile"] == keys["mass_profile"] == ("x", "ratio")
    assert {"material", "crack", "shear", "axial_load", "foundation", "support_spring",
            "point_mass"} <= set(keys)
    local = {n for n, e in EFFECTS.items() if e.local}
    assert {"crack", "point_mass", "point_spring", "section_loss"} <= local
    assert not local & {"material", "shear", "axial_load", "foundation"}


def _frequencies(model, n=5):
    return model_modes(model, n).frequencies_hz


@pytest.mark.parametrize("name,params,reference,tol", [
    ("point_spring", {"position": L / 2, "stiffness": 2e5},
     dict(point_springs=[(L / 2, 2e5)]), 1e-5),
    ("point_spring", {"position": 0.1, "stiffness": 5e4},  # between nodes
     dict(point_springs=[(0.1, 5e4)]), 1e-5),
    ("section_loss", {"position": 0.3, "length": 0.04, "stiffness_ratio": 0.7,
                      "mass_ratio": 0.7},
     dict(rigidity=zone(0.3, 0.04, 0.7), mass=zone(0.3, 0.04, 0.7)), 1e-4),
    ("stiffness_profile", {"x": [0.0, L], "ratio": [1.0, 0.8]},
     dict(rigidity=lambda x: 1.0 - 0.2 * x / L), 1e-6),
    ("stiffness_profile", {"x": [0.0, 0.2, L], "ratio": [1.0, 0.7, 1.1]},
     dict(rigidity=lambda x: np.interp(x, [0.0, 0.2, L], [1.0, 0.7, 1.1])), 1e-5),
    ("mass_profile", {"x": [0.0, L], "ratio": [1.2, 0.9]},
     dict(mass=lambda x: 1.2 - 0.3 * x / L), 1e-4),
])
def test_new_effects_match_an_independent_fine_beam(name, params, reference, tol):
    """Frequency ratios with and without the effect: the 46-element model's own mass
    discretisation error ((kh)^4/720, 1e-5 at mode 5) divides out."""
    plain = make_model()
    model = plain.with_effects([Effect(name, params)])
    want = ReferenceBeam(elements=1200, **reference).modes(5)[0]
    want_plain = ReferenceBeam(elements=1200).modes(5)[0]
    got = _frequencies(model) / _frequencies(plain)
    assert np.max(np.abs(got / (want / want_plain) - 1)) < tol


def test_two_cracks_are_two_instances_in_the_matrices():
    base = make_model()
    one = base.with_effects([Effect("crack", {"position": 0.12, "depth_ratio": 0.4})])
    two = base.with_effects([Effect("crack", {"position": 0.12, "depth_ratio": 0.4}),
                             Effect("crack", {"position": 0.42, "depth_ratio": 0.4})])
    want = ReferenceBeam(elements=1200, rigidity=product(christides_barr(0.12, 0.4),
                                                          christides_barr(0.42, 0.4))).modes(5)[0]
    plain = ReferenceBeam(elements=1200).modes(5)[0] / _frequencies(base)
    assert np.max(np.abs(_frequencies(two) * plain / want - 1)) < 2e-4
    assert np.max(np.abs(_frequencies(one) * plain / want - 1)) > 1e-2


def test_a_global_effect_may_not_repeat_and_a_local_one_may():
    data = dict(STEEL_BEAM, effects=[{"effect": "material", "E": 2e11},
                                     {"effect": "material", "E": 2.1e11}])
    with pytest.raises(GfeInputError, match=r"effects\[1\].effect: 'material' appears twice"):
        model_from_dict(data, "m.toml")
    data["effects"] = [{"effect": "crack", "position": 0.1, "depth_ratio": 0.3},
                       {"effect": "crack", "position": 0.4, "depth_ratio": 0.3}]
    assert [e.name for e in model_from_dict(data, "m.toml").effects] == ["crack", "crack"]


@pytest.fixture(scope="module")
def two_crack_data():
    s = interior(L, 45)
    f, y = ReferenceBeam(elements=1200, rigidity=product(
        christides_barr(0.12, 0.4), christides_barr(0.42, 0.4))).measure(5, s, seed=4)
    return make_measured(s, "w", f, y, "two-cracks")


def test_adding_crack_twice_finds_both(two_crack_data):
    outcome = update(make_model(), two_crack_data, ["crack", "crack"], **NOISE)
    positions = sorted(e.parameters["position"] for e in outcome.model.effects)
    assert [e.name for e in outcome.model.effects] == ["crack", "crack"]
    assert abs(positions[0] - 0.12) < 0.015 and abs(positions[1] - 0.42) < 0.015
    assert outcome.after.chi2_per_residual < 1.5


def test_a_crack_added_beside_a_present_one_does_not_move_it(two_crack_data):
    model = make_model().with_effects([Effect("crack", {"position": 0.12,
                                                        "depth_ratio": 0.3})])
    outcome = update(model, two_crack_data, ["crack:position=0.42"], **NOISE)
    first, second = (e.parameters for e in outcome.model.effects)
    assert abs(first["position"] - 0.12) < 0.015 and abs(first["depth_ratio"] - 0.4) < 0.05
    assert abs(second["position"] - 0.42) < 0.015 and abs(second["depth_ratio"] - 0.4) < 0.05
    # a model file with both refits both where they are (no collapse onto one place)
    fit = fit_effects(outcome.model, two_crack_data, [], noise=noise_of(**NOISE))
    assert sorted(round(e.parameters["position"], 2) for e in fit.effects) == [0.12, 0.42]


def test_a_global_effect_added_again_is_a_clear_error(two_crack_data):
    model = make_model().with_effects([Effect("material", {"E": 2.0e11})])
    with pytest.raises(GfeInputError, match="'material' appears twice"):
        update(model, two_crack_data, ["material"], **NOISE)
    with pytest.raises(GfeInputError, match="'shear' appears twice"):
        update(make_model(), two_crack_data, ["shear", "shear"], **NOISE)


@pytest.mark.parametrize("text,match", [
    ("crack:depth_ratio=1.5", "depth_ratio: must lie between 0 and 1"),
    ("point_mass:mass=-1", "mass: must be > 0"),
    ("crack:position=0.2,position=0.3", "position is given twice"),
    ("crack:position=2", "lies outside the structure"),
    ("crak", "did you mean 'crack'"),
    ("section_loss:stiffness_ratio=0", "stiffness_ratio: must lie in [0.01, 10]"),
])
def test_added_values_are_checked_like_model_files(text, match):
    with pytest.raises(GfeInputError, match=match.replace("[", r"\[").replace("]", r"\]")):
        parse_effect(text, make_model())


class TipMass(EffectType):
    """A user's effect: a mass at the right end (a cantilever's tip)."""

    name = "tip_mass"
    physics = "a mass at the right end"
    kinds = ("beam",)
    parameters = (Parameter("mass", "kg", "positive", "attached mass", null=0.0),)

    def contribute(self, model, params, build):
        build.add_point_mass(model.length, params["mass"])

    def variables(self, model, fixed):
        return [Variable("mass", 1e-4, 3.0, (0.05, 0.2, 0.5),
                         scale=lambda m: m.rho * m.area * m.length)]


def test_a_registered_effect_is_diagnosed_and_added():
    gfe_opt.register_effect(TipMass())
    try:
        cantilever = make_model(supports={"left": "clamped", "right": "free"})
        mass = 0.2 * cantilever.mass_per_length * L
        s = interior(L, 45)
        f, y = ReferenceBeam(elements=1200, supports=("clamped", "free"),
                             point_masses=[(L, mass)]).measure(5, s, seed=2)
        measured = make_measured(s, "w", f, y, "tip")
        result = diagnose(cantilever, measured, candidates=["material", "tip_mass"], **NOISE)
        assert result.best.name == "tip_mass"
        assert abs(result.best.parameters["mass"] / mass - 1) < 0.03
        outcome = update(cantilever, measured, ["tip_mass"], **NOISE)
        assert outcome.model.effects[0].name == "tip_mass"
        assert effect_type("tip_mass").describe(outcome.fit.effects[0].parameters,
                                                outcome.fit.sigma[0]).startswith("mass = ")
        with pytest.raises(ValueError, match="registered already"):
            gfe_opt.register_effect(TipMass())
    finally:
        del EFFECTS["tip_mass"]


@pytest.mark.parametrize("supports,effect,reference", [
    # a pin that gives: translational spring at the left end, rotation free
    (("pinned", "pinned"), Effect("support_translation", {"side": "left", "stiffness": 2e6}),
     dict(supports=("free", "pinned"), point_springs=[(0.0, 2e6)])),
    # both pins give
    (("pinned", "pinned"), Effect("support_translation", {"side": "both", "stiffness": 5e5}),
     dict(supports=("free", "free"), point_springs=[(0.0, 5e5), (L, 5e5)])),
    # a clamp that gives in rotation (the spring replaces the rotational fixity)
    (("clamped", "free"), Effect("support_spring", {"side": "left", "stiffness": 2e4}),
     dict(supports=("pinned", "free"), end_springs={"left": 2e4})),
    # a clamp that gives in translation, rotation still held
    (("clamped", "free"), Effect("support_translation", {"side": "left", "stiffness": 1e6}),
     dict(supports=("sliding", "free"), point_springs=[(0.0, 1e6)])),
])
def test_supports_that_give_match_an_independent_beam(supports, effect, reference):
    """Frequencies against the reference beam built another way (a free or sliding end with
    a spring at x = 0, or a pin with a rotational spring); the 46-element model's own
    discretisation error divides out through the same beam without the effect."""
    plain = make_model(supports=dict(zip(("left", "right"), supports)))
    model = plain.with_effects([effect])
    want = ReferenceBeam(elements=1200, **reference).modes(5)[0]
    want_plain = ReferenceBeam(elements=1200, supports=supports).modes(5)[0]
    got = _frequencies(model) / _frequencies(plain)
    assert np.max(np.abs(got / (want / want_plain) - 1)) < 1e-5
    # the change is real: at least 1 % on the first mode
    assert abs(got[0] - 1) > 0.01


def test_support_translation_needs_a_support_that_holds_the_translation():
    model = make_model(supports={"left": "free", "right": "pinned"})
    with pytest.raises(GfeInputError, match="left end is free"):
        model.with_effects([Effect("support_translation", {"side": "left", "stiffness": 1e5})])
    with pytest.raises(GfeInputError, match="did you mean 'support_translation'"):
        parse_effect("support_translaton", model)


def test_a_zone_fitted_past_an_end_is_the_part_on_the_structure():
    """section_loss variables past the right end give the zone on the beam; the fit starts
    past the end (off the kink) with the same zone; inside the beam nothing changes."""
    model = make_model()
    kind = effect_type("section_loss")
    variables = kind.variables(model, {})
    L = model.length
    past = np.array([0.8, 0.6, 0.9, 1.0])          # zone 0.5 L .. 1.1 L
    p = kind.to_physical(model, variables, past, {})
    assert p["position"] == pytest.approx(0.75 * L) and p["length"] == pytest.approx(0.5 * L)
    on_end = kind.to_variables(model, variables, p)
    assert kind.tie(model, variables, on_end) is not None
    moved = kind.untie(model, variables, on_end)
    assert moved[0] + moved[1] / 2 > 1.0             # the outer edge past the end
    again = kind.to_physical(model, variables, moved, {})
    assert again["position"] == pytest.approx(p["position"], abs=1e-12 * L)
    assert again["length"] == pytest.approx(p["length"], abs=1e-12 * L)
    inside = np.array([0.4, 0.2, 0.9, 1.0])
    assert kind.tie(model, variables, inside) is None
    assert np.array_equal(kind.untie(model, variables, inside), inside)


def _tip_body_frequencies(n_modes, EI, rho_a, length, mass, inertia):
    """Frequencies [Hz] of a clamped-free Euler–Bernoulli beam carrying at its tip a body
    of ``mass`` and rotary ``inertia``: w = A(cos βx − cosh βx) + B(sin βx − sinh βx)
    holds the clamp; at the tip EI w″ = ω² J w′ and EI w‴ = −ω² M w (the natural conditions
    of the body's kinetic energy); the roots of the 2 × 2 determinant in β, bracketed on a
    fine ladder."""
    def det(beta):
        x, w2 = beta * length, EI * beta**4 / rho_a
        c, s, ch, sh = np.cos(x), np.sin(x), np.cosh(x), np.sinh(x)
        w_a, w_b = c - ch, s - sh
        d1_a, d1_b = beta * (-s - sh), beta * (c - ch)
        d2_a, d2_b = beta**2 * (-c - ch), beta**2 * (-s - sh)
        d3_a, d3_b = beta**3 * (s - sh), beta**3 * (-c - ch)
        row1 = (EI * d2_a - w2 * inertia * d1_a, EI * d2_b - w2 * inertia * d1_b)
        row2 = (EI * d3_a + w2 * mass * w_a, EI * d3_b + w2 * mass * w_b)
        return (row1[0] * row2[1] - row1[1] * row2[0]) / np.cosh(x) ** 2

    ladder = np.linspace(0.3, 4 * (n_modes + 1), 40000) / length
    values = np.array([det(b) for b in ladder])
    roots = [scipy.optimize.brentq(det, ladder[i], ladder[i + 1])
             for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]
    beta = np.array(roots[:n_modes])
    return beta**2 * np.sqrt(EI / rho_a) / (2 * np.pi)


def test_a_tip_body_matches_the_closed_form_and_converges_at_fourth_order():
    """A cantilever with a body at its tip (mass 0.3 ρAL, rotary inertia 0.002 ρAL³): the
    frequencies of point_mass and rotary_inertia at x = L against the closed form's roots;
    the error falls as h⁴ (cubic Hermite elements, consistent mass), and the inertia
    lowers every mode (it is kinetic energy only)."""
    plain = make_model(supports={"left": "clamped", "right": "free"})
    rho_a, EI = plain.mass_per_length, plain.E * plain.inertia
    mass, inertia = 0.3 * rho_a * L, 0.002 * rho_a * L**3
    want = _tip_body_frequencies(5, EI, rho_a, L, mass, inertia)
    errors = []
    for n in (10, 20, 40, 80):
        model = plain.with_elements(n).with_effects([
            Effect("point_mass", {"position": L, "mass": mass}),
            Effect("rotary_inertia", {"position": L, "inertia": inertia})])
        errors.append(np.max(np.abs(_frequencies(model) / want - 1)))
    assert errors[-1] < 1e-6, errors
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(rates - 4) < 0.3), rates
    without = _frequencies(plain.with_elements(80).with_effects([
        Effect("point_mass", {"position": L, "mass": mass})]))
    assert np.all(want < without * (1 - 1e-3))
    # the same closed form without the inertia is the point mass's
    assert np.max(np.abs(without / _tip_body_frequencies(5, EI, rho_a, L, mass, 0.0) - 1)) \
        < 1e-6
