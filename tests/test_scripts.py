"""Every script runs (small, in a temporary folder) and prints what it promises."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


def _run(name, *args, cwd):
    return subprocess.run([sys.executable, str(SCRIPTS / name), *args], capture_output=True,
                          text=True, cwd=cwd, check=True).stdout


def test_paper_case_study(tmp_path):
    out = _run("paper_case_study.py", "--out", str(tmp_path / "cs"), cwd=tmp_path)
    rows = json.loads(out[:out.rindex("]") + 1])
    assert {p.name for p in (tmp_path / "cs").iterdir()} == {
        "fig1_k.png", "fig2_dkdx.png", "fig3_linear.png", "fig4_constant.png", "fig5_q.png"}
    for row in rows:
        assert row["ok"]
        if row["elements"] in (46, 92):  # crack at a node: located within one element
            assert abs(row["lowest_k_at_m"] - 0.2875) <= 0.575 / row["elements"]


def test_compare_solvers(tmp_path):
    out = _run("compare_solvers.py", cwd=tmp_path)
    rows = json.loads(out[out.index("\n[") + 1:])
    assert len(rows) == 12
    taper = [r for r in rows if r["problem"].startswith("tapered")]
    assert all(r["ok"] for r in taper)
    by = {(r["problem"], r["method"]): r for r in rows}
    for problem in {r["problem"] for r in rows}:  # same optimum by the direct KKT and IPOPT
        a = by[(problem, "ipopt equation error")]
        b = by[(problem, "equation error (auto: direct KKT)")]
        assert b["iterations"] == 0
        assert abs(a["parameter_error_rms"] - b["parameter_error_rms"]) < 1e-6
    assert out.count("agree=True") == 3  # IPOPT and the SDP on the same convex step


def test_bench_eigen_accuracy(tmp_path):
    out = json.loads(_run("bench_eigen_accuracy.py", "--max-elements", "10000", cwd=tmp_path))
    for row in out["rows"]:
        assert row["gfe_opt_max_rel_error"] < 1e-6
    raw = [r["raw_shift_invert_max_rel_error"] for r in out["rows"] if r["elements"] == 10000]
    assert all(isinstance(e, str) or e > 1e-4 for e in raw)  # raw shift-invert fails there
    assert "the finest mesh whose modal solve gfe-opt verifies" in out["above_ceiling"]


@pytest.mark.slow
def test_study_shape_rounding_shows_the_floor_and_what_lowers_it(tmp_path):
    """LAPACK's dense shapes carry a rounding floor that a smaller step does not lower (their
    second difference at h = 1e-11 is not h² smaller than at 1e-7: rounding, not
    curvature), and the package's inverse-iteration step lowers it at least tenfold; χ² near
    set 8's optimum is rough above the finish's 1e-9 floors from LAPACK's shapes alone and
    below it as computed; the frames' shapes sit far below LAPACK's floor as computed."""
    out = json.loads(_run("study_shape_rounding.py", cwd=tmp_path))
    shapes = out["shape_second_difference"]
    raw, refined = shapes["lapack_alone"], shapes["as_computed"]
    assert raw["1e-11"][0] > 1e-3 * raw["1e-07"][0] > 0   # 1e-8 of h² scaling: a floor
    assert all(a > 10 * b for a, b in zip(raw["1e-11"], refined["1e-11"]))
    chi2 = out["chi2_minus_centre_floors_at_-2h..2h"]
    rule = out["stopping_rule_floors"]
    assert max(abs(v) for v in chi2["lapack_alone"]["1e-11"]) > 3 * rule
    assert max(abs(v) for v in chi2["as_computed"]["1e-11"]) < rule
    frames = out["frame_shape_second_difference"]
    floor = max(frames["portal_lapack_alone"]["1e-11"])
    assert max(frames["three_storey_sparse"]["1e-11"]) < 0.1 * floor   # Lanczos: none
    assert max(frames["portal_as_computed"]["1e-11"]) < 0.1 * floor    # refined


def test_shipped_examples_are_what_the_script_writes(tmp_path):
    """problems/demo-measured.* and demo-frf.uff cannot drift from the code that makes them."""
    assert "hold what scripts/make_examples.py writes" in _run("make_examples.py", "--check",
                                                              cwd=tmp_path)


def test_example_check_compares_values_and_names_what_differs(tmp_path):
    """--check compares by value: a change of the last printed digit is no drift, a change of
    a value beyond the tolerance is named with its size."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        import make_examples
    finally:
        sys.path.remove(str(SCRIPTS))
    from gfe_opt.measured import load_measured, save_measured

    shipped = SCRIPTS.parent / "problems" / "demo-measured.json"
    m = load_measured(shipped)
    scale = float(abs(m.shapes).max())
    for factor, named in ((1e-9, False), (1e-4, True)):
        shapes = m.shapes.copy()
        shapes[3, 1] += factor * scale
        changed = tmp_path / f"{factor:g}" / "demo-measured.json"
        changed.parent.mkdir()
        save_measured(type(m)(m.x, m.dof, m.frequencies_hz, shapes, m.source), changed)
        lines = make_examples.differences(shipped, changed)
        assert bool(lines) == named, lines
        if named:
            assert "shapes[3, 1]" in lines[0] and "differs by 0.0001 of the largest" in lines[0]


def test_readme_commands_name_files_that_exist():
    """What scripts/check_readme.py (run by .ci/run) will run: every block it skips says
    why, and every repository file a runnable command names exists."""
    import re

    sys.path.insert(0, str(SCRIPTS))
    from check_readme import blocks, commands

    root = SCRIPTS.parent
    found = blocks((root / "README.md").read_text(encoding="utf-8"))
    runnable = [b for b in found if b[2] is None]
    assert len(runnable) >= 5 and all(len(b[2]) > 10 for b in found if b[2] is not None)
    named = []
    for lang, code, _, line in runnable:
        text = "\n".join(commands(code)) if lang == "bash" else code
        named += [(line, f) for f in re.findall(r"\b((?:problems|scripts)/[\w./-]+\.\w+)",
                                                  text)]
    assert named
    missing = [(line, f) for line, f in named if not (root / f).is_file()]
    assert not missing, missing
    # the placeholders of old (MODEL.toml, MEASURED.json) are no command anyone can paste
    assert not [b for b in runnable if b[0] == "bash"
                and re.search(r"\b(MODEL|MEASURED|FRF)\.\w+", b[1])]


def test_the_frame_campaign_builds_every_class_from_the_exact_frame():
    """scripts/bench_frame_diagnosis.py's generator (its crack bracket once failed, found
    only by a run): every class builds 6 modes at the sensors from the exact solution, the
    answers name a place on the frame, and a hidden change moves the frequencies off the
    model as it stands while 'none' does not beyond the noise."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        import bench_frame_diagnosis as campaign
    finally:
        sys.path.remove(str(SCRIPTS))
    import numpy as np

    from gfe_opt.frame import frame_modes

    for i, group in enumerate(campaign.CLASSES):
        case = campaign.make_case(4000 + i, group)
        measured, model = case["measured"], case["model"]
        # x and y at two points a member, and the portal's joints B (x) and C (y)
        joints = 0 if group == "storey" else 2
        assert measured.n_modes == 6 and measured.n_sensors == joints + 4 * len(
            model.members), group
        assert (len(case["answers"]) == 0) == (group == "none")
        assert (len(case["answers"]) == 2) == (group == "joints")
        for answer in case["answers"]:   # a place on the frame; a material, shear have none
            assert answer.get("node") in model.nodes or answer.get("member") in {
                m.id for m in model.members} or (answer["name"], group) in (
                ("material", "material"), ("shear", "deep")), answer
        f0 = frame_modes(model, 6).frequencies_hz
        shift = np.max(np.abs(measured.frequencies_hz / f0 - 1))
        noise = campaign.NOISE["freq_noise"] * case["noise_factor"]
        if group == "none":
            assert shift < 4 * noise, (group, shift, noise)
        else:   # a brace's weakest pull (20 N) moves its modes by a few noise levels only
            assert shift > (2 if group == "tension" else 4) * noise, (group, shift, noise)


def test_the_frame_body_study_splits_a_member_at_its_body_as_the_model_reads_it():
    """scripts/study_frame_body.py's exact portal with a body inside a member (the member
    split there, the body's mass and J on the new joint) and at a corner: the frequencies of
    the package's portal with the ``attached_body`` on a node of its mesh, at 64 elements a
    member, within 1e-5 (the mesh's h⁴ error), and a sensor on the split member reads the
    same mode on both sides of the split."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        import study_frame_body as study
    finally:
        sys.path.remove(str(SCRIPTS))
    from dataclasses import replace

    import numpy as np

    from gfe_opt.frame import frame_modes
    from gfe_opt.model import Effect
    from gfe_opt.problems import portal_frame

    model = portal_frame()
    fine = replace(model, members=tuple(replace(m, elements=64) for m in model.members))
    for member, at in (("left-column", 0.075), ("beam", 0.4)):
        exact, where = study._exact_with_body(model, member, at, 0.2, 1.5e-4)
        body = Effect("attached_body", {"member": member, "position": at, "mass": 0.2,
                                        "inertia": 1.5e-4})
        f = frame_modes(fine.with_effects([body]), 6).frequencies_hz
        truth = np.array([exact.frequency_near(x, 1e-3) for x in f])
        assert np.max(np.abs(f / truth - 1)) < 1e-5, (member, f / truth - 1)
        if where is not None:
            below = where({"member": member, "position": 0.05, "direction": "x"})
            above = where({"member": member, "position": 0.1, "direction": "x"})
            assert below == {"member": f"{member}-a", "position": 0.05, "direction": "x"}
            assert above["member"] == f"{member}-b"
            assert abs(above["position"] - 0.025) < 1e-12


def test_following_the_finishes_changes_no_fit_and_records_what_they_reached():
    """scripts/bench_fit_relevance.py's --campaign follows every Newton finish through a
    proxy of its residual: the diagnosis is the same to the last bit as without it, each
    finish's χ² after k Jacobians is the lowest it had evaluated by then (never below its
    end, never rising with k), and the rule's tally counts what it is defined to."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        import bench_fit_relevance as relevance
    finally:
        sys.path.remove(str(SCRIPTS))
    from gfe_opt import diagnosis
    from gfe_opt.model import Effect, load_model
    from gfe_opt.problems import problem_file
    from gfe_opt.synthetic import interior_sensors, synthetic_measurement

    model = load_model(problem_file("ss-steel-beam.toml")).with_elements(20)
    truth = model.with_effects([Effect("point_mass", {"position": 0.31, "mass": 0.05})])
    measured = synthetic_measurement(truth, 4, interior_sensors(model.length, 12),
                                     shape_noise=0.003, freq_noise=0.0005, seed=7,
                                     reference_elements=80)
    noise = {"freq_noise": 0.0005, "shape_noise": 0.003}
    serial, diagnosis.SERIAL_FITS = diagnosis.SERIAL_FITS, True
    try:
        plain = diagnosis.diagnose(model, measured, **noise)
        followed, finishes = relevance._followed_finishes(
            lambda: diagnosis.diagnose(model, measured, **noise))
    finally:
        diagnosis.SERIAL_FITS = serial
    assert followed.verdict == plain.verdict
    assert [f.misfit.chi2 for f in followed.fits] == [f.misfit.chi2 for f in plain.fits]
    assert len(finishes) >= len(plain.fits) and sum(f["jacobians"] for f in finishes) > 0
    for f in finishes:
        reached = [f["after"][k] for k in relevance.AFTER]
        assert all(a >= b for a, b in zip(reached, reached[1:]))
        assert reached[-1] >= f["end"] * (1 - 1e-12)
    # the rule: after 2 Jacobians, cut what is above F times the lowest then
    rows = [{"name": "a", "finishes": [
        {"after": {k: v for k in relevance.AFTER}, "end": end, "jacobians": n}
        for v, end, n in ((10.0, 9.0, 6), (500.0, 400.0, 9), (2000.0, 50.0, 12),
                          (20000.0, 19000.0, 2))]}]
    rules = {(r["after_jacobians"], r["F"]): r for r in relevance._rules(rows, 100.0)}
    # (the best end is 9: a finish ending at or below 100 x 9 is a contender)
    r = rules[(2, 100.0)]   # only 2000 is above 100 x 10 (20000's finish ended after 2)
    assert (r["finishes_cut"], r["jacobians_saved"], r["cut_contenders"]) == (1, 10, 1)
    assert r["jacobians_total"] == 6 + 9 + 12 + 2
    r = rules[(1, 10.0)]    # 500, 2000 and 20000 cut; 500 and 2000 end as contenders
    assert (r["finishes_cut"], r["jacobians_saved"], r["cut_contenders"]) == (3, 8 + 11 + 1,
                                                                              2)
    # against the best end (9): after 2 Jacobians only 2000 is above 100 x 9 and goes on
    ends = {(r["after_jacobians"], r["F"]): r for r in relevance._rules(rows, 100.0,
                                                                         "best_end")}
    r = ends[(2, 100.0)]
    assert (r["finishes_cut"], r["jacobians_saved"], r["cut_contenders"]) == (1, 10, 1)
    assert ends[(1, 1000.0)]["finishes_cut"] == 1      # 20000 > 9000, ending after 2


def test_study_discrepancy_shows_the_update_ringing_at_the_expected_noise_norm(tmp_path):
    """scripts/study_discrepancy.py: on 20 copies of a beam's own modes (45 sensors, 5 modes,
    0.3 % shape noise), the generic update with its expansion at the expected noise norm
    (τ = 1, the package's before stop 75) moves some node by more than 10 % on several
    copies; at the 97.5 % quantile of the noise norm (the package's now) on none, and its
    typical error is no larger."""
    out = _run("study_discrepancy.py", "--configs", "ss-46el-45s-5m", "--copies", "20",
               "--seed", "0", "--json", cwd=tmp_path)
    rows = {(r["truth"], r["tau"]): r for r in json.loads(out.strip().splitlines()[-1])}
    assert rows["none", 1.0]["ring"] >= 2 and rows["none", "rule"]["ring"] == 0
    assert rows["none", "rule"]["factor"] == pytest.approx(1.206, abs=1e-3)
    assert rows["none", "rule"]["rms_median"] <= rows["none", 1.0]["rms_median"]
    assert all(r["failed"] == 0 for r in rows.values())


@pytest.mark.slow   # 8 diagnoses, 20-30 s; tests/test_realisation.py holds the disowned taper
def test_bench_realisation_scores_the_words_on_truths_the_package_did_not_build(tmp_path):
    """scripts/bench_realisation.py on the linear tapers of seed 1 (a 1 200-element reference
    beam; EI 0.7-1.3 at the right end; the demo's beam and a 40-element clamped-free one):
    each reads first as a taper of the truth's sign, which the profile found reproduces
    (the rising ones were disowned before stop 75), with at most one feature beside it in
    all eight."""
    out = _run("bench_realisation.py", "--seeds", "1", "--classes", "linear", cwd=tmp_path)
    doc = json.loads(out.strip().splitlines()[-1])
    assert len(doc["cases"]) == 8
    for row in doc["cases"]:
        assert row["suggested"] == ["stiffness_profile"], row["name"]
        assert row["first_right"] and not row["disowned"], (row["name"], row["words"])
        assert row["features"][0]["shown_by_finding"] is True, row["name"]
    card = doc["scorecard"]
    assert card["linear"] == card["all"] and card["all"]["spurious"] <= 1


def test_bench_compares_jacobians_on_fits_both_sides_converged():
    """``scripts/bench.py --parts fits`` compares each fit of the analytic side with its
    namesake of the difference side; a fit whose two ends lie in different valleys (χ² 419
    after IPOPT's iteration limit where the other path reached 309: the real cantilever's
    section loss) or that a side left unconverged measures the paths' stopping, not the
    Jacobians: listed apart with both ends; the differences are those of the fits that
    both paths took to one end."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench", SCRIPTS / "bench.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    a = {"fits": [("d/crack", [0.19, 0.5], [1e-3, 1e-2], 100.0, "converged", True),
                  ("d/section_loss", [0.19, 0.38], [0.01, 0.02], 419.0,
                   "Maximum_Iterations_Exceeded", True),
                  ("d/shear", [1e5], [1e3], 90.0, "Maximum_Iterations_Exceeded", False),
                  ("d/foundation (failed)", [], [], float("nan"), "converged", True)]}
    b = {"fits": [("d/crack", [0.19 * (1 + 2e-7), 0.5], [1e-3, 1e-2], 100.0 * (1 + 1e-10),
                   "converged", True),
                  ("d/section_loss", [0.52, 0.49], [0.01, 0.02], 309.0, "converged", True),
                  ("d/shear", [1.1e5], [1e3], 90.0, "converged", True),
                  ("d/foundation (failed)", [], [], float("nan"), "converged", True)]}
    out = bench._fit_differences(a, b)
    assert out["fits_compared"] == 2   # the crack, and the failed foundation (no values)
    assert out["max_parameter_rel_difference"] == pytest.approx(2e-7, rel=1e-3)
    assert out["max_chi2_rel_difference"] == pytest.approx(1e-10, rel=1e-3)
    assert out["fits_ended_apart"] == [
        {"fit": "d/section_loss", "status": ["Maximum_Iterations_Exceeded", "converged"],
         "chi2": [419.0, 309.0]},
        {"fit": "d/shear", "status": ["Maximum_Iterations_Exceeded", "converged"],
         "chi2": [90.0, 90.0]}]
