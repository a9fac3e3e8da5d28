"""How much rounding the model's mode shapes carry, and what it does to χ² near an optimum.

The eigenvalues gfe-opt reports are Rayleigh quotients of the shapes (gfe_opt.modal), so a
shape error enters them squared; the shapes themselves carry the eigensolver's rounding,
about eps·λ_max/gap of a dense generalised solve (λ_max the mesh's highest eigenvalue).  The
study moves a crack by h of the beam's length (h = 1e-11 .. 1e-7) and prints the second
difference of each mode's shape (max over DOFs, relative to the mode's largest value): a
smooth function gives h²·φ'', rounding gives a floor that does not fall with h.  It does so
for the shapes of LAPACK's dense solve alone and for the shapes as gfe-opt computes them
(LAPACK's, then one step of inverse iteration at each mode's own eigenvalue:
gfe_opt.modal._inverse_iteration).  Then the same for χ²: the monitoring campaign of
tests/test_batch.py (20 elements, 9 sensors, 4 modes), its set 8 at the fit's end (a/d
0.356), χ² at the crack moved by ±h and ±2h, minus χ² there, in noise floors.  Last, the
frames' shapes: the three-storey frame's from shift-invert Lanczos (no such floor, no
refinement), the portal's from LAPACK, alone and refined.

    python scripts/study_shape_rounding.py
    OPENBLAS_CORETYPE=Sandybridge python scripts/study_shape_rounding.py
"""

import json
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import gfe_opt.modal as modal  # noqa: E402
from gfe_opt.fitting import misfit, noise_of  # noqa: E402
from gfe_opt.measured import load_measured  # noqa: E402
from gfe_opt.modal import model_modes  # noqa: E402
from gfe_opt.model import Effect, model_from_dict  # noqa: E402
from tests.conftest import STEEL_BEAM  # noqa: E402
from tests.truths import write_campaign  # noqa: E402

#: where tests/test_batch.py's set 8 fit ends (material E factor, crack position / length,
#: depth ratio), as `gfe-opt batch` printed it on this machine
END = (1.00916456, 0.33104147, 0.35599971)
STEPS = (1e-11, 1e-9, 1e-7)


@contextmanager
def _lapack_alone(alone: bool):
    """The dense solve's shapes without the package's inverse-iteration step (if alone)."""
    keep = modal._inverse_iteration
    if alone:
        modal._inverse_iteration = lambda A, B, lam, vec: vec
    try:
        yield
    finally:
        modal._inverse_iteration = keep


def _model(base, position, E=END[0], depth=END[2]):
    return base.with_effects([Effect("material", {"E": E * base.E}),
                              Effect("crack", {"position": position, "depth_ratio": depth})])


def _shape_floor(base, alone: bool) -> dict:
    with _lapack_alone(alone):
        out = {}
        x0 = END[1] * base.length
        for h in STEPS:
            S = [model_modes(_model(base, x0 + k * h * base.length), 4).shapes
                 for k in (-1, 0, 1)]
            d2 = (S[2] - 2 * S[1] + S[0]) / np.abs(S[1]).max(axis=0)
            out[f"{h:.0e}"] = [float(f"{v:.2e}") for v in np.abs(d2).max(axis=0)]
        return out


def _chi2_floor(base, alone: bool, measured) -> dict:
    with _lapack_alone(alone):
        x0 = END[1] * base.length
        out = {}
        for h in STEPS:
            fits = [misfit(_model(base, x0 + k * h * base.length), measured, noise_of())
                    for k in (-2, -1, 0, 1, 2)]
            floor = max(1.0, fits[2].chi2 / (fits[2].n_residuals - 3))
            out[f"{h:.0e}"] = [float(f"{(f.chi2 - fits[2].chi2) / floor:.2e}") for f in fits]
        return out


def _frame_floor() -> dict:
    """The same second difference on the frames (six modes): a 0.3-deep crack on the last
    member, at 0.37 of it, moved by h of the member.  The three-storey frame's modes come
    from shift-invert Lanczos (its 351 free DOFs), the portal's from LAPACK (alone, and as
    computed: refined)."""
    from gfe_opt.frame import frame_modes
    from gfe_opt.problems import portal_frame, three_storey_frame

    out = {}
    for name, model, alone in (("three_storey_sparse", three_storey_frame(), False),
                               ("portal_lapack_alone", portal_frame(), True),
                               ("portal_as_computed", portal_frame(), False)):
        member = model.members[-1]
        length = model.member_length(member)
        rows = {}
        for h in STEPS:
            with _lapack_alone(alone):
                S = [frame_modes(model.with_effects([Effect("crack", {
                    "member": member.id, "position": (0.37 + k * h) * length,
                    "depth_ratio": 0.3})], check=False), 6).shapes for k in (-1, 0, 1)]
            d2 = (S[2] - 2 * S[1] + S[0]) / np.abs(S[1]).max(axis=0)
            rows[f"{h:.0e}"] = [float(f"{v:.2e}") for v in np.abs(d2).max(axis=0)]
        out[name] = rows
    return out


def main():
    small = {**STEEL_BEAM, "elements": 20}
    base = model_from_dict(small, "small")
    with tempfile.TemporaryDirectory() as tmp:
        write_campaign(base, Path(tmp) / "sets", 10, n_modes=4, reference_elements=200,
                       sensors=np.linspace(0.05, 0.525, 9), onset=0.3)
        measured = load_measured(Path(tmp) / "sets" / "set-0008.json")
        result = {
            "shape_second_difference": {
                "lapack_alone": _shape_floor(base, True),
                "as_computed": _shape_floor(base, False)},
            "chi2_minus_centre_floors_at_-2h..2h": {
                "lapack_alone": _chi2_floor(base, True, measured),
                "as_computed": _chi2_floor(base, False, measured)},
            "frame_shape_second_difference": _frame_floor(),
            "stopping_rule_floors": 1e-9,
        }
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
