"""The diagnosis on truths the package did not build (issue 21).

* A small subset of the validation campaign (``scripts/bench_diagnosis.py``: the loop a
  user runs, scored), marked slow: ``.ci/run`` runs it (``python -m pytest -m slow``).
* A crack by another compliance law (a hinge with the line-spring compliance of
  Tada's function): the crack is found at its place; what the package's crack law cannot
  reproduce is reported as ``remaining`` (or nothing remains), never hidden.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from gfe_opt.diagnosis import diagnose
from gfe_opt.measured import make_measured

from .conftest import make_model
from .reference import ReferenceBeam, interior
from .truths import line_spring_compliance

ROOT = Path(__file__).resolve().parents[1]
L = 0.575


def test_another_crack_law_is_found_and_what_remains_is_said():
    EI = ReferenceBeam().EI
    x0 = 0.37
    k = 1.0 / line_spring_compliance(0.45, EI, 0.03175)
    s = interior(L, 30)
    f, y = ReferenceBeam(elements=800, hinges=[(x0, k)]).measure(6, s, seed=4)
    d = diagnose(make_model(), make_measured(s, "w", f, y, "hinge"),
                 shape_noise=0.003, freq_noise=0.0005)
    assert d.verdict == "effect_found"
    assert d.suggested and d.suggested[0] in ("crack", "section_loss")
    assert abs(d.best.parameters["position"] - x0) < 0.02 * L
    out = json.loads(json.dumps(d.to_json()))
    assert "remaining" in out
    if out["remaining"] is not None:   # what the package's crack law leaves: said, with where
        assert out["remaining"]["chi2_per_residual"] > 1.0
        assert set(out["remaining"]) == {"chi2_per_residual", "freq_error_rms_pct", "where"}
        assert all(0.0 <= w <= L for w in out["remaining"]["where"])


@pytest.mark.slow  # about 3 minutes: .ci/run runs it with the other slow studies
def test_a_campaign_subset_meets_the_targets_relaxed_for_its_size():
    sys.path.insert(0, str(ROOT / "scripts"))
    import bench_diagnosis

    from . import truths

    cases = truths.campaign(subset=12)
    rows = [bench_diagnosis.run_case(c) for c in cases]
    card = bench_diagnosis.scorecard(rows)["all"]
    assert card["internal_errors"] == 0 and card["exit_2"] == 0, [
        r["error"] for r in rows if r["error"]]
    # targets: 90 % verdicts right on the full campaign; 14 cases: at most 3 wrong
    assert sum(not r["verdict_right"] for r in rows) <= 3, [
        (r["name"], r["verdicts"], r["added"]) for r in rows if not r["verdict_right"]]
    assert card["false_alarms"] == 0
    assert np.isfinite(card["seconds_per_case"])
