"""Bodies attached to a plane frame, their rotary inertia included (a block on a corner, a
floor slab at a joint, a fixture on a member): does the loop of ``diagnose`` and ``update``
end with the body's mass and inertia, and with nothing else (``python
scripts/study_frame_body.py``)?  The frames' counterpart of ``scripts/study_tip_body.py``.

Each case is the portal of ``problems/`` (columns 0.3 m, beam 0.4 m, 20 elements a member,
both bases clamped) carrying a body of mass 0.05-0.25 kg (3-16 % of the beam's) and radius
of gyration 0-5 cm (J = m r²; in every fourth case r = 0: a point mass, the control) at a
corner joint (B or C, half the cases) or at 15-85 % of a member, from the exact frame of
``tests/frame_reference.py`` (dynamic stiffness, the body's mass and J on a node's DOFs; a
body inside a member splits it there), 6 modes at the frame tests' sensors (two points a
member in x and y, and the corners), with the noise stated to the diagnosis (0.3 % shape,
0.05 % frequency).  The model: the plain portal.  The loop adds what each diagnosis suggests,
with its values (``Diagnosis.add_arguments``), until a diagnosis says anything but "an
effect is missing" (at most four steps).  A case is right when it ends ``consistent`` with
the body and nothing else: an ``attached_body`` (or a ``point_mass`` and a
``rotary_inertia``) where r > 0, a ``point_mass`` where r = 0; at its place (a corner's body
on either member at that joint), within 2 % of its member's length, its mass within 5 % and
its J within 15 %.  A body at the mirror corner with the diagnosis's note that the data
cannot tell the two apart is counted apart ("mirror said"), and so is a body whose J the
data do not tell: the loop ends ``consistent`` with its point mass, in place, its mass
within 5 % ("J untold"), one whose J lies beyond 15 % but within 3 σ of the truth ("J
within 3 σ"), and a point mass off the body's place, ``consistent``, where a diagnosis of
the loop said that a body at the place fits as well ("body said alike": a body of large J
inside a column element, which the data cannot tell from a mass slid off it).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gfe_opt.diagnosis import diagnose, update  # noqa: E402
from gfe_opt.frame_data import effect_place  # noqa: E402
from gfe_opt.model import Effect  # noqa: E402
from gfe_opt.problems import portal_frame  # noqa: E402
from tests.test_frame_diagnosis import (  # noqa: E402
    _exact_with_body,
    _guess,
    _measured,
    _sensors,
)

STATED = {"shape_noise": 0.003, "freq_noise": 0.0005}
STEPS = 4


def case(seed: int, k: int) -> dict:
    rng = np.random.default_rng(seed)
    model = portal_frame()
    if rng.integers(2):   # a corner: the beam's start (B) or end (C)
        member_id = "beam"
        at = float(rng.choice([0.0, model.member_length(model.member("beam"))]))
    else:
        member_id = str(rng.choice([m.id for m in model.members]))
        at = float(np.round(rng.uniform(0.15, 0.85)
                            * model.member_length(model.member(member_id)), 4))
    mass = float(rng.uniform(0.05, 0.25))
    radius = 0.0 if k % 4 == 3 else float(rng.uniform(0.01, 0.05))
    inertia = mass * radius**2
    exact, where = _exact_with_body(model, member_id, at, mass, inertia)
    truth = Effect("attached_body" if inertia else "point_mass",
                   {"member": member_id, "position": at, "mass": mass,
                    **({"inertia": inertia} if inertia else {})})
    sensors = _sensors(model)
    measured = _measured(model, exact, _guess(model, [truth]), sensors, seed, where=where)
    start = time.perf_counter()
    verdicts, added, notes, fit, said, deciding = [], [], [], None, [], []
    for _ in range(STEPS):
        d = diagnose(model, measured, **STATED)
        verdicts.append(d.verdict)
        notes += [n for n in d.notes if "cannot tell these places apart" in n]
        turning = [c for c in d.caveats if c.kind == "alike" and any(
            e.name == "attached_body" for effects in c.alternatives for e in effects)]
        said += [e for c in turning for effects in c.alternatives for e in effects
                 if e.name == "attached_body"]
        deciding += [c.decide.as_dict() for c in turning if c.decide is not None]
        if d.verdict != "effect_found":
            break
        added += list(d.suggested)
        fit = update(model, measured, d.add_arguments(), **STATED).fit
        model = fit.model
    found = [(e.name, dict(e.parameters)) for e in model.effects]
    names = sorted(n for n, _ in found)
    place = effect_place(model, truth)
    bodies = [e for e in model.effects if e.name in ("attached_body", "point_mass")]
    places = [effect_place(model, e) for e in bodies]
    fitted_mass = sum(e.parameters["mass"] for e in bodies)
    fitted_inertia = sum(e.parameters["inertia"] for e in model.effects
                         if e.name in ("attached_body", "rotary_inertia"))
    kinds = (["attached_body"], ["point_mass", "rotary_inertia"]) if inertia \
        else (["point_mass"],)
    sizes = abs(fitted_mass / mass - 1) < 0.05 and (
        not inertia or abs(fitted_inertia / inertia - 1) < 0.15)
    shape = verdicts[-1] == "consistent" and names in [sorted(x) for x in kinds] and sizes
    length = model.member_length(model.member(member_id))

    def at_place(e):   # a joint's by its name; else on the member within 2 % of its length
        if place.startswith("node "):
            return effect_place(model, e) == place
        return e.parameters["member"] == member_id and \
            abs(e.parameters["position"] - at) <= 0.02 * length

    right = shape and all(at_place(e) for e in bodies)
    # J outside 15 % but within 3 σ of the truth (σ of the last update's fit): a small J the
    # data tell only roughly, said with its uncertainty
    sigma_j = [sig.get("inertia") for e, sig in zip(fit.effects, fit.sigma)
               if e.name in ("attached_body", "rotary_inertia")] if fit is not None else []
    loose = (not right and bool(inertia) and verdicts[-1] == "consistent"
             and names in [sorted(x) for x in kinds] and abs(fitted_mass / mass - 1) < 0.05
             and all(at_place(e) for e in bodies) and len(sigma_j) == 1
             and sigma_j[0] is not None and abs(fitted_inertia - inertia) < 3 * sigma_j[0])
    mirror = shape and not right and bool(notes)
    # a point mass off the body's place, consistent, where a diagnosis said that a body at
    # the place fits as well (a body of large J inside a column element: the data cannot
    # tell the two readings apart)
    body_said = bool(inertia) and not right and verdicts[-1] == "consistent" \
        and names == ["point_mass"] and any(at_place(e) for e in said)
    # a body whose J these data do not tell: the loop ends consistent with its point mass,
    # in place, and rotary_inertia (tried on a model holding a point mass) not significant
    untold = bool(inertia) and verdicts[-1] == "consistent" and names == ["point_mass"] \
        and abs(fitted_mass / mass - 1) < 0.05 and all(at_place(e) for e in bodies)
    return {"case": seed, "member": member_id, "position": at, "place": place, "mass": mass,
            "inertia": inertia, "verdicts": verdicts, "added": added, "found": found,
            "found_places": places, "right": bool(right), "mirror_said": bool(mirror),
            "inertia_untold": untold, "inertia_within_3_sigma": bool(loose),
            "body_said_alike": body_said, "bodies_said": len(said),
            # what those caveats said would tell the mass from the body (JSON ``decide``)
            "deciding": deciding, "seconds": time.perf_counter() - start}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=9100, help="the first case's seed")
    parser.add_argument("--cases", type=int, default=16)
    parser.add_argument("--json", help="write the rows to this file")
    args = parser.parse_args()
    rows = []
    for k in range(args.cases):
        row = case(args.seed + k, k)
        rows.append(row)
        mark = "right" if row["right"] else "mirror said" if row["mirror_said"] else \
            "J untold" if row["inertia_untold"] else \
            "J within 3 σ" if row["inertia_within_3_sigma"] else \
            "body said alike" if row["body_said_alike"] else "WRONG"
        print(f"[{k + 1}/{args.cases}] {row['case']} body at {row['place']}, "
              f"{1e3 * row['mass']:.1f} g, J {row['inertia']:.3g}: "
              f"{' -> '.join(row['verdicts'])} added {row['added']} {mark} "
              f"({row['seconds']:.1f} s)", flush=True)
        if not row["right"]:
            print(f"    found {row['found']} at {row['found_places']}", flush=True)
    right = sum(r["right"] for r in rows)
    said = sum(r["mirror_said"] for r in rows)
    untold = sum(r["inertia_untold"] for r in rows)
    loose = sum(r["inertia_within_3_sigma"] for r in rows)
    alike = sum(r["body_said_alike"] for r in rows)
    print(f"right {right} of {len(rows)} (J beyond 15 % but within 3 σ of the truth: {loose}; "
          f"mirror corner said: {said}; a point mass in place, consistent, its J not told by "
          f"the data: {untold}; a point mass off the place, the body there said to fit as "
          f"well: {alike})")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
