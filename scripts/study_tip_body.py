"""Bodies attached to beams, their rotary inertia included (a tip block, a fixture, a
shaker's armature): does the loop of ``diagnose`` and ``update`` end with the body's mass
and inertia, and with nothing else (``python scripts/study_tip_body.py``)?

Each case is the steel beam of the demo (0.575 m, 9.5 x 31.75 mm) on one of four supports
(clamped-free, free-free, pinned-pinned, clamped-clamped in turn), carrying a body of mass
0.05-0.4 ρAL and radius of gyration 0.02-0.08 L (J = m r²; in every fourth case r = 0: a
point mass, the control) at a free end (half the cases that have one) or at 15-85 % of the
length, from the independent reference beam of ``tests/reference.py`` (600 elements; the
inertia on the slope there), 5 elastic modes at 15 or 21 sensors between the model's nodes,
with the noise stated to the diagnosis (0.3 % shape, 0.05 % frequency; ``--data-noise``
to change the data's).  The model: the plain beam on 46 elements.  The loop adds what each
diagnosis suggests, with its values (``Diagnosis.add_arguments``), until a diagnosis says
anything but "an effect is missing" (at most four steps).  A case is right when it ends
``consistent`` with the body and nothing else: an ``attached_body`` (or a ``point_mass``
and a ``rotary_inertia``) where r > 0, a ``point_mass`` where r = 0; within 2 % of the
length of its place, its mass within 5 % and its J within 15 %.

Measured (stop 83): ``--seed 8100`` (the design seed) 23 of 24; held out, ``--seed 8200
--cases 48``, 46 of 48.  The three misses are bodies of r 6-7 % of L inside an element of
the 46-element model: found, J within 6 %, then "unexplained" with a note naming a mesh
with a node by the body (61, 49, 48 elements), on which each loop ends consistent.
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
from gfe_opt.measured import make_measured  # noqa: E402
from gfe_opt.model import model_from_dict  # noqa: E402
from tests.reference import STEEL, ReferenceBeam  # noqa: E402

STATED = {"shape_noise": 0.003, "freq_noise": 0.0005}
SUPPORTS = [("clamped", "free"), ("free", "free"), ("pinned", "pinned"), ("clamped", "clamped")]
STEPS = 4


def case(seed: int, k: int, data_noise) -> dict:
    rng = np.random.default_rng(seed)
    sup = SUPPORTS[k % 4]
    L = STEEL["length"]
    rho_a = STEEL["rho"] * STEEL["b"] * STEEL["h"]
    free_ends = [x for x, s in ((0.0, sup[0]), (L, sup[1])) if s == "free"]
    x0 = (float(rng.choice(free_ends)) if free_ends and rng.integers(2)
          else float(rng.uniform(0.15, 0.85) * L))
    mass = float(rng.uniform(0.05, 0.4) * rho_a * L)
    radius = 0.0 if k % 4 == 3 else float(rng.uniform(0.02, 0.08) * L)
    inertia = mass * radius**2
    n_sensors = int(rng.choice([15, 21]))
    x = np.linspace(0.0, L, n_sensors + 2)[1:-1] + 0.3 * L / 46   # between the nodes
    x = x[x < L]
    beam = ReferenceBeam(supports=sup, elements=600, point_masses=[(x0, mass)],
                         point_inertias=[(x0, inertia)] if inertia else [])
    rigid = 2 if sup == ("free", "free") else 0
    f, y = beam.measure(5 + rigid, x, seed=seed, shape_noise=data_noise[0],
                        freq_noise=data_noise[1])
    measured = make_measured(x, "w", f[rigid:], y[:, rigid:], f"tip-body-{seed}")
    model = model_from_dict({
        "name": "steel", "kind": "beam", "length": L, "elements": 46,
        "material": {"E": STEEL["E"], "rho": STEEL["rho"], "nu": 0.3},
        "section": {"shape": "rectangle", "b": STEEL["b"], "h": STEEL["h"]},
        "supports": {"left": sup[0], "right": sup[1]}}, "study")
    start = time.perf_counter()
    verdicts, added = [], []
    for _ in range(STEPS):
        d = diagnose(model, measured, **STATED)
        verdicts.append(d.verdict)
        if d.verdict != "effect_found":
            break
        added += list(d.suggested)
        model = update(model, measured, d.add_arguments(), **STATED).model
    found = {e.name: dict(e.parameters) for e in model.effects}
    names = set(found)
    bodies = [found[n] for n in ("attached_body", "point_mass") if n in found]
    fitted_mass = sum(b["mass"] for b in bodies)
    fitted_inertia = sum(found[n]["inertia"] for n in ("attached_body", "rotary_inertia")
                         if n in found)
    right = (verdicts[-1] == "consistent" and len(model.effects) == len(found)
             and names in (({"attached_body"}, {"point_mass", "rotary_inertia"}) if inertia
                           else ({"point_mass"},))
             and all(abs(b["position"] - x0) <= 0.02 * L for b in bodies)
             and abs(fitted_mass / mass - 1) < 0.05
             and (not inertia or abs(fitted_inertia / inertia - 1) < 0.15))
    return {"case": seed, "supports": "-".join(sup), "position": x0, "mass": mass,
            "inertia": inertia, "sensors": int(x.size), "verdicts": verdicts,
            "added": added, "found": found, "right": bool(right),
            "seconds": time.perf_counter() - start}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=8100, help="the first case's seed")
    parser.add_argument("--cases", type=int, default=24)
    parser.add_argument("--data-noise", default="0.003,0.0005",
                        help="shape,frequency noise of the data (relative)")
    parser.add_argument("--json", help="write the rows to this file")
    args = parser.parse_args()
    noise = tuple(float(v) for v in args.data_noise.split(","))
    rows = []
    for k in range(args.cases):
        row = case(args.seed + k, k, noise)
        rows.append(row)
        mark = "right" if row["right"] else "WRONG"
        print(f"[{k + 1}/{args.cases}] {row['case']} {row['supports']} body at "
              f"{row['position']:.3f} m, {1e3 * row['mass']:.1f} g, J {row['inertia']:.3g}: "
              f"{' -> '.join(row['verdicts'])} added {row['added']} {mark} "
              f"({row['seconds']:.1f} s)", flush=True)
        if not row["right"]:
            print(f"    found {row['found']}", flush=True)
    right = sum(r["right"] for r in rows)
    print(f"right {right} of {len(rows)}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
