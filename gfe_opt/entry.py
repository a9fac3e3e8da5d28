"""The installed ``gfe-opt`` command: imports the command line behind Ctrl-C handling, so
an interrupt while numpy and scipy load is one line too (exit 130)."""

import os
import sys

#: BLAS libraries' thread counts, set for this process before numpy loads (unless the user
#: set them): every fit, diagnosis and update runs under one BLAS thread anyway
#: (:func:`gfe_opt.threads.one_blas_thread`, the workers), and a BLAS loaded with a pool
#: of threads made the fit workers forked from this process slower at the same work
#: (measured: the 46-element diagnosis's workers 1.06 s of CPU against 0.88 s, the same
#: results to the last digit; `gfe-opt diagnose` of a 46-element beam 1.40 -> 1.22 s, best
#: of 5)
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
                "VECLIB_MAXIMUM_THREADS")


def main() -> int:
    for name in BLAS_THREADS:
        os.environ.setdefault(name, "1")
    try:
        from .cli import EXIT_INTERRUPTED
        from .cli import main as run
    except KeyboardInterrupt:
        print("gfe-opt: interrupted", file=sys.stderr)
        return 130
    try:
        return run()
    except KeyboardInterrupt:  # between main()'s own handling and the exit
        print("gfe-opt: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
