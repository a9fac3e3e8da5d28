"""``diagnose`` on plane frames, against tests generated independently: the exact dynamic
stiffness solution of the frame (tests/frame_reference.py: Euler–Bernoulli members, joints
and supports as springs, a crack as a line spring between two members) with noise; the
model is the package's finite-element frame without the effect.  Issue 24's setting: 6
modes, two points a member in x and y and the joints, 0.3 % shape and 0.05 % frequency
noise."""

import json
import re
from dataclasses import replace

import numpy as np
import pytest

from gfe_opt.diagnosis import diagnose, looks_like_noise, shape_correlation, update
from gfe_opt.fitting import misfit, noise_of
from gfe_opt.frame import frame_modes
from gfe_opt.frame_data import frame_measured_from_dict, load_frame_measured, neighbour_pairs
from gfe_opt.model import Effect, load_model
from gfe_opt.problems import portal_frame, problem_file
from gfe_opt.text import format_diagnosis

from .frame_reference import ExactFrame, self_stress, zone_frame

NOISE = {"freq_noise": 0.0005, "shape_noise": 0.003}


def _sensors(model):
    sensors = [{"node": "B", "direction": "x"}, {"node": "C", "direction": "y"}]
    for m in model.members:
        L = model.member_length(m)
        sensors += [{"member": m.id, "position": round(t * L, 4), "direction": d}
                    for t in (0.33, 0.71) for d in ("x", "y")]
    return sensors


def _measured(model, exact, guess_hz, sensors, seed, where=None, noise=NOISE):
    """6 exact modes near the ``guess_hz`` of a finite-element model (a bracket for the
    root finder, not the data), at ``sensors`` (``where`` maps a sensor to the exact frame's
    own), with ``noise``."""
    f = np.array([exact.frequency_near(x, 1e-3) for x in guess_hz])
    at = [where(s) for s in sensors] if where else sensors
    rng = np.random.default_rng(seed)
    modes = []
    for x in f:
        y = exact.mode_shape(x, at)
        modes.append({"frequency": float(x * (1 + noise["freq_noise"] * rng.standard_normal())),
                      "shape": [float(v) for v in y + noise["shape_noise"] * np.max(np.abs(y))
                                * rng.standard_normal(y.size)]})
    return frame_measured_from_dict({"sensors": sensors, "modes": modes}, model, "exact")


def _exact(model, joint_springs=(), ground_springs=()):
    return ExactFrame(model.nodes, [(m.start, m.end, m.E, m.rho, m.area, m.inertia)
                                    for m in model.members], dict(model.supports),
                      joint_springs, [m.id for m in model.members], ground_springs)


def line_spring_column(model, a, k):
    """The exact portal whose left column is two members joined ``a`` up from A by a
    rotational line spring ``k`` [N m/rad] (another crack law than the package's), and the
    map of a sensor on the model's left column to the exact frame's own."""
    nodes = {"A": (0.0, 0.0), "K": (0.0, a), **{n: model.nodes[n] for n in ("B", "C", "D")}}
    props = [(m.E, m.rho, m.area, m.inertia) for m in model.members]
    members = [("A", "K", *props[0]), ("K", "B", *props[0]), ("B", "C", *props[1]),
               ("D", "C", *props[2])]
    exact = ExactFrame(nodes, members, dict(model.supports), [("K", 1, k)],
                       ["lower", "upper", "beam", "right-column"])

    def where(s):
        if s.get("member") != "left-column":
            return s
        p = s["position"]
        return {**s, "member": "lower" if p < a else "upper", "position": p if p < a else p - a}

    return exact, where


class _Exact(ExactFrame):
    """The exact frame, its roots bracketed within 1 % where 0.1 % of the finite-element
    guess misses them (a body inside an element of the guess's mesh: its moment is not
    carried exactly there, README "A body that turns with the beam")."""

    def frequency_near(self, estimate_hz, width=1e-3):
        try:
            return super().frequency_near(estimate_hz, width)
        except ValueError:
            return super().frequency_near(estimate_hz, 1e-2)


def _exact_with_body(model, member_id, at, mass, inertia):
    """The exact portal with the body at ``at`` m along ``member_id`` (a joint when at an
    end), and the map of a sensor of the model to the exact frame's own."""
    base = _exact(model)
    m = model.member(member_id)
    length = model.member_length(m)
    if at in (0.0, length):
        node = m.start if at == 0.0 else m.end
        return _Exact(base.nodes, base.members, dict(model.supports), (),
                      base.member_ids, (), [(node, mass, inertia)]), None
    (x0, y0), (x1, y1) = model.nodes[m.start], model.nodes[m.end]
    t = at / length
    nodes = {**model.nodes, "K": (x0 + t * (x1 - x0), y0 + t * (y1 - y0))}
    k = [n.id for n in model.members].index(member_id)
    members, names = [], []
    for i, (row, name) in enumerate(zip(base.members, base.member_ids)):
        if i == k:
            members += [(row[0], "K", *row[2:]), ("K", row[1], *row[2:])]
            names += [f"{name}-a", f"{name}-b"]
        else:
            members.append(row)
            names.append(name)
    exact = _Exact(nodes, members, dict(model.supports), (), names, (),
                   [("K", mass, inertia)])

    def where(s):
        if s.get("member") != member_id:
            return s
        p = s["position"]
        return {**s, "member": f"{member_id}-{'a' if p < at else 'b'}",
                "position": p if p < at else p - at}

    return exact, where


def _guess(model, effects):
    fine = replace(model, members=tuple(replace(m, elements=40) for m in model.members))
    return frame_modes(fine.with_effects(effects, check=False), 6).frequencies_hz


def _diagnose(model, measured, **noise):
    """diagnose, its text and its JSON (a frame's sensors in "remaining") as the CLI
    prints them."""
    d = diagnose(model, measured, **noise)
    text = format_diagnosis(d, model)
    doc = json.loads(json.dumps(d.to_json()))
    assert doc["verdict"] == d.verdict and doc["add"] == d.add_arguments()
    for arg in d.add_arguments():
        assert f"--add {arg}" in text
    return d


# the second seed in the slow studies: the frame campaign's `none` class runs 8 portals more
@pytest.mark.parametrize("seed", [11, pytest.param(12, marks=pytest.mark.slow)])
def test_no_false_alarm_on_a_portal_that_is_as_modelled(seed):
    model = portal_frame()
    measured = _measured(model, _exact(model), _guess(model, []), _sensors(model), seed)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "consistent", d.notes


@pytest.mark.slow   # 60 s here: two diagnoses of the semi-rigid portal and its update
def test_the_frame_demo_tells_the_story_of_the_semirigid_portal(tmp_path, capsys):
    """``gfe-opt demo --frame``: the rigid-jointed portal against the shipped semi-rigid
    test; the diagnosis names a joint spring at each end of the beam, the update fits both
    within 2 % of the truth's 2000 N m/rad, the error falls to the noise, and the check
    after it says consistent.  What it prints, writes and draws come from one result: the
    update it prints is the updated file's, the report holds the printed tables."""
    from gfe_opt.cli import main
    from gfe_opt.demo import FRAME_DEMO_FILES, check_demo_folder

    out = tmp_path / "fdemo"
    assert main(["demo", "--frame", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "verdict: an effect is missing" in text
    assert "nothing significant is left: consistent" in text
    updated = load_model(out / "updated.toml", frames=True)
    springs = {e.parameters["node"]: e.parameters["stiffness"] for e in updated.effects
               if e.name == "joint_spring"}
    assert set(springs) == {"B", "C"} and len(updated.effects) == 2
    for stiffness in springs.values():
        assert stiffness == pytest.approx(2000.0, rel=0.02)
        assert f"stiffness = {stiffness:.5g}" in text
    after = re.search(r"after: frequency error ([0-9.]+) % rms", text)
    assert after and float(after.group(1)) < 0.1
    report = (out / "report.html").read_text()
    assert "joint_spring" in report and f"{springs['B']:.5g}" in report
    for name in ("frame_modes.png", "frame_diagnosis.png", "error.png"):
        assert (out / "figures" / name).stat().st_size > 0
    check_demo_folder(out, FRAME_DEMO_FILES)   # its own files: a second demo rewrites them


@pytest.mark.slow   # 52 s; the frame campaign's `joints` class and the README's semi-rigid
# portal (scripts/check_readme.py) run the same loop
def test_two_semirigid_joints_are_found_at_their_joints_and_then_the_portal_agrees():
    """The beam tied to both columns through 2000 N m/rad (the portal's 4EI/L is 9 000):
    with the noise not stated, the diagnosis suggests a joint spring at B and one at C
    together, each within 10 %; after them the model agrees."""
    model = portal_frame()
    beam = [m.id for m in model.members].index("beam")
    k = 2000.0
    truth = [Effect("joint_spring", {"node": n, "member": "beam", "stiffness": k})
             for n in ("B", "C")]
    exact = _exact(model, [("B", beam, k), ("C", beam, k)])
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 5)
    d = _diagnose(model, measured)
    assert d.verdict == "effect_found"
    assert d.suggested == ["joint_spring", "joint_spring"]
    # a uniform E fits better alone than one joint, and no second effect completes it: the
    # pair of joints is the finding, its first significant as the pair's
    material = next(f for f in d.fits if f.name == "material")
    assert material.misfit.chi2 < d.fits[0].misfit.chi2 and d.fits[0].significant
    found = {e.parameters["node"]: e.parameters["stiffness"] for e in d.together.effects}
    assert set(found) == {"B", "C"}   # at a two-member joint either member's end is one place
    # the pair holds both joints: neither is the other's alternative place (it was said)
    assert not any("cannot tell these places apart" in n for n in d.notes), d.notes
    for node, stiffness in found.items():
        assert stiffness == pytest.approx(k, rel=0.1), node
    # what diagnose prints to run next (and --json's "add"): each joint spring at its place
    assert sorted(d.add_arguments()) == sorted(
        f"joint_spring:node={e.parameters['node']},member={e.parameters['member']}"
        for e in d.together.effects)
    assert d.to_json()["add"] == d.add_arguments()
    # the figure says what the text says: its title the verdict, each spring at its joint
    # with the fitted value of the same result
    from gfe_opt.report import diagnosis_figures, verdict_title

    figs = diagnosis_figures(d, model)
    frame_axes, listing = figs["frame_diagnosis.png"].axes
    assert frame_axes.get_title(loc="left") == verdict_title(d) \
        == "joint_spring + joint_spring missing"
    labels = [t.get_text() for t in listing.texts]
    for e in d.together.effects:
        p = e.parameters
        assert any(t.endswith(f"joint_spring at {p['node']} ({p['member']}): stiffness "
                              f"{p['stiffness']:.3g} N m/rad") for t in labels), labels
    assert figs["candidates.png"].texts[0].get_text().endswith("joint_spring missing")
    after = update(model, measured, d.add_arguments(), **NOISE)
    assert {e.parameters["node"]: e.parameters["stiffness"] for e in after.model.effects} \
        == pytest.approx(found, rel=1e-4)
    again = diagnose(after.model, measured, **NOISE)
    assert again.verdict == "consistent", again.notes


@pytest.mark.slow   # 21 s each; the frame campaign's `material` class (8 cases a seed)
@pytest.mark.parametrize("scale,seed", [(1.03, 21), (0.985, 22)])
def test_a_portal_whose_steel_is_not_as_modelled_is_found_as_its_material(scale, seed):
    """Every member's E off by +3 % or -1.5 % (the exact solution of the frame with its
    members' E changed, not the package's effect): ``material`` is the finding, its change
    of E within 5 % of the truth's, and the model agrees after it."""
    model = portal_frame()
    truth = replace(model, members=tuple(replace(m, E=m.E * scale) for m in model.members))
    measured = _measured(model, _exact(truth), _guess(truth, []), _sensors(model), seed)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["material"], d.notes
    E = d.best.parameters["E"]
    assert E / model.E - 1 == pytest.approx(scale - 1, rel=0.05)
    # the figure draws the same result: every member, the fitted E
    from gfe_opt.report import diagnosis_figures

    frame_axes, listing = diagnosis_figures(d, model)["frame_diagnosis.png"].axes
    assert [t.get_text() for t in listing.texts] == [
        f"1: material of every member: E {E:.3g} Pa"]
    after = update(model, measured, ["material"], **NOISE)
    again = diagnose(after.model, measured, **NOISE)
    assert again.verdict == "consistent", again.notes


@pytest.mark.slow   # 50-85 s since zones are candidates; the semi-rigid pair stays in the suite
def test_two_loose_joints_are_a_pair_not_one_joint_that_may_be_at_the_other():
    """Both beam joints at about 900 N m/rad, 2.4x the noise, not stated (a case of the
    frame campaign): the pair of joint springs is suggested, and the first joint's fit
    alone, which fits nearly as well at the other joint, is not said to be undecided
    between B and C: the pair holds both (the note was printed beside the pair)."""
    model = portal_frame()
    beam = [m.id for m in model.members].index("beam")
    ks = {"B": 909.2, "C": 807.7}
    truth = [Effect("joint_spring", {"node": n, "member": "beam", "stiffness": k})
             for n, k in ks.items()]
    measured = _measured(model, _exact(model, [(n, beam, k) for n, k in ks.items()]),
                         _guess(model, truth), _sensors(model), 3,
                         noise={k: 2.37 * v for k, v in NOISE.items()})
    d = _diagnose(model, measured)
    assert d.verdict == "effect_found" and d.suggested == ["joint_spring", "joint_spring"]
    found = {e.parameters["node"]: e.parameters["stiffness"] for e in d.together.effects}
    assert found == pytest.approx(ks, rel=0.1)
    assert not any("cannot tell these places apart" in n for n in d.notes), d.notes


@pytest.mark.slow   # 26 s; the frame campaign's `support` class (a base A or D that turns)
def test_a_clamp_that_gives_is_a_support_spring_at_its_node():
    """The left base turns against 3000 N m/rad instead of being clamped: a support spring
    at A, within 10 %, then consistent."""
    model = portal_frame()
    k = 3000.0
    truth = [Effect("support_spring", {"node": "A", "stiffness": k})]
    exact = _exact(model, ground_springs=[("A", 2, k)])
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 7)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found"
    best = d.together.effects[-1] if d.together is not None else d.best.effects[-1]
    assert d.suggested == ["support_spring"], d.notes
    assert best.parameters["node"] == "A"
    assert best.parameters["stiffness"] == pytest.approx(k, rel=0.1)
    after = update(model, measured, d.add_arguments(), **NOISE)   # as printed
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


@pytest.mark.slow   # 23 s; the frame campaign's `crack` class (any member, 15-85 % along it)
def test_a_crack_near_a_column_base_is_found_on_that_column_at_its_place():
    """Another crack law than the package's: the exact frame's left column is two members
    joined at 0.06 m by a rotational line spring of 46 000 N m/rad (about a/h 0.3 of a
    single-edge crack); the model knows only Christides–Barr cracks.  The diagnosis names a
    crack on the left column within 2 % of its length of the line spring, and after it the
    model agrees."""
    model = portal_frame()
    a = 0.06
    exact, where = line_spring_column(model, a, 46000.0)
    bracket = [Effect("crack", {"member": "left-column", "position": a, "depth_ratio": 0.5})]
    measured = _measured(model, exact, _guess(model, bracket), _sensors(model), 9, where)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found", d.notes
    assert d.suggested[0] == "crack"
    crack = (d.together or d.best).effects[0]
    assert crack.parameters["member"] == "left-column"
    assert abs(crack.parameters["position"] - a) < 0.02 * 0.3
    after = update(model, measured, d.add_arguments(), **NOISE)   # as printed
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


# slow since stop 46 (11 s on a slow hour; the suite reached 11.5 min there): the frame
# campaign's `lean` class draws 4 such cases a seed, every member, across it
@pytest.mark.slow
def test_a_column_leaning_on_a_wall_is_a_point_spring_there():
    """The left column held across (x) at 40 % of its height by a spring to ground of 30
    times its EI/L³ (a wall it touches, a brace to the next frame): the exact frame with the
    column cut there.  Before frames took point springs, a section loss and a support
    spring stood in for it (a confident wrong answer); now the diagnosis names a point spring
    on that column, in x, within 2 % of its length, the stiffness within 10 %, drawn and
    printed at its place.  (That the model agrees after it, the loop's end, is the frame
    campaign's ``lean`` class: 8 cases a seed, every member, across it.)"""
    model = portal_frame()
    column = model.member("left-column")
    L = model.member_length(column)
    k, a = 30 * column.E * column.inertia / L**3, 0.4 * L
    exact, where = zone_frame(model, "left-column", a, a, 1.0, 1.0, [("Z1", (1.0, 0.0), k)])
    bracket = [Effect("point_spring", {"member": "left-column", "position": a,
                                       "direction": "x", "stiffness": k})]
    measured = _measured(model, exact, _guess(model, bracket), _sensors(model), 4, where)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["point_spring"], d.notes
    found = d.best.effects[0].parameters
    assert (found["member"], found["direction"]) == ("left-column", "x")
    assert abs(found["position"] - a) < 0.02 * L
    assert found["stiffness"] == pytest.approx(k, rel=0.1)
    assert d.add_arguments() == ["point_spring:member=left-column,direction=x"]
    from gfe_opt.frame_data import effect_place
    from gfe_opt.report import diagnosis_figures

    place = f"left-column at {found['position']:.3g} m in x"
    assert effect_place(model, d.best.effects[0]) == place
    frame_axes, listing = diagnosis_figures(d, model)["frame_diagnosis.png"].axes
    assert any(t.get_text().startswith(
        f"1: point_spring on left-column at {found['position']:.3g} m in x: stiffness "
        f"{found['stiffness']:.3g} N/m") for t in listing.texts)


# both slow since the suite reached 10 min on a slow hour: the frame campaign's `zone` class
# runs 8 zones a seed (a quarter of them at a joint or a base)
@pytest.mark.parametrize("start, end, ratio, seed", [
    pytest.param(0.21, 0.29, 1.6, 5, marks=pytest.mark.slow),   # a doubler plate in the beam
    pytest.param(0.0, 0.06, 2.5, 6, marks=pytest.mark.slow),   # a haunch at joint B
])
def test_a_stiffer_zone_of_the_beam_is_a_section_loss_there(start, end, ratio, seed):
    """Part of the beam deeper than modelled (I × ratio, A and ρA × its cube root): the exact
    frame with the beam split at the zone's edges.  The diagnosis names a section loss on
    the beam, its centre within 2 % of the beam's length, its added bending compliance
    ℓ (1/r − 1)/EI within 10 %, drawn over its extent in the figure as the text gives it;
    after it the model agrees."""
    model = portal_frame()
    beam = model.member("beam")
    exact, where = zone_frame(model, "beam", start, end, ratio, ratio ** (1 / 3))
    bracket = [Effect("section_loss", {"member": "beam", "position": (start + end) / 2,
                                       "length": end - start, "stiffness_ratio": ratio,
                                       "mass_ratio": ratio ** (1 / 3)})]
    measured = _measured(model, exact, _guess(model, bracket), _sensors(model), seed, where)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["section_loss"], d.notes
    zone = d.best.effects[0].parameters
    assert zone["member"] == "beam"
    assert abs(zone["position"] - (start + end) / 2) < 0.02 * model.member_length(beam)
    compliance = zone["length"] * (1 / zone["stiffness_ratio"] - 1)
    assert compliance == pytest.approx((end - start) * (1 / ratio - 1), rel=0.1)
    from gfe_opt.report import diagnosis_figures

    frame_axes, listing = diagnosis_figures(d, model)["frame_diagnosis.png"].axes
    labels = [t.get_text() for t in listing.texts]
    assert any(t.endswith(f"section_loss on beam at {zone['position']:.3g} m: length "
                          f"{zone['length']:.3g} m, stiffness_ratio "
                          f"{zone['stiffness_ratio']:.3g}, mass_ratio "
                          f"{zone['mass_ratio']:.3g}") for t in labels), labels
    after = update(model, measured, d.add_arguments(), **NOISE)
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


def test_each_member_as_long_as_the_best_one_is_fitted_again_from_the_best_place():
    """The best member's local effect, as found, starts the fit on every other member of its
    length (its distance from the start node, its length and sizes): a member whose own
    grid ended in a valley of its own (a portal's left column, whose zone near its foot was
    fitted at its top, while the right column's foot fitted better) is fitted again from
    the place its mirror image holds.  Members of another length, the best member itself
    and effects without a place along a member get no such start; a value the user gave
    stays."""
    from types import SimpleNamespace

    from gfe_opt.diagnosis import _same_place_elsewhere

    model = portal_frame()
    found = {"position": 0.0543, "length": 0.0111, "stiffness_ratio": 3.0, "mass_ratio": 1.29}

    def fit(member, **params):
        return SimpleNamespace(added=0, effects=(Effect("section_loss", {
            "member": member, **params}),))

    best = fit("right-column", **found)
    fits = [fit("left-column", position=0.287, length=0.026, stiffness_ratio=0.97,
                mass_ratio=0.53), fit("beam", position=0.39, length=0.009,
                                      stiffness_ratio=1.2, mass_ratio=0.05), best]
    assert _same_place_elsewhere(model, best, fits) == [
        (0, {"member": "left-column", **found})]
    assert _same_place_elsewhere(model, best, fits, {"mass_ratio": 1.0}) == [
        (0, {"member": "left-column", **found, "mass_ratio": 1.0})]
    beam = fits[1]
    assert _same_place_elsewhere(model, beam, fits) == []   # no other member is as long
    joint = SimpleNamespace(added=0, effects=(Effect("joint_spring", {
        "node": "B", "member": "beam", "stiffness": 2000.0}),))
    assert _same_place_elsewhere(model, joint, [joint, fits[0]]) == []


@pytest.mark.slow   # the rule's mechanism: the test above
def test_update_at_a_named_member_ends_where_the_diagnosis_did(monkeypatch):
    """The frame campaign's zone-3417, rebuilt here (3.3 cm of the left column, 5 to 8 cm
    above its base, 1.45 times as stiff; 1.42 times the usual noise, its measurement seed):
    the left column's own grid ends at the column's top; the diagnosis found the zone from
    the right column's place.  ``update --add section_loss:member=left-column`` (as the
    diagnosis prints it) fits the right column too and starts the left one from its place:
    the zone at its centre (within 2 % of the column), then consistent.  Without the start
    from the other column the update ends at the column's top."""
    from gfe_opt import diagnosis

    model = portal_frame()
    a, b, ratio = 0.04968723017791041, 0.08281547959797414, 1.4524548838899691
    exact, where = zone_frame(model, "left-column", a, b, ratio, ratio ** (1 / 3))
    bracket = [Effect("section_loss", {"member": "left-column", "position": (a + b) / 2,
                                       "length": b - a, "stiffness_ratio": ratio,
                                       "mass_ratio": ratio ** (1 / 3)})]
    noise = {k: 1.4165071946211496 * v for k, v in NOISE.items()}
    measured = _measured(model, exact, _guess(model, bracket), _sensors(model), 1932420502,
                         where, noise)
    args = ["section_loss:member=left-column"]
    after = update(model, measured, args, **noise)
    zone = after.model.effects[0].parameters
    assert abs(zone["position"] - (a + b) / 2) < 0.02 * 0.3, zone
    assert diagnose(after.model, measured, **noise).verdict == "consistent"
    monkeypatch.setattr(diagnosis, "_same_place_elsewhere", lambda *args: [])
    alone = update(model, measured, args, **noise).model.effects[0].parameters
    assert alone["position"] > 0.2, alone          # the column's top: its own valley


@pytest.mark.slow   # the told trade's mechanism: tests/test_fitting_numerics.py
def test_a_zone_shorter_than_the_modes_resolve_is_named_by_its_compliance():
    """2 cm of the right column (7 % of it) twice as stiff, at 1.7 times the usual noise
    (stated): six modes at two sensors a member cannot tell its length from its ratios.
    The diagnosis still names a section loss there (its distance from nothing the
    likelihood ratio's), its centre within 2 % of the column, its added compliance
    ℓ (1/r − 1) within 10 %, and says which parameters trade (the JSON's ``traded``, not
    ``not_estimable``); after it the model agrees."""
    model = portal_frame()
    a, b, ratio = 0.09, 0.11, 2.0
    exact, where = zone_frame(model, "right-column", a, b, ratio, ratio ** (1 / 3))
    bracket = [Effect("section_loss", {"member": "right-column", "position": 0.1,
                                       "length": 0.02, "stiffness_ratio": ratio,
                                       "mass_ratio": ratio ** (1 / 3)})]
    noise = {k: 1.7 * v for k, v in NOISE.items()}
    measured = _measured(model, exact, _guess(model, bracket), _sensors(model), 8, where,
                         noise)
    d = _diagnose(model, measured, **noise)
    assert d.verdict == "effect_found" and d.suggested == ["section_loss"], d.notes
    zone = d.best.effects[0].parameters
    assert zone["member"] == "right-column" and abs(zone["position"] - 0.1) < 0.02 * 0.3
    assert zone["length"] * (1 / zone["stiffness_ratio"] - 1) == pytest.approx(
        (b - a) * (1 / ratio - 1), rel=0.1)
    entry = next(e for e in d.to_json()["effects"] if e["effect"] == "section_loss")
    assert entry["traded"] and not entry["not_estimable"]
    # the compliance the data fix, within 3 of its σ of the truth's, told in the note too
    column = model.member("right-column")
    told = entry["told"]["compliance"]
    truth = (b - a) * (1 / ratio - 1) / (column.E * column.inertia)
    assert abs(told["value"] - truth) < 3 * told["sigma"] and told["unit"] == "rad/(N m)"
    # determined (2 σ from nothing) while the length alone is not (σ above its value)
    assert told["sigma"] < 0.5 * abs(told["value"])
    assert entry["uncertainty"]["length"] > entry["parameters"]["length"]
    assert any("the data fix their combination (added bending compliance" in n
               and f"{told['value']:.3g} ± {told['sigma']:.2g} rad/(N m)" in n
               for n in d.notes), d.notes
    after = update(model, measured, d.add_arguments(), **noise)
    assert diagnose(after.model, measured, **noise).verdict == "consistent"


@pytest.mark.slow   # 28 s; the frame campaign's `mass` class (a mass at joint B or C)
def test_a_mass_added_at_a_joint_is_a_point_mass_there():
    """0.1 kg at joint C (the beam weighs 0.157 kg): a point mass at C (an end of the beam
    or of the right column: one place), within 10 %, then consistent."""
    model = portal_frame()
    mass = 0.1
    truth = [Effect("point_mass", {"member": "beam", "position": 0.4, "mass": mass})]
    exact = _exact(model)
    exact = ExactFrame(exact.nodes, exact.members, dict(model.supports), (),
                       exact.member_ids, (), [("C", mass)])
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 13)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found", d.notes
    assert d.suggested == ["point_mass"], d.notes
    found = d.best.effects[-1].parameters
    member = model.member(found["member"])
    end = {0.0: member.start, model.member_length(member): member.end}
    at = next((node for x, node in end.items() if abs(found["position"] - x) < 0.02 * 0.4), None)
    assert at == "C", found
    assert found["mass"] == pytest.approx(mass, rel=0.1)
    after = update(model, measured, d.add_arguments(), **NOISE)   # as printed
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


def _braced_portal():
    """The portal with a slender diagonal brace from A to C (A = 2 mm², I = 1e-10 m⁴): its
    axial stiffness is of the order of the portal's own in sway."""
    from gfe_opt.frame import frame_from_dict, frame_to_dict

    data = frame_to_dict(portal_frame())
    data["members"].append({"id": "brace", "from": "A", "to": "C", "elements": 20,
                            "material": data["members"][0]["material"],
                            "section": {"A": 2e-6, "I": 1e-10}})
    return frame_from_dict(data, "braced portal")


def loose_brace(ratio):
    """The braced portal, the exact frame whose brace carries ``ratio`` of its modelled EA
    (E × ratio and I / ratio: EI and ρA kept) and a bracket of its frequencies."""
    model = _braced_portal()
    members = []
    for m in model.members:
        props = (m.E, m.rho, m.area, m.inertia)
        if m.id == "brace":
            props = (ratio * m.E, m.rho, m.area, m.inertia / ratio)
        members.append((m.start, m.end, *props))
    exact = ExactFrame(model.nodes, members, dict(model.supports), (),
                       [m.id for m in model.members])
    truth = [Effect("axial_stiffness", {"member": "brace", "ratio": ratio})]
    return model, exact, _guess(model, truth)



def test_a_loose_brace_is_a_lower_axial_stiffness_of_that_brace():
    """The brace carries 40 % of its modelled EA (its bending and mass as modelled), built
    in the exact frame another way: E 0.4 E and I I/0.4 (EI and ρA kept).  The diagnosis names the
    axial stiffness of the brace, within 10 %, and after it the model agrees."""
    ratio = 0.4
    model, exact, guess = loose_brace(ratio)
    measured = _measured(model, exact, guess, _sensors(model), 17)
    _found_on_the_brace_then_consistent(model, measured, "axial_stiffness", "ratio", ratio)


def _found_on_the_brace_then_consistent(model, measured, name, key, truth):
    """``diagnose`` names ``name`` on the brace, its ``key`` within 10 % of ``truth``; after
    ``update`` with the printed arguments the next diagnosis says ``consistent``."""
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found", d.notes
    assert d.suggested == [name], d.notes
    found = d.best.effects[-1].parameters
    assert found["member"] == "brace"
    assert found[key] == pytest.approx(truth, rel=0.1)
    after = update(model, measured, d.add_arguments(), **NOISE)   # as printed
    assert diagnose(after.model, measured, **NOISE).verdict == "consistent"


def _tensioned_brace(strain, seed):
    """The braced portal whose brace was made ``strain`` × its length shorter before it was
    pinned in (a turnbuckle): every member's axial force from the exact static solution
    (the brace pulls, the portal's members push back), each carried in the exact frame's
    members (EI w⁗ − T w″); the model, measured data, and the brace's force [N]."""
    model = _braced_portal()
    members = [(m.start, m.end, m.E, m.rho, m.area, m.inertia) for m in model.members]
    ids = [m.id for m in model.members]
    forces = self_stress(model.nodes, members, dict(model.supports), ids.index("brace"),
                         strain)
    exact = ExactFrame(model.nodes, [(*m, t) for m, t in zip(members, forces)],
                       dict(model.supports), (), ids)
    truth = [Effect("axial_load", {"member": i, "tension": t}) for i, t in zip(ids, forces)]
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), seed)
    return model, measured, forces[ids.index("brace")]


def test_a_brace_pulled_tight_is_fitted_as_the_axial_load_of_that_brace():
    """A brace shortened by 5e-4 before it was fitted pulls 102 N (12 % of its Euler load)
    and the portal's members push back (up to 41 N, below 0.1 % of theirs): ``update
    --add axial_load``, its member not given, fits every member's and keeps the brace's,
    within 10 % of the exact force, to the noise."""
    model, measured, force = _tensioned_brace(5e-4, 32)
    out = update(model, measured, ["axial_load"], **NOISE)
    found = out.model.effects[-1].parameters
    assert found["member"] == "brace"
    assert found["tension"] == pytest.approx(force, rel=0.1)
    assert out.before.chi2_per_residual > 20 and out.after.chi2_per_residual < 1.5


@pytest.mark.slow   # about 35 s; the update of the test above is its fit
def test_a_brace_pulled_tight_is_diagnosed_as_its_axial_load_and_then_the_portal_agrees():
    model, measured, force = _tensioned_brace(5e-4, 32)
    _found_on_the_brace_then_consistent(model, measured, "axial_load", "tension", force)


def test_unstated_noise_on_a_frame_needs_white_components_and_frequencies_at_a_tests_precision():
    """Neighbours in the whiteness test are one component along the structure (an x and a y
    reading at one point are not); and where a frame's few sensors leave the test weak, a
    model whose frequencies are off by far more than a test's precision is no model at the
    noise, however white its shape residuals.  On the shipped semi-rigid portal (exact,
    2000 N m/rad at both ends of the beam): one joint spring alone is not noise, both are."""
    model = portal_frame()
    sensors = _sensors(model)
    a, b = neighbour_pairs(model, sensors)
    assert len(a) == len(sensors) - 2   # one chain in x, one in y
    assert all(sensors[i]["direction"] == sensors[j]["direction"] for i, j in zip(a, b))
    measured = load_frame_measured(problem_file("portal-frame-semirigid.json"), model)
    noise = noise_of(None, None)

    def noise_like(nodes):
        m = model.with_effects([Effect("joint_spring", {"node": n, "member": "beam",
                                                        "stiffness": 2000.0}) for n in nodes])
        fit = misfit(m, measured, noise)
        return looks_like_noise(m, fit, shape_correlation(m, measured, noise), measured), fit

    one, fit_one = noise_like(["C"])
    both, fit_both = noise_like(["B", "C"])
    assert fit_one.freq_error_rms_pct > 1.0 and not one
    assert fit_both.freq_error_rms_pct < 0.2 and both


@pytest.mark.parametrize("seed, mass, factor, alike", [
    (26, 0.1087, 2.3, True), pytest.param(21, 0.1087, 2.3, True, marks=pytest.mark.slow),
    # slow since stop 46 (the suite reached 11 min on slow hours): the frame campaign's
    # `mass` class draws 4 corner masses a seed, most of them told apart
    pytest.param(3, 0.15, 1.0, False, marks=pytest.mark.slow)])
def test_a_mass_at_a_corner_of_the_symmetric_portal_names_the_corner_it_cannot_tell_apart(
        seed, mass, factor, alike):
    """The portal is symmetric: a mass at joint C and one at joint B give the same
    frequencies and shapes that differ a little.  At 2.3x the noise (not stated) 0.11 kg
    there lies about 4 noise floors from its mirror, where noise picks the wrong corner one
    time in four (the frame campaign, scripts/bench_frame_diagnosis.py, found masses at
    the wrong corner without a word, one with Δχ² 59 in the wrong one's favour): the
    diagnosis names C and says B may as well be right (seed 26: B's χ² within 3.84 floors;
    seed 21: 21 worse, but the two places' predictions lie closer than the 10.8 floors at
    which noise picks the wrong one 5 % of the time).  0.15 kg at the stated noise lies
    20 floors from its mirror: C, and no such note."""
    model = portal_frame()
    base = _exact(model)
    exact = ExactFrame(base.nodes, base.members, dict(model.supports), (), base.member_ids,
                       (), [("C", mass)])
    truth = [Effect("point_mass", {"member": "beam", "position": 0.4, "mass": mass})]
    noisy = {k: factor * v for k, v in NOISE.items()}
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), seed,
                         noise=noisy)
    d = _diagnose(model, measured, **({} if alike else NOISE))
    assert d.verdict == "effect_found" and d.suggested == ["point_mass"], d.notes
    found = d.best.effects[-1]
    assert found.parameters["mass"] == pytest.approx(mass, rel=0.1)
    from gfe_opt.frame_data import effect_place

    assert effect_place(model, found) == "node C"
    said = [n for n in d.notes if "cannot tell these places apart" in n]
    if alike:
        assert len(said) == 1 and said[0].startswith(
            "the point_mass at node C may as well be at node B"), d.notes
        assert said[0] in json.loads(json.dumps(d.to_json()))["notes"]
    else:
        assert not said, d.notes
    # a place given in full (--add point_mass:member=beam,position=0.4): it stopped with an
    # internal error (the position was read as a fraction of a beam's length)
    at_c = update(model, measured, ["point_mass:member=right-column,position=0.3"])
    assert at_c.model.effects[0].parameters["mass"] == pytest.approx(mass, rel=0.1)


def _body_at_corner(mass, radius, seed, known=False, node="C"):
    """The portal with a body at joint ``node`` (B or C; ``mass`` kg, J = mass radius²) in
    the exact frame (its mass and J on the joint's DOFs), and the model (``known``: holding
    the body's mass as a point mass there)."""
    model = portal_frame()
    inertia = mass * radius**2
    end = model.member_length(model.member("beam")) if node == "C" else 0.0
    exact, _ = _exact_with_body(model, "beam", end, mass, inertia)
    truth = [Effect("attached_body", {"member": "beam", "position": end, "mass": mass,
                                      "inertia": inertia})]
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), seed)
    if known:
        model = model.with_effects([Effect("point_mass", {"member": "beam", "position": end,
                                                          "mass": mass})])
    return model, measured, inertia


@pytest.mark.parametrize("node, mass, radius", [("C", 0.3, 0.03), ("B", 0.136, 0.0104)])
def test_a_body_at_a_frame_corner_is_found_with_its_rotary_inertia(node, mass, radius):
    """A block on a corner of the portal whose rotary inertia turns with the joint: 0.3 kg
    (a fifth of the beam's mass) of radius of gyration 3 cm on C, and 136 g of 1 cm on B.
    The diagnosis reads the point mass again as a body (``attached_body``, selection step
    6): at the corner (within 2 % of a member's length), its mass and J within 3 σ of the
    truth; ``consistent`` after ``update``.  Before frames took the body, the point mass
    alone left χ²/n 77 on C and a section loss by the corner was named first; the small
    block on B was read as a point mass 1.04 ± 0.05 cm into the beam."""
    from gfe_opt.frame_data import effect_place

    model, measured, inertia = _body_at_corner(mass, radius, 5, node=node)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["attached_body"], d.notes
    body, sigma = d.best.effects[-1], d.best.sigma[-1]
    assert effect_place(model, body) == f"node {node}"
    for key, truth in (("mass", mass), ("inertia", inertia)):
        assert abs(body.parameters[key] - truth) < 3 * sigma[key], (key, body, sigma)
        assert body.parameters[key] == pytest.approx(truth, rel=0.2)
    after = update(model, measured, d.add_arguments(), **NOISE)
    assert _diagnose(after.model, measured, **NOISE).verdict == "consistent"


def test_a_body_inside_a_column_element_is_not_a_point_mass_placed_with_confidence():
    """A block of 0.12 kg, radius of gyration 4.2 cm (J 2.1e-4 kg m²) at 0.0675 m up the
    portal's left column, inside an element (the column's 20 elements put nodes at 0.06 and
    0.075 m), in the exact frame with the column split at the block.  A point mass slid
    off it, at 0.084 m, fits the data as well as the body (the data cannot tell a mass's J
    from a shift along a column's rising slope), and its place's σ is 0.3 mm.  Before, that
    mass was said alone, a confident wrong place (``scripts/study_frame_body.py`` cases
    9108 and 9201).  Now, whatever the finding: where it is a point mass more than 2 % of
    the column off the block, a caveat says that a body that turns fits as well over a
    range of places that holds the block's within 2 % of the column, one of its
    alternatives a body there, and the text, the JSON and the figure's alternatives say
    the same; ``consistent`` after the update, where the caveat is said again on the
    point mass the model now holds."""
    model = portal_frame()
    length = model.member_length(model.member("left-column"))
    at, mass, radius = 0.0675, 0.12, 0.042
    exact, where = _exact_with_body(model, "left-column", at, mass, mass * radius**2)
    truth = [Effect("attached_body", {"member": "left-column", "position": at,
                                      "mass": mass, "inertia": mass * radius**2})]
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 3, where=where)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found", d.notes
    found, turning = d.best.effects[-1], []
    assert found.parameters["member"] == "left-column"
    assert found.parameters["mass"] == pytest.approx(mass, rel=0.1)
    if found.name == "point_mass" and abs(found.parameters["position"] - at) > 0.02 * length:
        turning = [c for c in d.caveats if c.kind == "alike" and "turns with" in c]
        assert len(turning) == 1, d.notes
        places = [float(x) for x in re.findall(r"from ([\d.e-]+) to ([\d.e-]+) m", turning[0])[0]]
        assert places[0] - 0.02 * length <= at <= places[1] + 0.02 * length, turning
        bodies = [e for effects in turning[0].alternatives for e in effects]
        assert all(e.name == "attached_body" for e in bodies)
        assert min(abs(e.parameters["position"] - at) for e in bodies) < 0.02 * length, bodies
        doc = json.loads(json.dumps(d.to_json()))
        said = [c for c in doc["caveats"] if c["note"] == str(turning[0])]
        assert said and len(said[0]["alternatives"]) == len(turning[0].alternatives)
        assert set(map(str, d.drawn_alternatives)) >= set(map(str, bodies))
        assert turning[0] in format_diagnosis(d, model)
    after = update(model, measured, d.add_arguments(), **NOISE)
    again = _diagnose(after.model, measured, **NOISE)
    assert again.verdict == "consistent"
    if turning:   # said at every diagnosis of the model holding that point mass
        present = [c for c in again.caveats if c.kind == "alike" and c.present == 0]
        assert len(present) == 1 and "present point_mass" in present[0], again.notes
        assert min(abs(e.parameters["position"] - at) for (e,) in present[0].alternatives) \
            < 0.02 * length


@pytest.mark.slow   # 5 s
def test_a_frame_holding_the_mass_gets_the_rotary_inertia_it_lacks():
    """The portal whose model holds the corner block's 0.3 kg as a point mass at C but not
    its J (r 3 cm): ``rotary_inertia`` is tried at the mass and found, J within 5 %."""
    model, measured, inertia = _body_at_corner(0.3, 0.03, 7, known=True)
    d = _diagnose(model, measured, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["rotary_inertia"], d.notes
    found = d.best.effects[-1].parameters
    assert found["member"] == "beam" and abs(found["position"] - 0.4) < 0.008
    assert found["inertia"] == pytest.approx(inertia, rel=0.05)


@pytest.mark.slow   # 6 s; the frame campaign's `ground` class (a foundation under any member)
def test_a_beam_resting_on_a_foundation_is_a_foundation_under_that_beam():
    """The portal's beam on a Winkler foundation of half its EI (π/ℓ)⁴ (the exact frame,
    complex wavenumbers below the foundation's own frequency): found under the beam within
    10 %, to the noise; a stiffer beam (a section loss over it), a stiffer steel, a prop or
    a force do not explain it (without the foundation among the candidates, a force in the
    beam and a prop at its middle together came within χ²/n 1.41 of it, with the verdict
    effect_found: a confident wrong answer; the candidates here are those competitors).
    The update the diagnosis suggests is the same fit."""
    model = portal_frame()
    beam = model.member("beam")
    kf = 0.5 * beam.E * beam.inertia * (np.pi / model.member_length(beam)) ** 4
    exact = ExactFrame(model.nodes, [(m.start, m.end, m.E, m.rho, m.area, m.inertia)
                                     + ((0.0, kf) if m.id == "beam" else ())
                                     for m in model.members], dict(model.supports), (),
                       [m.id for m in model.members])
    truth = [Effect("foundation", {"member": "beam", "stiffness": kf})]
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 21)
    names = ["foundation", "section_loss", "material", "point_spring", "axial_load"]
    d = _diagnose(model, measured, candidates=names, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["foundation"], d.notes
    found = d.best.effects[d.best.added].parameters
    assert found["member"] == "beam"
    assert found["stiffness"] == pytest.approx(kf, rel=0.1)
    assert d.best.misfit.chi2_per_residual < 1.5
    assert d.add_arguments() == ["foundation:member=beam"]
    after = update(model, measured, d.add_arguments(), **NOISE)
    assert after.model.effects[0].parameters["stiffness"] == pytest.approx(
        found["stiffness"], rel=1e-4)


# every member alike in the slow studies (the frame campaign's `deep` class runs 8 more)
@pytest.mark.parametrize("beam_depth", [pytest.param(None, marks=pytest.mark.slow), 0.035])
def test_a_deep_portal_lacks_shear_not_a_softer_steel(beam_depth):
    """Columns 0.06 m deep (ℓ/h 5) and the beam as deep (6.7) or 0.035 m (11.4: its
    section then another, its κGA another share of the first member's), measured from the
    exact frame of Timoshenko members, each of κGA 5/6 G A (tests/frame_reference: no
    gfe-opt element in it): the Euler–Bernoulli model is 3.5 to 16 % high.  ``shear`` is
    found, κGA within 3 % of the first member's 5/6 G A, to the noise; a uniformly softer
    steel (E lower, every mode alike) or a looser member (an axial stiffness) leave χ²/n
    above 100 (the candidates here are those competitors; the campaign's ``deep`` class
    runs every one).  Updated as the diagnosis says, the portal is consistent."""
    from .test_frame import deep_portal

    model, exact, truth = deep_portal(0.06, beam_depth)
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 5)
    names = ["shear", "material", "axial_stiffness"]
    d = _diagnose(model, measured, candidates=names, **NOISE)
    assert d.verdict == "effect_found" and d.suggested == ["shear"], d.notes
    kga = truth[0].parameters["shear_rigidity"]
    assert d.best.effects[0].parameters["shear_rigidity"] == pytest.approx(kga, rel=0.03)
    assert d.best.misfit.chi2_per_residual < 1.5
    others = [f for f in d.fits if f.name != "shear"]
    assert min(f.misfit.chi2_per_residual for f in others) > 100
    after = update(model, measured, d.add_arguments(), **NOISE)
    again = diagnose(after.model, measured, candidates=names, **NOISE)
    assert again.verdict == "consistent", again.notes


@pytest.mark.slow   # 80 to 100 s each: the loop, two diagnoses and an update
@pytest.mark.parametrize("case", ["mass and joint", "support and joint", "shear and joint"])
def test_two_different_changes_are_found_together_and_then_the_portal_agrees(case):
    """Two unrelated changes at once, exact (no gfe-opt element), outside the frame
    campaign's classes (one change each): 0.15 kg at joint C with the beam's end at B
    loose (3000 N m/rad), or base A turning against 800 N m/rad with the beam's end at C
    loose (4000), or every member 0.04 m deep (ℓ/h 7.5 to 10, Timoshenko members of
    κGA 5/6 G A) with the beam's end at B loose (half its 4EI/ℓ).  The loop names both at
    their places within 5 % and ends consistent."""
    from gfe_opt.diagnosis import follow

    from .test_frame import deep_portal

    model = portal_frame()
    members = [(m.start, m.end, m.E, m.rho, m.area, m.inertia) for m in model.members]
    beam, ids = [m.id for m in model.members].index("beam"), [m.id for m in model.members]
    if case == "shear and joint":
        model, deep, truth = deep_portal(0.04)
        b = model.member("beam")
        k = 2.0 * b.E * b.inertia / model.member_length(b)
        exact = ExactFrame(deep.nodes, deep.members, dict(model.supports), [("B", beam, k)],
                           ids)
        truth = truth + [Effect("joint_spring", {"node": "B", "member": "beam",
                                                 "stiffness": k})]
    elif case == "mass and joint":
        exact = ExactFrame(model.nodes, members, dict(model.supports), [("B", beam, 3000.0)],
                           ids, (), [("C", 0.15)])
        truth = [Effect("joint_spring", {"node": "B", "member": "beam", "stiffness": 3000.0}),
                 Effect("point_mass", {"member": "beam", "position": 0.4, "mass": 0.15})]
    else:
        exact = ExactFrame(model.nodes, members, dict(model.supports), [("C", beam, 4000.0)],
                           ids, [("A", 2, 800.0)])
        truth = [Effect("joint_spring", {"node": "C", "member": "beam", "stiffness": 4000.0}),
                 Effect("support_spring", {"node": "A", "stiffness": 800.0})]
    measured = _measured(model, exact, _guess(model, truth), _sensors(model), 7)
    out = follow(model, measured, **NOISE)
    assert out.verdicts[-1] == "consistent", out.verdicts
    assert sorted(e.name for e in out.model.effects) == sorted(e.name for e in truth)
    for t in truth:
        e = next(e for e in out.model.effects if e.name == t.name)
        if "node" in t.parameters:
            assert e.parameters["node"] == t.parameters["node"]
        elif "member" in t.parameters:   # the mass at joint C: the beam's end (or the
            assert e.parameters["member"] in ("beam", "right-column")   # right column's top)
        size = next(k for k in ("stiffness", "mass", "shear_rigidity") if k in t.parameters)
        assert e.parameters[size] == pytest.approx(t.parameters[size], rel=0.05)


def test_a_zone_read_from_frequencies_alone_ends_without_an_internal_error():
    """A softer zone (EI × 0.57) near the right column's base, the portal's six exact
    frequencies alone (``scripts/bench_frame_diagnosis.py --seed 3300 --frequencies-only``,
    its loop: diagnose, update as printed, diagnose again): a finish's Hessian was positive
    to eigvalsh and singular to the LU solve, and the loop ended in LinAlgError.  It now
    ends with verdicts, the last ``consistent`` (from frequencies alone what it added need
    not be the zone: here a point mass at the left column's top, which the campaign scores
    wrong)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    import bench_frame_diagnosis as campaign

    row = campaign.run_case(campaign.frequencies_only(campaign.make_case(3307, "zone")))
    assert row["verdicts"][0] == "effect_found" and row["verdicts"][-1] == "consistent"
    assert row["added"]


def test_frequencies_alone_say_a_crack_on_the_beam_may_be_at_its_mirror_place():
    """A line-spring crack 0.304 m along the symmetric portal's beam (the campaign's
    crack-3304, the exact frame), six frequencies alone: they cannot tell it from its
    mirror image at 0.096 m, where the fit ended.  The diagnosis said so for beams, never
    for a frame: a confident wrong place.  Now the note names the mirror place (the
    truth's, within 2 % of the beam); with the shapes the mirror place does not fit as
    well and nothing is said."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    import bench_frame_diagnosis as campaign

    case = campaign.make_case(3304, "crack")
    truth = case["answers"][0]
    assert truth["member"] == "beam"
    said = re.compile(r"the crack on beam at ([0-9.]+) m fits as well at its mirror image, "
                      r"beam at ([0-9.]+) m .*: the frequencies cannot tell the two places "
                      r"apart")
    alone = campaign.frequencies_only(case)
    d = diagnose(alone["model"], alone["measured"], candidates=["crack"], **alone["noise"])
    assert d.verdict == "effect_found"
    notes = [m for m in map(said.match, d.notes) if m]
    assert len(notes) == 1
    here, mirror = (float(v) for v in notes[0].groups())
    assert abs(here + mirror - 0.4) < 1e-3
    assert min(abs(here - truth["position"]), abs(mirror - truth["position"])) < 0.02 * 0.4
    # the same caveat as the JSON gives it: its kind and the crack at the mirror place
    caveat, = [c for c in d.to_json()["caveats"] if c["kind"] == "mirror"]
    assert caveat["note"] == notes[0].group(0)
    (other,), = caveat["alternatives"]
    assert other["effect"] == "crack" and other["parameters"]["member"] == "beam"
    assert abs(other["parameters"]["position"] - mirror) < 1e-3
    with_shapes = diagnose(case["model"], case["measured"], candidates=["crack"],
                           **case["noise"])
    assert not any("mirror image" in n for n in with_shapes.notes)
    assert not any(c.kind == "mirror" for c in with_shapes.caveats)
