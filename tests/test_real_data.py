"""The whole loop on a real test shipped with the repository (README "Real data").

``problems/hr-cantilever.csv``: ten bending frequencies of a steel cantilever from the
High-Rate-SHM Working Group's Dataset-4 (CC BY-SA 4.0), re-derived from the published
spectrum by ``scripts/hr_cantilever_peaks.py``; ``problems/hr-cantilever.toml``: the
nominal model (published dimensions, catalogue steel, rigid clamp).  Nobody knows the truth
here, so the test asserts what physics allows and what the tool promises:

* the nominal model is about 9 % stiff in every mode: the first effect is uniform
  (``material``), with E between 150 and 200 GPa (for a uniform cantilever a lower E is the
  same as a shorter free length: E 169 GPa is the strip held 31 mm deeper in its clamp
  block);
* nothing proposed raises the frequency error, and the error falls at every step;
* no crack is proposed (the issue's complaint: a compliant clamp read as a crack);
* a local effect that ten frequencies fit equally well at two places or sizes is no finding
  (issue 21): the tool names both and the measurement that decides, and suggests neither.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gfe_opt.diagnosis import diagnose, update
from gfe_opt.measured import load_measured
from gfe_opt.model import load_model
from gfe_opt.text import format_diagnosis

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


def readme_first_diagnosis() -> list[str]:
    """The lines the README shows for the first ``gfe-opt diagnose`` of the real cantilever,
    up to its first "..." (the rest of the block is abbreviated)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## Real data")[1].split("```\n", 3)[2]
    return block.split("\n...")[0].splitlines()


def test_shipped_data_are_cited_and_frequency_only():
    text = (PROBLEMS / "hr-cantilever.csv").read_text()
    assert "CC BY-SA 4.0" in text and "High-Rate-SHM" in text
    assert "Attribution-ShareAlike 4.0" in (PROBLEMS / "hr-cantilever.LICENSE.txt").read_text()
    measured = load_measured(PROBLEMS / "hr-cantilever.csv")
    assert measured.frequency_only and measured.n_modes == 10
    # bending modes of a cantilever: ratios to the first near (β_n/β_1)², 6.27, 17.5, 34.4
    ratios = measured.frequencies_hz[1:4] / measured.frequencies_hz[0]
    np.testing.assert_allclose(ratios, [6.267, 17.55, 34.39], rtol=0.05)


def test_real_cantilever_loop():
    model = load_model(PROBLEMS / "hr-cantilever.toml")
    measured = load_measured(PROBLEMS / "hr-cantilever.csv")
    errors = []
    for step in range(3):
        d = diagnose(model, measured)
        if step == 0:  # issue 20: the same words and digits under every BLAS kernel (.ci/run)
            printed = format_diagnosis(d, model).splitlines()
            shown = readme_first_diagnosis()
            assert len(shown) >= 6 and any("not a finding" in line for line in shown)
            for line in shown:
                assert line in printed, (line, printed)
        errors.append(d.current.freq_error_rms_pct)
        for fit in d.fits:  # nothing ranked may raise the frequency error beyond rounding
            if fit.significant:
                assert fit.misfit.freq_error_rms_pct <= errors[-1] + 1e-6, fit.name
        if d.verdict != "effect_found":
            break
        assert "crack" not in d.suggested, d.suggested
        if step == 0:
            assert d.suggested[0] == "material", d.suggested
        assert d.remaining is None or d.remaining["chi2_per_residual"] > 1.0
        outcome = update(model, measured, d.suggested)
        assert outcome.after.freq_error_rms_pct < errors[-1]
        model = outcome.model
    assert np.all(np.diff(errors) < 0), errors
    assert errors[0] > 8.0 and errors[-1] < 0.7, errors
    # the zone the frequencies place at 0.35 m softer or at 0.41 m stiffer: named, not added
    assert any(n.startswith("not a finding") and "mode shapes" in n for n in d.notes), d.notes
    assert not any(e.name == "section_loss" for e in model.effects)
    E = next(e.parameters["E"] for e in model.effects if e.name == "material")
    assert 150e9 < E < 200e9, E
    assert not any(e.name == "crack" for e in model.effects)
