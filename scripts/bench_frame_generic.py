"""How the generic-element update of a frame reads, member by member: a small campaign.

    python scripts/bench_frame_generic.py --seeds 100-111 [--no-floor] [--samples 6]

Three truths, each from the exact dynamic stiffness solution of ``tests/frame_reference.py``
(6 modes, the frame tests' sensors, 0.3 % shape / 0.05 % frequency noise, one noise draw a
seed): the portal as modelled; the portal whose beam has E 10 % low; the braced portal whose
brace carries 40 % of its EA.  For each, the generic update (``gfe_opt.diagnosis`` runs it
the same way) is read against its noise band of ``--samples`` draws and its features listed;
the counts are how often the portal as modelled shows none, the beam's uniform EI change
comes first (and alone), the brace's uniform EA change comes first.  ``--no-floor`` drops the
frames' 5 % floor on uniform and taper features (``realisation._frame_change``)."""

import argparse
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gfe_opt import realisation  # noqa: E402
from gfe_opt.diagnosis import _generic_only  # noqa: E402
from gfe_opt.fitting import noise_of  # noqa: E402
from gfe_opt.frame import FrameDiscretisation  # noqa: E402
from gfe_opt.problems import portal_frame  # noqa: E402
from tests.test_frame_diagnosis import NOISE, _exact, _guess, _measured, _sensors, loose_brace  # noqa: E402


def _features(model, measured, noise, samples):
    result = _generic_only(model, measured, noise)
    if result is None or not result.ok:
        return None
    band = realisation.profile_band(FrameDiscretisation(model), measured, result, noise,
                                    samples=samples)
    return [(m, f.kind, what, round(float(f.value), 3)) for m, _, f, what in band.features]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", default="100-111", help="first-last (inclusive)")
    parser.add_argument("--samples", type=int, default=realisation.BAND_SAMPLES)
    parser.add_argument("--no-floor", action="store_true")
    parser.add_argument("--weighting", choices=("rows", "energy"), default="rows",
                        help="the generic update's residual weighting (rows: the paper's)")
    args = parser.parse_args()
    from gfe_opt import frame_generic

    frame_generic.WEIGHTING = args.weighting
    first, last = (int(v) for v in args.seeds.split("-"))
    if args.no_floor:
        local = realisation._frame_change
        realisation._frame_change = lambda f: 1.0 if f.kind in ("uniform", "taper") else local(f)
    noise = noise_of(NOISE["freq_noise"], NOISE["shape_noise"])
    portal = portal_frame()
    softer = replace(portal, members=tuple(replace(m, E=m.E * (0.9 if m.id == "beam" else 1.0))
                                           for m in portal.members))
    cases = {"as modelled": (portal, _exact(portal), _guess(portal, [])),
             "beam E x 0.9": (portal, _exact(softer), _guess(softer, [])),
             "brace EA x 0.4": loose_brace(0.4)}
    counts = {"none_clean": 0, "beam_first": 0, "beam_alone": 0, "brace_first": 0, "seeds": 0}
    for seed in range(first, last + 1):
        found = {}
        for name, (model, exact, guess) in cases.items():
            measured = _measured(model, exact, guess, _sensors(model), seed)
            found[name] = _features(model, measured, noise, args.samples) or []
            print(f"seed {seed} {name}: {found[name]}", flush=True)
        counts["seeds"] += 1
        counts["none_clean"] += found["as modelled"] == []
        beam = [f[:3] for f in found["beam E x 0.9"]]
        counts["beam_first"] += beam[:1] == [("beam", "uniform", "EI")]
        counts["beam_alone"] += beam == [("beam", "uniform", "EI")]
        counts["brace_first"] += [f[:3] for f in found["brace EA x 0.4"]][:1] == [
            ("brace", "uniform", "EA")]
    print(("without the floor " if args.no_floor else "") + str(counts))


if __name__ == "__main__":
    main()
