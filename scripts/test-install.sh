#!/usr/bin/env bash
# Installs roamlab from BUILD_DIR (default build) into a temporary prefix, then
#  1. checks the installed headers: no internal/ folder, no include of an internal header;
#  2. builds and runs examples/consumer (find_package(roamlab COMPONENTS estimator recording), a user error model
#     registered by name, a solve) with MuJoCo's and OpenCV's CMake packages disabled, and checks that neither the
#     estimator's nor the recording's installed target files name them and that the program links neither;
#  3. builds a program that links every component (find_package(roamlab COMPONENTS <all>)), after checking that the
#     same project fails to configure with MuJoCo and OpenCV hidden as in 2;
#  4. configures a consumer project that finds roamlab with find_package(roamlab) and registers two regression
#     suites with roamlab_add_regression_suite: one whose checks hold and one with an impossible bound, which ctest
#     must see fail.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
prefix="$work/prefix"
cmakedir="$prefix/lib/cmake/roamlab"

fail() {
  echo "test-install: $1" >&2
  exit 1
}

# 1. The public headers.
[ -f "$prefix/include/roamlab/estimator/model_registry.h" ] || fail "no estimator headers in $prefix/include/roamlab"
if find "$prefix/include" -type d -name internal | grep .; then fail "internal/ headers were installed"; fi
if grep -rn '#include ".*internal/' "$prefix/include"; then fail "an installed header includes an internal one"; fi

# 2. The consumer example, without MuJoCo or OpenCV.
if grep -il 'mujoco\|opencv' "$cmakedir"/roamlab_{common,recording,estimator}Targets*.cmake; then
  fail "the estimator component's targets name MuJoCo or OpenCV"
fi
# (--no-warn-unused-cli: that nothing reads the two variables is the point.)
no_mujoco_opencv=(-DCMAKE_DISABLE_FIND_PACKAGE_mujoco=TRUE -DCMAKE_DISABLE_FIND_PACKAGE_OpenCV=TRUE --no-warn-unused-cli)
cmake -S examples/consumer -B "$work/example" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  "${no_mujoco_opencv[@]}" >/dev/null
cmake --build "$work/example" -j "${JOBS:-$(nproc)}" >/dev/null
if ldd "$work/example/consumer_example" | grep -i 'mujoco\|opencv'; then fail "consumer_example links MuJoCo or OpenCV"; fi
"$work/example/consumer_example" "$work/example"

# 3. Every component.
mkdir -p "$work/all"
cat > "$work/all/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.22)
project(all_components CXX)
set(CMAKE_CXX_STANDARD 17)
set(components common recording importers frontend estimator odometry eval sim gap gap_sim)
find_package(roamlab 0.1 REQUIRED COMPONENTS ${components})
list(TRANSFORM components PREPEND roamlab:: OUTPUT_VARIABLE targets)
add_executable(all_components main.cc)
target_link_libraries(all_components PRIVATE ${targets})
CMAKE
cat > "$work/all/main.cc" <<'CXX'
#include "estimator/model_registry.h"
#include "estimator/odometry/odometry_model.h"
#include "eval/metrics.h"
#include "frontend/scan_matcher.h"
#include "gap/twin.h"
#include "importers/rosbag.h"
#include "sim/simulator.h"
int main() { return roamlab::estimator::FindErrorModel("gps") == nullptr ? 1 : 0; }
CXX
# The same flags make asking for sim fail: they do hide MuJoCo and OpenCV.
if cmake -S "$work/all" -B "$work/all/hidden" -DCMAKE_PREFIX_PATH="$prefix" "${no_mujoco_opencv[@]}" >/dev/null 2>&1; then
  fail "find_package(roamlab COMPONENTS sim ...) succeeded with MuJoCo and OpenCV hidden"
fi
cmake -S "$work/all" -B "$work/all/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/all/build" >/dev/null
"$work/all/build/all_components" || fail "the program linking every component did not find the gps model"

# 4. The regression suites.
scenarios="$prefix/share/roamlab/scenarios"
configs="$prefix/share/roamlab/configs"
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
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
ctest --test-dir "$work/consumer/build" --output-on-failure
grep -q '<failure message="value .* violates bound' "$work/consumer/build/regress/consumer_impossible/junit.xml"
echo "test-install: the headers, the consumer example (no MuJoCo, no OpenCV), every component and"
echo "test-install: roamlab_add_regression_suite work from $prefix"
