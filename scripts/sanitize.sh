#!/usr/bin/env bash
# Builds the libraries and the tests of the parsers, the recording, the estimator core and the model-free odometry with
# AddressSanitizer and UndefinedBehaviorSanitizer (clang; any finding fails the test) into BUILD_DIR and runs them
# (none of them carries the ctest label slow). The build is shared with scripts/fuzz.sh. docs/reliability.md gives
# the times.
#   BUILD_DIR  default build-asan (shared with scripts/fuzz.sh); with TESTS=fast build-asan-fast, the whole tree
#              without the fuzzers' coverage instrumentation
#   TESTS      the test binaries (space-separated), default the list below; `fast`: the whole tree, and every ctest
#              test without the label slow or slurm (the fast suite of scripts/run-tests.sh)
#   JOBS       build parallelism and the shards each test binary runs in at once, default the number of cores
#   SANITIZE_OPT  optimization level of the build, default -O2 (ROAMLAB_SANITIZE_OPT); -O0 compiles fastest
set -euo pipefail
cd "$(dirname "$0")/.."

default_tests=(common_test recording_test importers_test estimator_models_test estimator_test odometry_test
               regress_suite_test)
read -r -a tests <<<"${TESTS:-${default_tests[*]}}"
fuzz=ON
build_dir=${BUILD_DIR:-build-asan}
if [ "${tests[*]}" = fast ]; then
  fuzz=OFF
  build_dir=${BUILD_DIR:-build-asan-fast}
fi
jobs=${JOBS:-$(nproc)}

command -v clang++ >/dev/null || { echo "roamlab sanitize: clang++ not found (scripts/setup.sh installs clang)" >&2; exit 1; }
start=$(date +%s)
CC=clang CXX=clang++ cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROAMLAB_SANITIZE=ON \
  -DROAMLAB_SANITIZE_OPT="${SANITIZE_OPT:--O2}" -DROAMLAB_FUZZ="$fuzz" >/dev/null
# Leaks are errors; a finding stops the test with its report (ASAN_OPTIONS / UBSAN_OPTIONS).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if [ "${tests[*]}" = fast ]; then
  cmake --build "$build_dir" -j "$jobs"
  built=$(date +%s)
  status=0
  ctest --test-dir "$build_dir" -LE 'slow|slurm' -j "$jobs" --output-on-failure \
    --output-junit "$(cd "$build_dir" && pwd)/sanitize-junit.xml" >"$build_dir/fast.sanitize.log" 2>&1 || status=$?
  grep -E '^[0-9]+% tests passed|\(Failed\)|\(Timeout\)|Exception' "$build_dir/fast.sanitize.log" || true
  echo "roamlab sanitize: build $((built - start)) s, tests $(($(date +%s) - built)) s (log $build_dir/fast.sanitize.log)"
  [ "$status" = 0 ] || { echo "roamlab sanitize: failed (ctest exit $status)" >&2; exit 1; }
  exit 0
fi
cmake --build "$build_dir" -j "$jobs" --target "${tests[@]}"
built=$(date +%s)
failed=()
for t in "${tests[@]}"; do
  binary=$(find "$build_dir/tests" -type f -name "$t" | head -n 1)
  t0=$(date +%s)
  # JOBS shards of the binary's tests at once (GoogleTest's sharding), their logs joined afterwards.
  pids=()
  for ((shard = 0; shard < jobs; shard++)); do
    GTEST_TOTAL_SHARDS=$jobs GTEST_SHARD_INDEX=$shard "$binary" --gtest_brief=1 \
      >"$build_dir/$t.$shard.sanitize.log" 2>&1 &
    pids+=($!)
  done
  status=ok
  for pid in "${pids[@]}"; do wait "$pid" || status=FAILED; done
  for ((shard = 0; shard < jobs; shard++)); do
    cat "$build_dir/$t.$shard.sanitize.log"
    rm -f "$build_dir/$t.$shard.sanitize.log"
  done >"$build_dir/$t.sanitize.log"
  [ "$status" = ok ] || { failed+=("$t"); tail -n 60 "$build_dir/$t.sanitize.log" >&2; }
  echo "roamlab sanitize: $t: $status in $(($(date +%s) - t0)) s (log $build_dir/$t.sanitize.log)"
done
echo "roamlab sanitize: build $((built - start)) s, tests $(($(date +%s) - built)) s"
if ((${#failed[@]})); then
  echo "roamlab sanitize: failed: ${failed[*]}" >&2
  exit 1
fi
