#!/usr/bin/env bash
# Model-free odometry on the simulated deformed robots (seed 001, Section IV, Table II): simulates the training and
# test drives of configurations F1 (taped wheel, differential drive), T1 (unaligned wheels, mecanum) and T2 (tilted
# wheel, mecanum), learns every model from the training drive's scan matcher and evaluates it on the test drive
# against ground_truth.tum, one table per configuration (the seed's Tables III-IV).
#   bash scripts/deformed_odometry.sh [OUT_DIR]     (default out/deformed; about 10 minutes of CPU)
# Needs build/apps/roamlab. Key intervals as the seed: 0.3 s for the differential drive, 0.6 s for the mecanum robot.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/deformed}
roamlab=$here/build/apps/roamlab
configuration() {  # name, key interval [s]
  local name=$1 interval=$2 dir=$out/$1 models=()
  mkdir -p "$dir"
  for role in train test; do
    [ -f "$dir/$role/recording.yaml" ] ||
      "$roamlab" simulate "$here/scenarios/deformed_${name}_${role}.yaml" --out "$dir/$role" --quiet
  done
  # shellcheck disable=SC2086
  for spec in "linear" "parametric" "gp zero rbf" "gp linear rbf" "gp zero linear" "gp zero rbf+linear" \
              "gp linear rbf+linear"; do
    set -- $spec
    local file="$dir/$1${2:+_$2}${3:+_$3}.json"
    if [ "$1" = gp ]; then
      "$roamlab" odometry learn --recording "$dir/train" --model gp --mean "$2" --kernel "$3" --interval "$interval" \
        --out "$file" --quiet
    else
      "$roamlab" odometry learn --recording "$dir/train" --model "$1" --interval "$interval" --out "$file" --quiet
    fi
    models+=("$file")
  done
  echo "== $name (interval $interval s)"
  "$roamlab" odometry evaluate --model "${models[@]}" --recording "$dir/test" --out "$dir/eval"
}
configuration f1 0.3
configuration t1 0.6
configuration t2 0.6
