"""Write the example measured files shipped in ``problems/`` (the README's commands use them).

    python scripts/make_examples.py [--check]

* ``demo-measured.json``, ``.csv``, ``.uff``: the demo's test (``gfe_opt.demo`` reads the
  JSON): the paper's steel beam with a crack at x = 0.19 m, a/d = 0.5, 5 modes at 45
  sensors, from the tests' independent 1200-element Hermite beam (``tests/reference.py``,
  not gfe-opt's model) with 0.3 % shape and 0.05 % frequency noise.
* ``demo-frf.uff``: accelerances of the same cracked beam, roving hammer, response at
  x = 0.1725 m, 9 points, 150-2300 Hz in steps of 1.25 Hz, 0.5-0.8 % damping, complex noise
  of 0.5 % of each FRF's peak: modal superposition of the modes of the closed-form-checked
  1200-element reference beam of ``tests/reference.py`` (not gfe-opt's own model).

``--check`` regenerates into a temporary folder and reads both versions back: it fails
(exit 1), naming the file, the value and by how much, when a shipped value differs from the
regenerated one by more than ``CHECK_RTOL`` of its array's largest magnitude (the files come
from eigen-solves whose last bits change with the BLAS kernel and thread count; a text format
that rounds them can flip a last printed digit, which is not a drift of the code).
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gfe_opt.demo import DEMO_CRACK, NOISE  # noqa: E402
from gfe_opt.identify import load_frfs  # noqa: E402
from gfe_opt.measured import load_measured, make_measured, save_measured  # noqa: E402
from tests.reference import (  # noqa: E402
    ReferenceBeam,
    christides_barr,
    interior,
    synthesise_frfs,
    write_uff58,
)

#: the demo's test: 5 modes at 45 equally spaced interior sensors, this seed
DEMO_SEED = 2002


def demo_test():
    """The demo's measured modes from the tests' independent 1200-element beam."""
    beam = ReferenceBeam(rigidity=christides_barr(DEMO_CRACK["position"],
                                                  DEMO_CRACK["depth_ratio"]))
    x = interior(beam.length, 45)
    f, y = beam.measure(5, x, shape_noise=NOISE["shape_noise"],
                        freq_noise=NOISE["freq_noise"], seed=DEMO_SEED)
    return make_measured(x, "w", f, y, "demo: cracked beam (tests/reference.py)")

FRF_POINTS = np.linspace(0.0575, 0.5175, 9)
FRF_LINES = np.arange(150.0, 2300.0 + 1e-9, 1.25)
FRF_DAMPING = np.array([0.005, 0.006, 0.008])
FRF_RESPONSE = 2  # index of the response point (x = 0.1725 m)


def write_examples(folder: Path) -> list[Path]:
    measured = demo_test()
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


#: shipped and regenerated values agree to this fraction of their array's largest magnitude:
#: an FRF near a resonance amplifies its natural frequency's rounding (~1e-9 between BLAS
#: kernels) by 1/ζ (200 at ζ = 0.5 %): 2e-7 of the largest was seen between SkylakeX and
#: Sandybridge; 50 times that is still 500 times below the 0.5 % noise the files carry, which
#: any change of the code that makes them moves by more
CHECK_RTOL = 1e-5


def _arrays(path: Path) -> dict:
    """The numbers a file holds, by name."""
    if path.name.startswith("demo-frf"):
        f = load_frfs([path])
        return {"x": f.x, "freq": f.freq, "frf.real": f.frf.real, "frf.imag": f.frf.imag}
    m = load_measured(path)
    return {"x": m.x, "frequencies_hz": m.frequencies_hz, "shapes": m.shapes}


def differences(fresh: Path, shipped: Path, rtol: float = CHECK_RTOL) -> list[str]:
    """What differs between two versions of an example file, by value (empty: the same)."""
    if not shipped.exists():
        return [f"{shipped.name}: missing"]
    a, b = _arrays(fresh), _arrays(shipped)
    out = []
    for key in a:
        x, y = np.asarray(a[key], dtype=float), np.asarray(b[key], dtype=float)
        if x.shape != y.shape:
            out.append(f"{shipped.name}: {key} has shape {y.shape}, the script writes {x.shape}")
            continue
        scale = max(float(np.max(np.abs(x))) if x.size else 0.0, 1e-300)
        err = np.abs(x - y)
        if err.size and float(err.max()) > rtol * scale:
            i = np.unravel_index(int(np.argmax(err)), err.shape)
            where = "[" + ", ".join(str(int(k)) for k in i) + "]"
            out.append(f"{shipped.name}: {key}{where} is {float(y[i])!r}, the script writes "
                       f"{float(x[i])!r}"
                       f" (differs by {float(err.max()) / scale:.2g} of the largest, allowed "
                       f"{rtol:g})")
    return out


def main():
    if "--check" in sys.argv[1:]:
        with tempfile.TemporaryDirectory() as tmp:
            fresh = write_examples(Path(tmp))
            stale = [line for p in fresh for line in differences(p, ROOT / "problems" / p.name)]
        if stale:
            print("differ from what scripts/make_examples.py writes:\n  " + "\n  ".join(stale))
            return 1
        print(f"the example files hold what scripts/make_examples.py writes (values within "
              f"{CHECK_RTOL:g} of each array's largest)")
        return 0
    for path in write_examples(ROOT / "problems"):
        print(f"{path.relative_to(ROOT)} ({path.stat().st_size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
