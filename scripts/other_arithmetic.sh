#!/usr/bin/env bash
# The same answers under other arithmetic (issue 20): the tests that carry a decision of
# the tool (the real-data loop and the demo with their README output, the diagnosis and
# frequency-only tests, the open-world, free-free and figure tests, identification, the batch
# table, the shipped examples, the generic update's solvers) run again under other OpenBLAS
# kernels and with one BLAS thread; each run must pass.  Sandybridge (AVX) and Haswell (AVX2) run on any x86-64 machine of this kind;
# SkylakeX (AVX-512) only where the processor has it.  `--full` runs the whole suite under
# each setting instead of the decision tests.
#
#     bash scripts/other_arithmetic.sh [--full]
set -euo pipefail
cd "$(dirname "$0")/.."
DECISIONS=(
    tests/test_real_data.py
    tests/test_diagnosis.py
    tests/test_frequency_only.py
    tests/test_open_world.py
    tests/test_figures.py
    tests/test_identify.py
    tests/test_batch.py
    tests/test_effects.py
    tests/test_free_free.py
    tests/test_frame.py
    tests/test_frame_diagnosis.py
    tests/test_frame_generic.py
    tests/test_frame_profile.py
    tests/test_realisation.py
    tests/test_updating.py
    tests/test_screening.py
    tests/test_fitting_numerics.py
    tests/test_scripts.py::test_shipped_examples_are_what_the_script_writes
    tests/test_cli.py::test_demo_tells_the_whole_story_and_refuses_to_overwrite
)
if [[ "${1:-}" == "--full" ]]; then
    DECISIONS=()
fi
settings=("OPENBLAS_CORETYPE=Sandybridge" "OPENBLAS_CORETYPE=Haswell")
if grep -qw avx512f /proc/cpuinfo 2>/dev/null; then
    settings+=("OPENBLAS_CORETYPE=SkylakeX")
fi
settings+=("OPENBLAS_NUM_THREADS=1")
for setting in "${settings[@]}"; do
    echo "== python -m pytest ${DECISIONS[*]:-(the whole suite)} with ${setting}"
    env "${setting}" python -c "import threadpoolctl, numpy; \
print('   BLAS:', [(i['internal_api'], i.get('architecture'), i['num_threads']) \
for i in threadpoolctl.threadpool_info()])"
    env "${setting}" python -m pytest -q -p no:cacheprovider "${DECISIONS[@]}"
done
