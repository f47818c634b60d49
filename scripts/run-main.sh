#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the main job end to end: the ATV on MuJoCo hills (scenarios/atv_hills.yaml, the
# seed's Section V: Table I calibration, Section V noise), offline self-calibration, online fixed-lag tracking with the
# calibrated values, and evaluation against the truth. Output in out/main/ (OUT_DIR overrides).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
roamlab=${BUILD_DIR:-build}/apps/roamlab
out=${OUT_DIR:-out/main}
rm -rf "$out" && mkdir -p "$out"
"$roamlab" simulate scenarios/atv_hills.yaml --out "$out/recording"
"$roamlab" calibrate "$out/recording" --config configs/atv_calibration.yaml --out "$out/calibration"
"$roamlab" track "$out/recording" --config configs/atv_tracking.yaml \
  --calibration "$out/calibration/calibration.json" --out "$out/tracking"
"$roamlab" evaluate --estimate "$out/calibration" --estimate "$out/tracking" --recording "$out/recording" \
  --out "$out/report"
echo "report: $out/report/report.html (headline numbers, the calibration's parameter table, ATE, RPE, NEES and the"
echo "        figures, all in one page); metrics.json and each estimate's own evaluation in $out/report/{calibration,tracking}"
