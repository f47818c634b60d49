#!/usr/bin/env bash
# Installs roamlab from BUILD_DIR (default build) into a temporary prefix, then configures a consumer project that
# finds it with find_package(roamlab) and registers two regression suites with roamlab_add_regression_suite: one
# whose checks hold and one with an impossible bound, which ctest must see fail.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
scenarios="$work/prefix/share/roamlab/scenarios"
configs="$work/prefix/share/roamlab/configs"
mkdir -p "$work/consumer"
cat > "$work/consumer/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.22)
project(consumer NONE)
enable_testing()
find_package(roamlab 0.1 REQUIRED)
roamlab_add_regression_suite(consumer_regression suite.yaml)
roamlab_add_regression_suite(consumer_impossible impossible.yaml)
set_tests_properties(consumer_impossible PROPERTIES WILL_FAIL TRUE)
EOF
for suite in suite impossible; do
  bound='<= 1.0'
  [ "$suite" = impossible ] && bound='<= 0.0'
  cat > "$work/consumer/$suite.yaml" <<EOF
cases:
  - name: atv_calibration
    mode: calibrate
    scenario: $scenarios/atv_hills.yaml
    config: $configs/atv_calibration.yaml
    checks:
      - {metric: metrics.ate_m, bound: "$bound"}
      - {metric: metrics.parameters.odometer.k_gamma.error.max_abs, bound: "<= 0.005"}
EOF
done
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
ctest --test-dir "$work/consumer/build" --output-on-failure
grep -q '<failure message="value .* violates bound' "$work/consumer/build/regress/consumer_impossible/junit.xml"
echo "test-install: find_package(roamlab) and roamlab_add_regression_suite work from $work/prefix"
