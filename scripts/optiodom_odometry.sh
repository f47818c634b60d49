#!/usr/bin/env bash
# Model-free odometry on the real OptiOdom recordings (seed 001 on real data): imports every run, learns each model on
# the runs of some shapes and evaluates it on runs of another shape, one table per split.
#   bash scripts/optiodom_odometry.sh [DATA_DIR] [OUT_DIR]     (DATA_DIR: the OptiOdom dataset's data/ folder; OUT_DIR: out/optiodom)
# Needs build/apps/roamlab. Splits (sets recorded the same day; the Jun-2020 and Dec-2020 robots differ):
#   diff_dec_sq2circ  train square + ivanjko (Dec 2020)   test circular (Dec 2020)
#   diff_jun_sq2circ  train square + ivanjko (Jun 2020)   test circular (Jun 2020)
#   diff_dec_circ2sq  train circular (Dec 2020)           test square + ivanjko (Dec 2020)
#   diff_jun_circ2sq  train circular (Jun 2020)           test square + ivanjko (Jun 2020)
#   omni3_sq2circ     train square                        test circular
#   omni3_circ2sq     train circular                      test square
#   omni4_sq2circ, omni4_circ2sq, tricycle_sq2circ, tricycle_circ2sq: likewise
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
data=${1:-$here/../shared/data/optiodom/data}
out=${2:-$here/out/optiodom}
roamlab=$here/build/apps/roamlab
interval=${INTERVAL:-0.25}
[ -d "$data" ] || { echo "optiodom_odometry.sh: $data: no OptiOdom data" >&2; exit 2; }
mkdir -p "$out/rec"
# Import: out/rec/<kind>/<shape>/<run>.
for run in "$data"/*/*/*/*_run-??.csv; do
  rel=${run#"$data"/}
  dest="$out/rec/$(echo "$rel" | cut -d/ -f1-2)/$(basename "$run" .csv)"
  [ -f "$dest/recording.yaml" ] || "$roamlab" import optiodom "$run" --out "$dest" --quiet
done
only=${ONLY:-}  # a regular expression: run only the splits whose names match
split() {  # name, training recordings (glob), test recordings (glob)
  local name=$1 train=$2 test=$3 dir=$out/$1 models=()
  [[ -z "$only" || "$name" =~ $only ]] || return 0
  mkdir -p "$dir"
  # shellcheck disable=SC2086
  for spec in "linear" "parametric" "gp linear rbf" "gp zero rbf" "gp zero linear" "gp zero rbf+linear" \
              "gp linear rbf+linear"; do
    set -- $spec
    local file="$dir/$1${2:+_$2}${3:+_$3}.json"
    if [ "$1" = gp ]; then
      "$roamlab" odometry learn --recording $train --model gp --mean "$2" --kernel "$3" --interval "$interval" \
        --out "$file" --quiet
    else
      "$roamlab" odometry learn --recording $train --model "$1" --interval "$interval" --out "$file" --quiet
    fi
    models+=("$file")
  done
  echo "== $name (interval $interval s)"
  # shellcheck disable=SC2086
  "$roamlab" odometry evaluate --model "${models[@]}" --recording $test --out "$dir/eval"
}
r=$out/rec
split diff_dec_sq2circ "$r/diff/square/2312* $r/diff/ivanjko/2312*" "$r/diff/circular/2312*"
split diff_jun_sq2circ "$r/diff/square/2306* $r/diff/ivanjko/2506*" "$r/diff/circular/2506*"
split diff_dec_circ2sq "$r/diff/circular/2312*" "$r/diff/square/2312* $r/diff/ivanjko/2312*"
split diff_jun_circ2sq "$r/diff/circular/2506*" "$r/diff/square/2306* $r/diff/ivanjko/2506*"
split omni3_sq2circ "$r/omni3/square/*" "$r/omni3/circular/*"
split omni3_circ2sq "$r/omni3/circular/*" "$r/omni3/square/*"
split omni4_sq2circ "$r/omni4/square/*" "$r/omni4/circular/*"
split omni4_circ2sq "$r/omni4/circular/*" "$r/omni4/square/*"
split tricycle_sq2circ "$r/tricyc/square/*" "$r/tricyc/circular/*"
split tricycle_circ2sq "$r/tricyc/circular/*" "$r/tricyc/square/*"
