"""Frequency-only and sparse tests (issue 11): no shapes, or fewer than three sensors.

Measurements come from ``tests/reference.py`` (an independent fine-mesh beam): a cantilever
whose clamp gives (a pinned end with a rotational spring) and carries a tip mass, and a
simply supported beam with a Christides–Barr crack.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from gfe_opt.cli import main
from gfe_opt.correlation import compare
from gfe_opt.diagnosis import check_enough_modes, diagnose, update
from gfe_opt.errors import GfeInputError
from gfe_opt.measured import load_measured, make_measured
from gfe_opt.model import Effect
from gfe_opt.updating import update_generic
from tests.conftest import STEEL_BEAM, make_model
from tests.reference import STEEL, ReferenceBeam, christides_barr

L = STEEL["length"]
CANTILEVER = {**STEEL_BEAM, "name": "cantilever", "elements": 40,
              "supports": {"left": "clamped", "right": "free"}}
CLAMP = 2.0e4      # N m/rad: the clamp's rotational stiffness
TIP_MASS = 0.05    # kg at the free end


def cantilever_frequencies(n_modes=10, noise=0.0005, seed=3):
    truth = ReferenceBeam(supports=("pinned", "free"), elements=800,
                          end_springs={"left": CLAMP}, point_masses=[(L, TIP_MASS)])
    f, _ = truth.measure(n_modes, [L], shape_noise=0.0, freq_noise=noise, seed=seed)
    return f


def _rms_error(misfit):
    return misfit.summary()["freq_error_rms_pct"]


def test_files_without_shapes_read_and_compare_by_frequency(tmp_path, capsys):
    f = cantilever_frequencies(6)
    (tmp_path / "m.json").write_text(json.dumps(
        {"modes": [{"frequency": v} for v in f]}))
    (tmp_path / "m.csv").write_text("x," + ",".join(f"{v:.6f}" for v in f) + "\n")
    one_sensor = make_measured([L], "w", f, np.ones((1, f.size)), "one sensor")
    model = make_model(CANTILEVER)
    for measured in (load_measured(tmp_path / "m.json"), load_measured(tmp_path / "m.csv"),
                     one_sensor):
        assert measured.frequency_only
        c = compare(model, measured)
        assert c.pairing == "frequency" and c.mac_matrix is None and c.residual is None
        assert [p.test_mode for p in c.pairs] == list(range(1, 7))
        # paired one to one with the nearest model mode: the lowest test mode with the lowest
        assert [p.model_mode for p in c.pairs] == list(range(1, 7))
        assert all(p.mac is None for p in c.pairs)
    (tmp_path / "model.toml").write_text(
        "\n".join(f"{k} = {json.dumps(v)}" for k, v in CANTILEVER.items()
                  if not isinstance(v, dict)) + "\n"
        + "".join(f"[{k}]\n" + "".join(f"{kk} = {json.dumps(vv)}\n" for kk, vv in v.items())
                  for k, v in CANTILEVER.items() if isinstance(v, dict)))
    assert main(["compare", str(tmp_path / "model.toml"), str(tmp_path / "m.json"),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["pairing"] == "frequency" and out["mac_mean"] is None
    assert out["localisation"] is None
    assert all(p["mac"] is None for p in out["pairs"])
    assert main(["compare", str(tmp_path / "model.toml"), str(tmp_path / "m.csv")]) == 0
    text = capsys.readouterr().out
    assert "1.000" not in text and "paired by frequency" in text


def test_frequency_only_limits(tmp_path):
    f = cantilever_frequencies(3)
    measured = make_measured(None, "w", f, None, "three frequencies")
    model = make_model(CANTILEVER)
    with pytest.raises(GfeInputError, match="shapes"):
        update_generic(model, measured)
    check_enough_modes(measured, [Effect("material", {})])
    check_enough_modes(measured, [Effect("crack", {})])   # whether it is determined: the fit
    # frequencies alone: more frequencies than fitted parameters, whatever they are
    with pytest.raises(GfeInputError, match="3 measured frequencies cannot determine them"):
        check_enough_modes(measured, [Effect("crack", {}), Effect("material", {})])
    four = make_measured(None, "w", cantilever_frequencies(4), None, "four frequencies")
    check_enough_modes(four, [Effect("crack", {}), Effect("material", {})])


@pytest.mark.parametrize("start", [0.2, 0.8])
def test_a_cracks_mirror_image_is_named_not_guessed(start):
    """Symmetric pinned-pinned beam, frequencies only: a crack at 0.2 L and one at 0.8 L give
    the same frequencies; diagnose finds the crack and names both places."""
    position = start * L
    truth = ReferenceBeam(elements=800, rigidity=christides_barr(position, 0.35))
    f, _ = truth.measure(6, [L / 2], shape_noise=0.0, freq_noise=0.0003, seed=11)
    measured = make_measured(None, "w", f, None, "crack, frequencies only")
    d = diagnose(make_model(), measured, candidates=["crack", "material", "point_mass"],
                 freq_noise=0.0003)
    assert d.verdict == "effect_found" and d.best.name == "crack"
    found = d.best.effects[-1].parameters["position"]
    assert min(abs(found - position), abs(found - (L - position))) < 0.02 * L
    assert d.best.mirror_position == pytest.approx(L - found, abs=1e-6)
    assert any("mirror" in n for n in d.notes), d.notes
    # the caveat the text prints is the one the JSON and the figures read: the crack at
    # the mirror place, drawn hollow on the structure under the candidates
    caveat, = [c for c in d.caveats if c.kind == "mirror"]
    assert caveat in d.notes and caveat in [c["note"] for c in d.to_json()["caveats"]]
    (other,), = caveat.alternatives
    assert other.name == "crack" and other.parameters["position"] == pytest.approx(L - found)
    from gfe_opt.report import elsewhere
    assert elsewhere(d) == [(pytest.approx(L - found), "crack")]
    # and update, adding the crack as suggested, says it too: the updated model holds one
    # of two places, and its σ knows of neither
    outcome = update(make_model(), measured, d.suggested, freq_noise=0.0003)
    again, = [c for c in outcome.notes if getattr(c, "kind", None) == "mirror"]
    x = outcome.model.effects[-1].parameters["position"]
    assert again.alternatives[0][0].parameters["position"] == pytest.approx(L - x)
    assert outcome.to_json()["caveats"] == [again.to_json()]
    # and every diagnosis after it, of the model that holds the crack at one of the two
    later = diagnose(outcome.model, measured, candidates=["crack", "material", "point_mass"],
                     freq_noise=0.0003)
    present, = [c for c in later.caveats if c.kind == "mirror"]
    assert present.startswith("the present crack (effects[0]) at x = ") and present.present == 0
    assert later.drawn_alternatives == []   # the figures draw the finding's, not these
    assert present.alternatives[0][0].parameters["position"] == pytest.approx(L - x, abs=1e-3)


@pytest.mark.slow   # 40 s: the suite's 10 minutes; a frequency-only diagnosis runs in
# test_a_cracks_mirror_image_is_named_not_guessed
def test_frequency_only_cantilever_loop_ends_without_a_crack():
    """Ten frequencies of a cantilever whose clamp gives and which carries a tip mass: the
    loop (diagnose, add what it suggests, again) never adds a crack and never raises the
    error.  The soft clamp is found; with a tip mass the ten frequencies fit as well at
    (2.0e4 N m/rad, 0.050 kg, the truth) as at (2.4e5 N m/rad, 0.62 kg): χ² 2.2 and 2.4 for
    10 values.  The data do not determine the pair, and the tool says so (issue 21) and
    names the measurement that decides instead of picking one."""
    noise = 0.0005
    f = cantilever_frequencies(10, noise)
    measured = make_measured(None, "w", f, None, "cantilever, frequencies only")
    model = make_model(CANTILEVER)
    errors, added = [], []
    for _ in range(3):
        d = diagnose(model, measured, freq_noise=noise)
        errors.append(_rms_error(d.current))
        if d.verdict != "effect_found":
            break
        assert "crack" not in d.suggested, d.suggested
        outcome = update(model, measured, d.suggested, freq_noise=noise)
        assert _rms_error(outcome.after) <= errors[-1] + 1e-9
        model = outcome.model
        added += d.suggested
    else:
        pytest.fail(f"no end after adding {added}")
    assert "crack" not in added
    assert set(added) <= {"support_spring", "point_mass", "material", "support_translation"}
    assert np.all(np.diff(errors) <= 1e-9), errors
    spring = [e for e in model.effects if e.name == "support_spring"]
    assert spring, added
    if d.verdict != "consistent":   # the pair's two solutions named, and what decides
        undecided = [n for n in d.notes if n.startswith("not a finding")]
        assert undecided and "point_mass" in undecided[0], d.notes
        assert "mode shapes" in undecided[0] and not d.suggested
    else:
        assert errors[-1] < 2 * 100 * noise, errors   # rms error within twice the noise [%]


def test_two_cracks_fitted_together_are_one_end_whichever_slot_holds_which():
    """Six frequencies of a cantilever with two Rizos cracks (the truth generator's fine
    mesh, another law than the package's), both fitted from frequencies alone: the fit
    runs from many starts and ends with the two cracks in either slot.  Those are one
    structure, not another that fits as well: no equivalent end, no note repeating the
    finding in the other order (before, the note said the frequencies could not tell the
    cracks from themselves swapped, and a diagnosis reading such a pair called it not
    determined).  The cracks are found at the truths' places."""
    from gfe_opt.model import model_from_dict
    from tests import truths

    case = truths.draw("crack", 5501, pair_with="crack", frequency_only=True)
    assert case.shapes is None and [h.klass for h in case.hidden] == ["crack", "crack"]
    model = model_from_dict(case.model, case.name)
    measured = make_measured([], "w", case.frequencies, None, case.name)
    result = update(model, measured, ["crack", "crack"])
    found = sorted(e.parameters["position"] for e in result.fit.effects)
    truth = sorted(h.position for h in case.hidden)
    assert np.max(np.abs(np.subtract(found, truth))) < 0.02 * model.length
    for effects in result.fit.equivalent:   # any other end is another structure
        assert sorted(e.parameters["position"] for e in effects) != pytest.approx(
            found, abs=0.01 * model.length)
    assert not any(str(n).startswith("the frequencies fit as well with crack")
                   for n in result.notes)


def test_a_crack_in_the_valley_the_coarse_grid_ranked_second_is_found():
    """Seven frequencies of a clamped-pinned beam with a Rizos crack (another law than the
    package's; the truth generator's fine mesh): along the beam the crack's χ² has a valley
    every few tenths of the length, and the grid's coarse depths rank the valley of the
    truth (χ² 8.6 at its bottom) below one at 0.46 L (2 887).  The fit runs from every
    valley of the grid and ends at the truth's place, at the noise; from the grid's best
    point alone it ended in the wrong valley, and the diagnosis took a point mass."""
    from scipy.special import chdtri

    from gfe_opt.fitting import Noise, fit_effects
    from gfe_opt.model import model_from_dict
    from tests import truths

    case = truths.draw("crack", 2249, frequency_only=True)
    assert case.name == "crack-rizos-clamped-pinned-2249" and case.shapes is None
    model = model_from_dict(case.model, case.name)
    measured = make_measured([], "w", case.frequencies, None, case.name)
    fit = fit_effects(model, measured, [Effect("crack", {})], noise=Noise())
    x = fit.effects[-1].parameters["position"]
    assert abs(x - case.hidden[0].position) < 0.02 * model.length
    # at the noise: below the 99.9 % quantile of χ² with 7 frequencies − 2 parameters
    assert fit.success and fit.misfit.chi2 < chdtri(7 - 2, 1e-3)


def test_a_hinge_read_from_a_pinned_beams_frequencies_is_not_said_to_be_a_mass_alone():
    """A Rizos hinge (a rotational spring, not gfe-opt's crack law) at 0.23 L of a
    pinned–pinned beam, 8 frequencies alone: a point mass at the same place shifts them
    alike to first order (sin² of each mode there weighs both), and fits them to the noise
    (χ² 2.9); a section loss whose stiffness ratio sits on its lower bound fits them better
    still (0.85; a concentrated compliance, its length and ratio trading, so neither is
    determined alone and it was no finding of its own).  The diagnosis may name either, but
    must not name the mass alone: the caveat says the frequencies cannot tell it from the
    crack-like zone.  Before stop 77 the mass was said alone, as in the seed-2600 beam
    campaign's crack-rizos-pinned-pinned-2748 (the alike test then took significant fits
    only, and counted the parameter held on its bound)."""
    from tests.truths import rizos_compliance

    model = make_model(elements=60)
    x = 0.134
    compliance = rizos_compliance(0.45, model.E * model.inertia, model.depth)
    truth = ReferenceBeam(elements=800, hinges=[(x, 1.0 / compliance)])
    f, _ = truth.measure(8, [L / 2], shape_noise=0.0, freq_noise=0.0005, seed=2749)
    measured = make_measured(None, "w", f, None, "hinge, frequencies only")
    d = diagnose(model, measured, freq_noise=0.0005)
    assert d.verdict == "effect_found"
    crack_like = {"crack", "section_loss"}
    found = d.best.effects[-1].parameters["position"]
    assert min(abs(found - x), abs(found - (L - x))) < 0.02 * L
    if d.best.name not in crack_like:
        alike = [c for c in d.caveats if c.kind == "alike"]
        assert alike and any(n in alike[0] for n in crack_like), d.caveats
        assert "cannot tell" in alike[0]


@pytest.mark.xfail(strict=True, reason="known weakness (stop 87): a richer fit that fits as "
                   "well but loses by its parameters' count is not said alike; the rule that "
                   "says it also said every zone that merely re-describes the finding (README)")
def test_a_stiffness_loss_that_fits_as_well_as_a_mass_is_said_beside_it():
    """Seven frequencies of a cantilever with a notch (another law than the package's; the
    truth generator's fine mesh, noise 1.5 times the default, not stated).  A point mass
    fits them to the noise, and so does a short zone of lower stiffness at the notch's
    place, with two more parameters: the frequencies do not tell a mass from a stiffness
    loss there.  The point mass may be named (it ranks first by χ² and its parameters'
    count), but not alone: the zone should be said beside it, as an alternative at the
    notch, and listed as indistinguishable in the JSON.  The mass is said alone, a
    confident wrong answer: the zone stands 4.05 behind by χ²/s² + p ln n (ALIKE_CHI2
    3.84), all of it its two parameters more.  Saying alike every fit within 3.84 floors
    of χ² with more parameters fixes this case and adds 67 caveats to the two beam
    campaigns, nearly all a zone that re-describes the finding (a 3 mm zone of a tenth the
    stiffness for a crack, a 2 cm zone of three times the mass for a point mass, a zone
    over the beam for E): the rule needs a test of whether the two fits are one physical
    effect, not yet written."""
    from gfe_opt.model import model_from_dict
    from tests import truths

    case = truths.draw("crack", 7700, frequency_only=True)
    assert case.name == "crack-notch-clamped-free-7700" and case.shapes is None
    model = model_from_dict(case.model, case.name)
    measured = make_measured([], "w", case.frequencies, None, case.name)
    result = diagnose(model, measured)
    assert result.verdict == "effect_found"
    named = result.suggested[0]
    if named == "point_mass":
        alike = [c for c in result.caveats if c.kind == "alike"]
        assert alike, result.notes
        zones = [e for c in alike for effects in c.alternatives for e in effects
                 if e.name in ("section_loss", "crack")]
        assert zones and any(abs(e.parameters["position"] - case.hidden[0].position)
                             < 0.02 * model.length for e in zones), zones
        assert "section_loss" in result.to_json()["indistinguishable"]
    else:   # a stiffness loss named: at the notch
        fit = next(f for f in result.fits if f.name == named)
        assert abs(fit.effects[-1].parameters["position"] - case.hidden[0].position) \
            < 0.02 * model.length
