"""BLAS threads (gfe_opt.threads): public calls run with one and give the count back; fit
workers forked under one start no BLAS threads of their own."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import gfe_opt
from gfe_opt import correlation
from gfe_opt.problems import problem_file
from gfe_opt.synthetic import interior_sensors, synthetic_measurement


def _counts():
    return [i["num_threads"] for i in threadpool_info()]


def test_a_public_comparison_runs_with_one_blas_thread_and_gives_the_count_back(
        monkeypatch):
    """``gfe_opt.compare`` solves its modes with one BLAS thread (as the fit workers do:
    the same rounding, whatever the core count) and leaves the counts as it found them."""
    model = gfe_opt.load_model(problem_file("ss-steel-beam.toml"))
    measured = synthetic_measurement(model, 3, interior_sensors(model.length, 9))
    seen = []
    real = correlation.discretisation_modes

    def spy(*args, **kwargs):
        seen.append(max(_counts()))
        return real(*args, **kwargs)

    monkeypatch.setattr(correlation, "discretisation_modes", spy)
    # two threads asked for, whatever this process started with (one core: one stays)
    with threadpool_limits(limits=2):
        before = _counts()
        gfe_opt.compare(model, measured)
        assert seen == [1]
        assert _counts() == before


POOL_THREADS_CODE = """
import contextlib, json, os
import numpy, scipy.linalg
from threadpoolctl import threadpool_info, threadpool_limits
from gfe_opt import diagnosis, threads

def blas_threads():
    return max(i["num_threads"] or 1 for i in threadpool_info() if i["user_api"] == "blas")

def worker(_):
    return len(os.listdir("/proc/self/task")), blas_threads()

if blas_threads() == 1:
    print("one thread from the start")
else:
    for forked_under_one in (True, False):
        pool = diagnosis._new_pool(2)
        limits = threads.one_thread_limits if forked_under_one else contextlib.nullcontext
        with limits():
            futures = [pool.submit(worker, i) for i in range(2)]
        print(json.dumps([forked_under_one, sorted({f.result() for f in futures})]))
        pool.shutdown(wait=True)
"""


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="Linux's /proc lists threads")
def test_fit_workers_forked_under_one_blas_thread_start_no_blas_threads():
    """A fit worker forked under one BLAS thread (as :func:`diagnosis._pool_jobs` forks
    them) sets no count again, so OpenBLAS restarts no pool of threads in it: the worker
    runs on its one OS thread; forked under more, its initializer must set one, and the
    restarted threads are there beside it (they spin at first: the slower workers)."""
    env = {k: v for k, v in os.environ.items() if not k.endswith("THREADS")}
    run = subprocess.run([sys.executable, "-c", POOL_THREADS_CODE], capture_output=True,
                         text=True, timeout=120, env=env)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.strip().splitlines()
    if lines == ["one thread from the start"]:
        pytest.skip("BLAS loads with one thread here (one core)")
    assert json.loads(lines[0]) == [True, [[1, 1]]]
    under_more, restarted = json.loads(lines[1])
    assert not under_more and all(t > 1 and b == 1 for t, b in restarted)
