"""Write the example measured files shipped in ``problems/`` (the README's commands use them).

    python scripts/make_examples.py [--check]

* ``demo-measured.json``, ``.csv``, ``.uff``: the demo's test (``gfe_opt.demo``): the
  paper's steel beam with a crack at x = 0.19 m, a/d = 0.5, 5 modes at 45 sensors,
  simulated on an independent fine mesh with 0.3 % shape and 0.05 % frequency noise.
* ``demo-frf.uff``: accelerances of the same cracked beam, roving hammer, response at
  x = 0.1725 m, 9 points, 150-2300 Hz in steps of 1.25 Hz, 0.5-0.8 % damping, complex noise
  of 0.5 % of each FRF's peak: modal superposition of the modes of the closed-form-checked
  1200-element reference beam of ``tests/reference.py`` (not gfe-opt's own model).

``--check`` regenerates into a temporary folder and fails (exit 1) when a shipped file
differs, so the files cannot drift from the code that makes them.
"""

import filecmp
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gfe_opt.demo import DEMO_CRACK, demo_measurement  # noqa: E402
from gfe_opt.measured import save_measured  # noqa: E402
from tests.reference import ReferenceBeam, christides_barr, synthesise_frfs, write_uff58  # noqa: E402,E501

FRF_POINTS = np.linspace(0.0575, 0.5175, 9)
FRF_LINES = np.arange(150.0, 2300.0 + 1e-9, 1.25)
FRF_DAMPING = np.array([0.005, 0.006, 0.008])
FRF_RESPONSE = 2  # index of the response point (x = 0.1725 m)


def write_examples(folder: Path) -> list[Path]:
    measured = demo_measurement()
    paths = []
    for suffix in (".json", ".csv", ".uff"):
        path = folder / f"demo-measured{suffix}"
        save_measured(measured, path, force=True)
        paths.append(path)
    beam = ReferenceBeam(rigidity=christides_barr(DEMO_CRACK["position"],
                                                  DEMO_CRACK["depth_ratio"]))
    freqs, full = beam.modes(3)
    h = beam.length / beam.elements
    nodes = np.round(FRF_POINTS / h).astype(int)
    shapes = full[2 * nodes]  # translations at the (node-coincident) points
    H = synthesise_frfs(freqs, shapes, FRF_DAMPING, FRF_LINES, FRF_RESPONSE,
                        form="accelerance", noise=0.005, seed=7)
    path = folder / "demo-frf.uff"
    write_uff58(path, FRF_POINTS, FRF_LINES, H, FRF_RESPONSE)
    return paths + [path]


def main():
    if "--check" in sys.argv[1:]:
        with tempfile.TemporaryDirectory() as tmp:
            fresh = write_examples(Path(tmp))
            stale = [p.name for p in fresh if not filecmp.cmp(p, ROOT / "problems" / p.name,
                                                              shallow=False)]
        if stale:
            print("differ from what scripts/make_examples.py writes: " + ", ".join(stale))
            return 1
        print("the example files are as scripts/make_examples.py writes them")
        return 0
    for path in write_examples(ROOT / "problems"):
        print(f"{path.relative_to(ROOT)} ({path.stat().st_size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
