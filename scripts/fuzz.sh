#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/; clang, AddressSanitizer + UndefinedBehaviorSanitizer) into BUILD_DIR, writes
# their seed corpora and runs each harness, one after another, for FUZZ_SECONDS (docs/reliability.md).
#   BUILD_DIR      default build-asan (shared with scripts/sanitize.sh)
#   FUZZ_SECONDS   time per harness, default 30 (-max_total_time)
#   FUZZ_RUNS      when set: this many executions per harness instead of a time (-runs)
#   FUZZERS        the harnesses to run (space-separated), default all
#   JOBS           build parallelism, default the number of cores
#   SANITIZE_OPT   optimization level of the build, default -O2 (ROAMLAB_SANITIZE_OPT); -O0 compiles fastest
#   FUZZ_BUILD     0: run the harnesses already built in BUILD_DIR (no configure, no build), default 1
#   ASAN_OPTIONS   default malloc_context_size=2 (below)
#   ROAMLAB_DATA_DIR  real recordings to cut small seed excerpts from (default: the data directory the tests read,
#                     ROAMLAB_SHARED_DIR/data in tests/CMakeLists.txt; skipped when absent)
#   ROAMLAB        the command line that simulates the recording seeds (default build/apps/roamlab, the Release build
#                  of scripts/setup.sh; skipped when absent)
# The seeds are written to BUILD_DIR/fuzz/seeds/<harness>, what the fuzzers add to BUILD_DIR/fuzz/corpus/<harness>,
# crash reproducers to BUILD_DIR/fuzz/artifacts/. Exits 1 when a harness finds a crash, a leak or a timeout.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=${BUILD_DIR:-build-asan}
seconds=${FUZZ_SECONDS:-30}
all=(recording_fuzz ros1_bag_fuzz mcap_fuzz rosbag2_fuzz optiodom_fuzz csv_fuzz scenario_fuzz estimator_config_fuzz
     regress_suite_fuzz)
read -r -a fuzzers <<<"${FUZZERS:-${all[*]}}"
data_dir=${ROAMLAB_DATA_DIR:-../shared/data}

command -v clang++ >/dev/null || { echo "roamlab fuzz: clang++ not found (scripts/setup.sh installs clang)" >&2; exit 1; }
start=$(date +%s)
if [ "${FUZZ_BUILD:-1}" != 0 ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROAMLAB_SANITIZE=ON \
    -DROAMLAB_SANITIZE_OPT="${SANITIZE_OPT:--O2}" -DROAMLAB_FUZZ=ON >/dev/null
  cmake --build "$build_dir" -j "${JOBS:-$(nproc)}" --target fuzz_seeds "${fuzzers[@]}"
fi
built=$(date +%s)

# The longest input per harness where the default (the largest seed) is more than the harness needs: a suite's cases
# are loaded one after the other, and 4 KB hold two or three of them.
declare -A max_len=([regress_suite_fuzz]=4096)

work="$build_dir/fuzz"
seeds="$work/seeds"
rm -rf "$seeds"
mkdir -p "$seeds" "$work/artifacts"
"$build_dir/fuzz/fuzz_seeds" "$seeds"
mkdir -p "$seeds/scenario_fuzz" "$seeds/estimator_config_fuzz" "$seeds/regress_suite_fuzz"
cp scenarios/*.yaml "$seeds/scenario_fuzz/"
cp configs/*.yaml "$seeds/estimator_config_fuzz/"
cp regression/*.yaml "$seeds/regress_suite_fuzz/"
# Each case of the repository's suites as a suite of its own, without the comment lines: every case fits in the
# harness's -max_len below.
for suite in regression/*.yaml; do
  awk -v out="$seeds/regress_suite_fuzz/$(basename "$suite" .yaml)" '
    /^[[:space:]]*#/ { next }
    /^  - name:/ { n++; file = sprintf("%s_case%02d.yaml", out, n); printf "%s", head > file }
    n == 0 { head = head $0 "\n"; next }
    { print > file }' "$suite"
done
for seed in "$seeds"/regress_suite_fuzz/*_case*.yaml; do
  [ "$(wc -c <"$seed")" -le "${max_len[regress_suite_fuzz]}" ] ||
    echo "roamlab fuzz: the seed $seed is longer than -max_len=${max_len[regress_suite_fuzz]} (cut)" >&2
done
# Simulated recordings, each file cut to its first 12 lines, packed as recording_fuzz reads them.
roamlab=${ROAMLAB:-build/apps/roamlab}
if [ -x "$roamlab" ]; then
  mkdir -p "$seeds/recording_fuzz"
  for scenario in atv_hills indoor_diffdrive_slip; do
    rec="$work/simulated/$scenario"
    rm -rf "$rec"
    "$roamlab" simulate "scenarios/$scenario.yaml" --out "$rec" --quiet
    { cat "$rec/recording.yaml"
      for file in "$rec"/*.csv "$rec"/ground_truth.tum; do
        [ -f "$file" ] || continue
        printf '%%%%%%%% %s\n' "$(basename "$file")"; head -n 12 "$file"
      done; } >"$seeds/recording_fuzz/$scenario"
  done
fi
# Small excerpts of real recordings, when present: the head of each file (never kept in the repository).
if [ -d "$data_dir" ]; then
  for meta in $(for robot in diff omni3 omni4 tricyc; do
                  find "$data_dir/optiodom/data/$robot" -name '*_metadata.csv' 2>/dev/null | sort | head -n 3
                done); do
    run=${meta%_metadata.csv}_run-01.csv
    [ -f "$run" ] || continue
    { head -n 40 "$run"; printf '%%%%%%%% set_metadata.csv\n'; cat "$meta"; } >"$seeds/optiodom_fuzz/$(basename "$run")"
  done
  husky="$data_dir/husky_test1/test1.bag"
  [ -f "$husky" ] && head -c 65536 "$husky" >"$seeds/ros1_bag_fuzz/husky"
  mcap="$data_dir/ros2/rosbags_fixture/test_bag_mcap/test_bag_mcap.mcap"
  [ -f "$mcap" ] && head -c 65536 "$mcap" >"$seeds/mcap_fuzz/fixture"
  xio="$data_dir/xio_imu_mag/sensor_data.csv"
  if [ -f "$xio" ]; then
    { printf 'time: {column: 0, unit: s}\ncsv: {header: true}\nstreams:\n'
      printf '  imu: {type: imu, columns: [1, 2, 3, 4, 5, 6], units: [deg/s, deg/s, deg/s, g, g, g]}\n'
      printf '  magnetometer: {type: magnetometer, columns: [7, 8, 9], units: uT}\n'
      printf '%%%%%%%% a.csv\n'; head -n 40 "$xio"; } >"$seeds/csv_fuzz/xio"
  fi
fi

# Allocation and free stacks of a report are cut to the allocating call: the system libraries (yaml-cpp, bzip2, ...)
# have no frame pointers, so AddressSanitizer's fast unwinder reads their stack as frames, each stack a new entry of
# its stack depot, which never shrinks (docs/reliability.md). A reproducer run alone gives the whole stacks.
export ASAN_OPTIONS=${ASAN_OPTIONS:-malloc_context_size=2}
failed=()
for f in "${fuzzers[@]}"; do
  mkdir -p "$work/corpus/$f"
  limit=(-max_total_time="$seconds")
  [ -n "${FUZZ_RUNS:-}" ] && limit=(-runs="$FUZZ_RUNS")
  [ -n "${max_len[$f]:-}" ] && limit+=(-max_len="${max_len[$f]}")
  log="$work/$f.log"
  if "$build_dir/fuzz/$f" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$work/artifacts/$f-" "$work/corpus/$f" "$seeds/$f" >"$log" 2>&1; then
    status=ok
  else
    status=FAILED
    failed+=("$f")
    tail -n 40 "$log" >&2
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  echo "roamlab fuzz: $f: $status, $runs executions (log $log)"
done
echo "roamlab fuzz: build $((built - start)) s, total $(($(date +%s) - start)) s"
if ((${#failed[@]})); then
  echo "roamlab fuzz: failed: ${failed[*]} (reproducers in $work/artifacts)" >&2
  exit 1
fi
