#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the main job end to end: a 30 s ATV drive with the seed's Table I calibration
# and Section V noise, offline self-calibration, online fixed-lag tracking. Output in out/main/ (OUT_DIR overrides).
# Until the MuJoCo simulator lands (issue 3) the drive comes from the kinematic generator in tests/support.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build_dir=${BUILD_DIR:-build}
out=${OUT_DIR:-out/main}
rm -rf "$out" && mkdir -p "$out"
"$build_dir/tests/support/make_synthetic_recording" "$out/recording" 30 1
"$build_dir/apps/roamlab" calibrate "$out/recording" --config scenarios/atv_calibration.yaml --out "$out/calibration"
"$build_dir/apps/roamlab" track "$out/recording" --config scenarios/atv_tracking.yaml \
  --calibration "$out/calibration/calibration.json" --out "$out/tracking"
echo "report: $out/calibration/calibration.json, $out/tracking/summary.json, $out/tracking/trajectory.tum"
echo "truth (for comparison only; the estimator never reads it): $out/recording/truth.yaml"
