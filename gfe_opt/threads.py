"""BLAS threads.  Every fit, diagnosis, update and comparison runs with one
(:func:`one_blas_thread`): the same rounding in this process as in the fit workers',
whatever the machine's core count, and the small matrices gain nothing from more.  With
numpy's and scipy's OpenBLAS each loaded with a pool of two threads (a 2-core machine), the
screen of a portal member's section-loss grid (171 points, 80-column reduced pencils) took
2.5 s against 0.19 s with one thread, and one comparison of the demo beam 7.5 ms against
4.1 ms (measured in process; the threads that poll for work after each call, the likely
cause, are not measured)."""

from __future__ import annotations

import contextlib
import functools
import sys


def one_thread_limits():
    """One thread for each thread pool (BLAS, OpenMP) that has more, in effect from this
    call (threadpoolctl's limits, a context manager restoring them); a null context where
    every pool has one.  A count is never set again where it is one already: OpenBLAS
    restarts its pool of threads when its count is set in a process forked from one that
    had the pool (a fit worker: three OS threads in it instead of one), and the worker was
    slower (measured: a 92-DOF generalised eigensolve in two such workers at once 0.76 ms
    against 0.54 ms, averaged over its first 0.2 s; the same over 2 s; the 46-element
    diagnosis's workers 1.06 s of CPU against 0.88 s).  The libraries are found once
    (0.27 ms), and again when modules were imported since (one that loads its own BLAS);
    a call then costs 10 µs."""
    global _CONTROLLER
    if _CONTROLLER is None or _CONTROLLER[0] != len(sys.modules):
        import scipy.linalg  # noqa: F401 (its BLAS loaded, to be controlled too)
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = (len(sys.modules), ThreadpoolController())
    controller = _CONTROLLER[1]
    more = sorted({c.prefix for c in controller.lib_controllers
                   if (c.get_num_threads() or 1) > 1})
    return controller.limit(limits=dict.fromkeys(more, 1)) if more else \
        contextlib.nullcontext()


#: (len(sys.modules) when built, threadpoolctl's controller of the libraries loaded then)
_CONTROLLER = None


def one_blas_thread(fn):
    """Run ``fn`` with one BLAS thread, as the fit workers do: the same rounding in this
    process as in theirs, whatever the machine's core count (an update reproduces the fit
    its diagnosis made; a diagnosis does not hinge on how many threads BLAS took)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with one_thread_limits():
            return fn(*args, **kwargs)
    return wrapper
