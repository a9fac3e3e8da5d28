"""Re-derive problems/hr-cantilever.csv from the published impulse-test spectrum.

Source: High-Rate-SHM Working Group, "Dataset-4: Univariate signal with non-stationarity",
https://github.com/High-Rate-SHM-Working-Group/Dataset-4-Univariate-signal-with-non-stationarity
file modal_analysis/data/FFT_data.lvm (LabVIEW text: frequency [Hz] and the RMS FFT of the
tip acceleration [dB], Δf = 0.0853 Hz), licensed CC BY-SA 4.0.

Peaks: local maxima of the dB spectrum below 2 kHz standing 30 dB or more above their
surroundings (scipy's prominence) and above -100 dB; each refined by a parabola through the
line and its two neighbours (in dB).  Two peaks are left out by that rule and by name:
168.5 Hz (-102 dB) and 191.7 Hz (prominence 21 dB), near the first torsional mode of the
strip (about 204 Hz by the thin-strip formula), which a bending model does not have.

    python scripts/hr_cantilever_peaks.py PATH/TO/FFT_data.lvm [--out problems/hr-cantilever.csv]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.signal import find_peaks

PROMINENCE_DB = 30.0
FLOOR_DB = -100.0
UPPER_HZ = 2000.0

HEADER = """\
# Measured bending frequencies [Hz] of a steel cantilever (759 x 50.66 x 5.14 mm), impulse
# test, one accelerometer (PCB J352C33) near the free end; frequencies only (no shapes).
# Derived by scripts/hr_cantilever_peaks.py (spectral peaks, parabolic refinement) from
# modal_analysis/data/FFT_data.lvm of: High-Rate-SHM Working Group, "Dataset-4: Univariate
# signal with non-stationarity",
# https://github.com/High-Rate-SHM-Working-Group/Dataset-4-Univariate-signal-with-non-stationarity
# Licensed CC BY-SA 4.0 (https://creativecommons.org/licenses/by-sa/4.0/); this derived
# file is shared under the same licence (problems/hr-cantilever.LICENSE.txt).
"""


def read_lvm(path: Path):
    """(frequency [Hz], level [dB]) from the LabVIEW measurement file."""
    rows = []
    started = 0
    for line in path.read_text(errors="replace").splitlines():
        if line.startswith("***End_of_Header***"):
            started += 1
            continue
        if started < 2:
            continue
        cells = line.split("\t")
        try:
            rows.append((float(cells[0]), float(cells[1])))
        except (ValueError, IndexError):
            continue
    data = np.array(rows)
    return data[:, 0], data[:, 1]


def peaks(freq, level):
    """Refined peak frequencies [Hz] by the rule in the module docstring."""
    band = freq < UPPER_HZ
    idx, props = find_peaks(level[band], prominence=PROMINENCE_DB)
    df = freq[1] - freq[0]
    out = []
    for i in idx:
        if level[i] < FLOOR_DB:
            continue
        a, b, c = level[i - 1], level[i], level[i + 1]
        out.append(freq[i] + 0.5 * (a - c) / (a - 2 * b + c) * df)
    return np.array(out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("lvm", type=Path)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    f = peaks(*read_lvm(args.lvm))
    text = HEADER + "x," + ",".join(f"{v:.3f}" for v in f) + "\n"
    if args.out:
        args.out.write_text(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
