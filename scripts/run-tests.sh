#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the default test suite, then the quick subset of the regression suite
# (scenarios/regression.yaml, results in BUILD_DIR/regress/). Slow tests carry the ctest label "slow" and are left out
# unless ROAMLAB_SLOW_TESTS=1; ROAMLAB_FULL_REGRESSION=1 runs every regression case.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build_dir=${BUILD_DIR:-build}
exclude=(-LE slow)
[ "${ROAMLAB_SLOW_TESTS:-0}" = "1" ] && exclude=()
ctest --test-dir "$build_dir" --output-on-failure -j "${JOBS:-$(nproc)}" "${exclude[@]}"
regress=(--quick)
[ "${ROAMLAB_FULL_REGRESSION:-0}" = "1" ] && regress=()
"$build_dir/apps/roamlab" regress scenarios/regression.yaml --out "$build_dir/regress" --jobs "${JOBS:-$(nproc)}" \
  "${regress[@]}"
