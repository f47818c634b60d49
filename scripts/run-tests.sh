#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the default test suite. Slow tests carry the ctest label "slow" and are left out
# unless ROAMLAB_SLOW_TESTS=1.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build_dir=${BUILD_DIR:-build}
exclude=(-LE slow)
[ "${ROAMLAB_SLOW_TESTS:-0}" = "1" ] && exclude=()
ctest --test-dir "$build_dir" --output-on-failure -j "${JOBS:-$(nproc)}" "${exclude[@]}"
