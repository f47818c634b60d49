#!/usr/bin/env bash
# The MuJoCo twin diagnosed against the real OptiOdom recordings: per robot day, the twin's patch is fitted on each
# training run (`roamlab diagnose --replay`, the default --std auto: HAC on these imported runs) and shown on held-out
# runs of the same robot (--held-out); tools/twin_table.py then prints the drift table and the within-day spread of
# the fitted parameters. Days: diff_dec (23 Dec 2020: square runs train, circular and Ivanjko runs held out),
# diff_jun (square runs of 23 Jun 2020 train, circular and Ivanjko runs of 25 Jun held out: two days apart, the
# dataset has no other runs of 23 Jun), diff_jun25 (25 Jun: circular runs train, another circular and an Ivanjko run
# held out), omni3 (22 Dec 2020: square runs train, circular runs held out), diffset_dec (23 Dec: the patch fitted on a
# square, a circular and an Ivanjko run together, --train-with, with at most 2 and 3 effects; the other circular,
# Ivanjko and square runs of the day held out), squareset_dec and squareset_jun (three square runs of 23 Dec or of
# 23 Jun fitted together, at most 3 effects; the day's fourth square and the circular and Ivanjko runs of 23 Dec or
# 25 Jun held out).
#   bash scripts/twin_optiodom.sh [DATA_DIR] [OUT_DIR]   (DATA_DIR: the OptiOdom dataset's data/ folder, default
#                                                          $ROAMLAB_DATA_DIR/optiodom/data, else ../shared/data's;
#                                                          OUT_DIR: out/twin_optiodom)
# Needs build/apps/roamlab and python3. Ten diagnoses of about 40-70 s of CPU each and two (diffset_dec) of about
# 190-200 s, on two threads; JOBS (default 1) of them at a time (OUT/<day>_<set>.time: each one's wall and CPU time).
# ONLY (a regular expression) runs only the days whose names match (diff_dec, diff_jun, diff_jun25, omni3,
# diffset_dec, squareset_dec, squareset_jun).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
data=${1:-${ROAMLAB_DATA_DIR:-$here/../shared/data}/optiodom/data}
out=${2:-$here/out/twin_optiodom}
roamlab=$here/build/apps/roamlab
jobs=${JOBS:-1}
only=${ONLY:-}
[ -d "$data" ] || { echo "twin_optiodom.sh: $data: no OptiOdom data" >&2; exit 2; }
mkdir -p "$out/rec"
rec() {  # kind/shape/set: imports run 01 once, prints its recording directory
  local dest=$out/rec/$1
  [ -f "$dest/recording.yaml" ] ||
    "$roamlab" import optiodom "$data/$1/$(basename "$1")_run-01.csv" --out "$dest" --quiet
  echo "$dest"
}
diagnose() {  # day, robot (diff, omni3), training shape/set, held-out shape/set...
  local day=$1 robot=$2 set=${3#*/} dir=$out/$1_${3#*/} held=()
  local training=$3
  shift 3
  [[ -z "$only" || "$day" =~ $only ]] || return 0
  [ -f "$dir/twin.json" ] && return 0
  local train
  train=$(rec "$robot/$training")
  for h in "$@"; do held+=("$(rec "$robot/$h")"); done
  local config=$here/configs/real/optiodom_diff_nominal.yaml
  if [ "$robot" = omni3 ]; then
    config=$out/omni3_nominal.yaml
    [ -f "$config" ] || "$roamlab" init "$train" --out "$config" --quiet
  fi
  /usr/bin/time -f "%e s wall, %U s user + %S s system CPU" -o "$out/${day}_$set.time" \
    "$roamlab" diagnose --real "$train" --scenario "$here/scenarios/real/optiodom_$robot.yaml" --config "$config" \
    --no-baseline --replay --no-plots --quiet --out "$dir" --held-out "${held[@]}"
}
diagnose_set() {  # day, robot, max effects, "training shape/set ...", held-out shape/set...
  local day=$1 robot=$2 n=$3 dir=$out/$1_max$3 held=() with=()
  local -a training
  read -ra training <<<"$4"
  shift 4
  [[ -z "$only" || "$day" =~ $only ]] || return 0
  [ -f "$dir/twin.json" ] && return 0
  local first
  first=$(rec "$robot/${training[0]}")
  for t in "${training[@]:1}"; do with+=("$(rec "$robot/$t")"); done
  for h in "$@"; do held+=("$(rec "$robot/$h")"); done
  /usr/bin/time -f "%e s wall, %U s user + %S s system CPU" -o "$out/${day}_max$n.time" \
    "$roamlab" diagnose --real "$first" --train-with "${with[@]}" --max-effects "$n" \
    --scenario "$here/scenarios/real/optiodom_$robot.yaml" --config "$here/configs/real/optiodom_diff_nominal.yaml" \
    --no-baseline --replay --no-plots --quiet --out "$dir" --held-out "${held[@]}"
}
reap() { wait -n || echo "twin_optiodom.sh: a diagnosis failed (its output above)" >&2; }
run() {  # diagnose in the background, at most $jobs at a time
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do reap; done
  diagnose "$@" &
}
for square in 231220200029 231220200040 231220200045 231220200048; do
  run diff_dec diff "square/$square" circular/231220200121 circular/231220200134 ivanjko/231220200057
done
for square in 221220201934 221220201953; do
  run omni3 omni3 "square/$square" circular/221220201643 circular/221220201701
done
for square in 230620202042 230620202144 230620202258 230620202317; do
  run diff_jun diff "square/$square" circular/250620202104 ivanjko/250620201618
done
for circle in 250620202104 250620202236; do
  run diff_jun25 diff "circular/$circle" circular/250620202119 ivanjko/250620201618
done
for n in 2 3; do
  set_runs=(diffset_dec diff "$n" "square/231220200029 circular/231220200121 ivanjko/231220200057")
  for h in circular/2312202001{34,41,46,50,54,57} ivanjko/2312202001{02,04,07} square/2312202000{40,45,48}; do
    set_runs+=("$h")
  done
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do reap; done
  diagnose_set "${set_runs[@]}" &
done
square_set() {  # day, three training squares, held-out shape/set...
  local day=$1 training=$2
  shift 2
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do reap; done
  diagnose_set "$day" diff 3 "$training" "$@" &
}
square_set squareset_dec "square/231220200029 square/231220200040 square/231220200045" square/231220200048 \
  circular/2312202001{21,34,41,46,50,54,57} ivanjko/231220200057 ivanjko/2312202001{02,04,07}
square_set squareset_jun "square/230620202042 square/230620202144 square/230620202258" square/230620202317 \
  circular/2506202021{04,19} circular/2506202022{36,51} circular/2506202023{17,45} ivanjko/2506202016{18,36,55} \
  ivanjko/250620201738
while [ "$(jobs -rp | wc -l)" -gt 0 ]; do reap; done
python3 "$here/tools/twin_table.py" "$out"
for f in "$out"/*.time; do echo "$(basename "$f" .time): $(tail -1 "$f")"; done
