"""What the generic-element update says in words, scored on truths the package did not build
(``python scripts/bench_realisation.py [--seeds 1,2,3] [--json out.json]``).

``diagnose --realise`` (the command's default) reads the paper's generic update against its
null profile and noise band (:mod:`gfe_opt.realisation`) and says each feature in a sentence,
then which of them the effect found reproduces.  The diagnosis campaign
(``scripts/bench_diagnosis.py``) scores the verdicts, not these words; this scores the
words, on the classes whose truth is a change of EI the nodal family reads:

* ``crack`` (``tests/truths.py``: other crack laws): the first feature is a loss within two
  elements of it; ``zone`` (smooth, softer or stiffer): a loss or a rise as the zone, within
  two elements of it;
* ``taper`` (quadratic or stepped) and ``linear`` (EI ±15-30 % linearly to the right end;
  the demo's beam with 45 sensors and 5 modes, and 40 elements with 12-45 sensors and 4-6
  modes on three supports): the first feature is a taper rising or falling as the truth;
* ``material`` (E ±6 %): the first feature is a uniform change of the truth's sign;
* ``none``: no feature.

Every other feature is counted as **spurious** (it says a difference the truth does not
have), and a first feature right that the effect found (of the truth's family, fitting the
test to the noise) is said *not* to reproduce is counted **disowned** (the words contradict
the finding: a rising taper found as the profile that fits to the noise, called ringing,
stop 75; a data update that rang itself is counted too: on noise seed 13 the demo beam's
0.7 taper reads 0.56, with a rise beside it).  Each case is one ``diagnose`` (about 2 s);
``--seeds 1,2,3`` (39 cases) takes about 1.5 minutes.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gfe_opt.diagnosis import diagnose  # noqa: E402
from gfe_opt.measured import make_measured  # noqa: E402
from gfe_opt.model import model_from_dict  # noqa: E402
from tests.reference import ReferenceBeam, add_noise, interior  # noqa: E402
from tests.truths import BEAM, FREQ_NOISE, SHAPE_NOISE, draw, model_dict  # noqa: E402

CLASSES = ("crack", "zone", "taper", "material", "none")
#: the effects whose fit reads the truth's change of EI (a crack law the package lacks is
#: still a crack; a zone or a taper may be read as a zone or a profile)
FAMILY = {"crack": {"crack", "section_loss"}, "zone": {"section_loss", "crack"},
          "taper": {"stiffness_profile", "section_loss", "material"},
          "linear": {"stiffness_profile"}, "material": {"material"}, "none": set()}
LINEAR_SUPPORTS = (("pinned", "pinned"), ("clamped", "free"), ("clamped", "clamped"))


def cases(seeds, classes=(*CLASSES, "linear")):
    """(name, class, model dict, x, f, y, stated noise or None, want) of every case: ``want``
    is what the first feature must be (kind, sign of its change, place or None, the half
    length it may lie from the place beyond two elements) or None (no feature)."""
    out = []
    L = BEAM["length"]
    for klass in [k for k in CLASSES if k in classes]:
        for seed in seeds:
            c = draw(klass, seed)
            h = c.hidden[0] if c.hidden else None
            if klass == "crack":
                want = ("loss", -1, h.position, 0.0)
            elif klass == "zone":   # a zone may be stiffer than the rest
                k = h.size["stiffness_ratio"]
                want = ("loss" if k < 1 else "rise", np.sign(k - 1.0), h.position,
                        h.size["length"] / 2)
            elif klass == "taper":
                end = h.size.get("end_ratio", h.size.get("step_ratio"))
                want = ("taper", np.sign(end - 1.0), None, 0.0)
            elif klass == "material":
                want = ("uniform", np.sign(h.size["E_ratio"] - 1.0), None, 0.0)
            else:
                want = None
            out.append((c.name, klass, c.model, c.x, c.frequencies, c.shapes, c.stated, want))
    EI = BEAM["E"] * BEAM["b"] * BEAM["h"] ** 3 / 12
    rho_a = BEAM["rho"] * BEAM["b"] * BEAM["h"]
    for seed in seeds if "linear" in classes else ():
        # the demo's beam (46 elements, 45 sensors, 5 modes), pinned: where the reading of a
        # rising taper was disowned (stop 75)
        for ratio in (0.7, 0.85, 1.15, 1.3):
            beam = ReferenceBeam(length=L, EI=EI, rho_a=rho_a, elements=800,
                                 rigidity=lambda s, r=ratio: 1 + (r - 1) * s / L)
            x = interior(L, 45)
            f, y = beam.measure(5, x, shape_noise=0.0, freq_noise=0.0)
            f, y = add_noise(f, y, SHAPE_NOISE, FREQ_NOISE, seed + 10)
            out.append((f"linear-{ratio}-pinned-pinned-46el-{seed}", "linear",
                        model_dict(("pinned", "pinned"), 46), x, f, y,
                        (FREQ_NOISE, SHAPE_NOISE), ("taper", np.sign(ratio - 1.0), None, 0.0)))
        rng = np.random.default_rng(seed)
        supports = LINEAR_SUPPORTS[seed % len(LINEAR_SUPPORTS)]
        for ratio in (0.7, 0.8, 1.2, 1.3):
            beam = ReferenceBeam(length=L, EI=EI, rho_a=rho_a, elements=800, supports=supports,
                                 rigidity=lambda s, r=ratio: 1 + (r - 1) * s / L)
            n_modes, n_sensors = int(rng.integers(4, 7)), int(rng.integers(12, 46))
            x = interior(L, n_sensors)
            f, y = beam.measure(n_modes, x, shape_noise=0.0, freq_noise=0.0)
            f, y = add_noise(f, y, SHAPE_NOISE, FREQ_NOISE, seed + 100)
            out.append((f"linear-{ratio}-{'-'.join(supports)}-{seed}", "linear",
                        model_dict(supports, 40), x, f, y, (FREQ_NOISE, SHAPE_NOISE),
                        ("taper", np.sign(ratio - 1.0), None, 0.0)))
    return out


def score(klass, want, features, unexplained, found, explains, element_length) -> dict:
    """One case's row: the first feature right, the spurious features, disowned."""
    first = features[0] if features else None
    if want is None:
        right = first is None
    else:
        kind, sign, place, half = want
        right = (first is not None and first.kind == kind
                 # a taper's change is end against start; any other feature's against 1
                 and np.sign(first.value - (first.start if kind == "taper" else 1.0)) == sign
                 and (place is None or abs(first.x - place) <= half + 2 * element_length))
    spurious = len(features) - (1 if right and want is not None else 0)
    disowned = bool(right and want is not None and found & FAMILY[klass] and explains
                    and first in unexplained)
    return {"first_right": bool(right), "spurious": int(spurious), "disowned": disowned}


def run(seeds, classes=(*CLASSES, "linear"), progress=True) -> dict:
    rows = []
    todo = cases(seeds, classes)
    for i, (name, klass, md, x, f, y, stated, want) in enumerate(todo, start=1):
        start = time.perf_counter()
        model = model_from_dict(md, name)
        noise = {"freq_noise": stated[0], "shape_noise": stated[1]} if stated else {}
        d = diagnose(model, make_measured(x, "w", f, y, name), realise=True, **noise)
        band = d.profile_band
        features = list(band.features) if band is not None else []
        unexplained = list(band.unexplained) if band is not None else []
        found = set(d.suggested)
        explains = d.remaining is None and d.verdict == "effect_found"
        row = {"name": name, "class": klass, "verdict": d.verdict, "suggested": d.suggested,
               "features": [{"kind": ft.kind, "x": ft.x, "value": ft.value,
                             "shown_by_finding": None if band is None or band.explained is None
                             else ft not in unexplained} for ft in features],
               "words": list(d.realisation),
               **score(klass, want, features, unexplained, found, explains,
                       model.element_length),
               "seconds": time.perf_counter() - start}
        rows.append(row)
        if progress:
            print(f"[{i}/{len(todo)}] {name}: first {'right' if row['first_right'] else 'WRONG'}"
                  f", {row['spurious']} spurious{', DISOWNED' if row['disowned'] else ''}"
                  f" ({row['seconds']:.1f} s)", file=sys.stderr, flush=True)
    card = {}
    for klass in (*CLASSES, "linear"):
        mine = [r for r in rows if r["class"] == klass]
        if mine:
            card[klass] = {"cases": len(mine),
                           "first_right": sum(r["first_right"] for r in mine),
                           "spurious": sum(r["spurious"] for r in mine),
                           "disowned": sum(r["disowned"] for r in mine)}
    card["all"] = {k: sum(v[k] for v in card.values()) for k in
                   ("cases", "first_right", "spurious", "disowned")}
    return {"seeds": list(seeds), "scorecard": card, "cases": rows}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1,2,3", help="comma-separated case seeds")
    parser.add_argument("--classes", default=",".join((*CLASSES, "linear")),
                        help="comma-separated, of %(default)s")
    parser.add_argument("--json", type=Path, help="write the JSON document here too")
    args = parser.parse_args(argv)
    seeds = [int(s) for s in args.seeds.split(",")]
    classes = args.classes.split(",")
    unknown = [c for c in classes if c not in (*CLASSES, "linear")]
    if unknown:
        parser.error(f"unknown class {unknown[0]!r} (one of {', '.join((*CLASSES, 'linear'))})")
    out = run(seeds, classes)
    text = json.dumps(out, default=float)
    if args.json:
        args.json.write_text(text + "\n", encoding="utf-8")
    for klass, c in out["scorecard"].items():
        print(f"{klass:9s} first feature right {c['first_right']:3d} of {c['cases']:3d}"
              f"   spurious {c['spurious']:3d}   disowned {c['disowned']:3d}",
              file=sys.stderr)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
