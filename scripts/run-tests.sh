#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the default test suite, then the cluster tests against a one-node Slurm
# (scripts/local-slurm.sh, started and stopped here), then the quick subset of the regression suite
# (regression/suite.yaml, results in BUILD_DIR/regress/). Slow tests carry the ctest label "slow" and are left out
# unless ROAMLAB_SLOW_TESTS=1; ROAMLAB_FULL_REGRESSION=1 runs every regression case. The cluster tests carry the label
# "slurm"; they run when the one-node Slurm starts here (root, slurm-wlm and munge), and otherwise are reported
# as not run; ROAMLAB_SLURM_TESTS=0 leaves them out, ROAMLAB_SLURM_TESTS=1 makes a failed start an error.
set -euo pipefail
cd "$(dirname "$0")/.."
t0=$(date +%s)
bash scripts/setup.sh
echo "roamlab tests: set-up and build took $(($(date +%s) - t0)) s"
build_dir=${BUILD_DIR:-build}
exclude=(-LE 'slow|slurm')
[ "${ROAMLAB_SLOW_TESTS:-0}" = "1" ] && exclude=(-LE slurm)
junit="$(cd "$build_dir" && pwd)/ctest-junit.xml"
ctest --test-dir "$build_dir" --output-on-failure -j "${JOBS:-$(nproc)}" "${exclude[@]}" --output-junit "$junit"
# A GoogleTest suite whose SetUpTestSuite fails reports its tests as skipped, which ctest counts as passing; the test
# output (kept in the JUnit file) says so.
if grep -q 'FAILED TEST SUITE' "$junit"; then
  echo "roamlab tests: a test suite's set-up failed and its tests were reported skipped; see $junit" >&2
  exit 1
fi
export LOCAL_SLURM_DIR=${LOCAL_SLURM_DIR:-$(cd "$build_dir" && pwd)/local-slurm}
slurm_tests=${ROAMLAB_SLURM_TESTS:-auto}
# A cluster an interrupted earlier call left running in LOCAL_SLURM_DIR is stopped first.
[ "$slurm_tests" = "0" ] || bash scripts/local-slurm.sh stop >/dev/null
if [ "$slurm_tests" = "auto" ]; then
  if bash scripts/local-slurm.sh start; then
    slurm_tests=1
  else
    echo "roamlab tests: the one-node Slurm did not start here; the cluster tests (label slurm) are NOT run" \
      "(ROAMLAB_SLURM_TESTS=1 makes this an error)" >&2
    slurm_tests=0
  fi
elif [ "$slurm_tests" = "1" ]; then
  bash scripts/local-slurm.sh start
fi
if [ "$slurm_tests" = "1" ]; then
  trap 'bash scripts/local-slurm.sh stop' EXIT
  eval "$(bash scripts/local-slurm.sh env)"
  # One at a time: the node's cores run the tasks.
  slurm_junit="$(cd "$build_dir" && pwd)/ctest-slurm-junit.xml"
  ctest --test-dir "$build_dir" --output-on-failure -L slurm --output-junit "$slurm_junit"
  if grep -q 'FAILED TEST SUITE' "$slurm_junit"; then
    echo "roamlab tests: the cluster tests' set-up failed; see $slurm_junit" >&2
    exit 1
  fi
fi
regress=(--quick)
[ "${ROAMLAB_FULL_REGRESSION:-0}" = "1" ] && regress=()
"$build_dir/apps/roamlab" regress regression/suite.yaml --out "$build_dir/regress" --jobs "${JOBS:-$(nproc)}" \
  "${regress[@]}"
