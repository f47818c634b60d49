#!/bin/sh
# Dead reckoning of a differential-drive robot from its wheel encoders: an estimator that is not roamlab's, written
# for roamlab's testbed of external estimators (docs/external-estimator.md). POSIX sh and awk only (mawk does).
#
#   dead_reckoning.sh RECORDING_DIR OUT_DIR
#
# Reads the recording's files directly (never the truth): recording.yaml (platform.kind differential_drive,
# platform.geometry wheel_radius_m and baseline_m, the streams), the wheel_encoders stream (cumulative wheel angles in
# rad, columns left and right) and the first row of the first pose stream (motion capture), the only absolute
# information it uses: the start pose. Without a pose stream it starts at the world origin with heading 0 and writes
# no covariance (its frame is then its own: the evaluation aligns it to the truth, and a NEES would mean nothing).
#
# From there it integrates the wheels (midpoint heading), on a flat floor (z and roll and pitch stay those of the
# start), and propagates the covariance of (x, y, yaw) with each wheel's travel error of variance
# DR_WHEEL_SIGMA^2 * |travel| (a random walk per metre rolled; default DR_WHEEL_SIGMA 0.01 m per sqrt(m)), from the
# pose stream's stated noise (noise: position_m, orientation_rad) at the start. Writes
#   OUT/trajectory.tum   one pose per encoder row from the start pose's stamp on, at the encoder row's stamp
#   OUT/covariance.csv   the 3x3 world-frame position covariance of each pose [m^2]; z keeps the start's variance
# Exit status 2 with one line on standard error when the recording is not one it can use.
set -eu
if [ $# -ne 2 ]; then
  echo "usage: dead_reckoning.sh RECORDING_DIR OUT_DIR" >&2
  exit 2
fi
rec=$1
out=$2
wheel_sigma=${DR_WHEEL_SIGMA:-0.01}
mkdir -p "$out"
exec awk -v rec="$rec" -v out="$out" -v wheel_sigma="$wheel_sigma" '
function fail(message) { print "dead_reckoning: " message > "/dev/stderr"; failed = 1; exit 2 }
# The number after "key:" in a YAML line ("" when absent).
function value_of(line, key,    rest) {
  if (!match(line, "(^|[ {,])" key ":[ ]*")) return ""
  rest = substr(line, RSTART + RLENGTH)
  if (!match(rest, "^[-+0-9.eE]+")) return ""
  return substr(rest, RSTART, RLENGTH)
}
# The stream entries of recording.yaml: name, type, units, columns and noise line of each.
function read_recording(path,    line, current, n) {
  n = 0
  while ((getline line < path) > 0) {
    if (line ~ /^  kind:/) { kind = line; sub(/^  kind:[ ]*/, "", kind) }
    if (line ~ /^  geometry:/) { radius = value_of(line, "wheel_radius_m"); baseline = value_of(line, "baseline_m") }
    if (line ~ /^  - name:/) { current = line; sub(/^  - name:[ ]*/, "", current); names[++n] = current }
    if (line ~ /^    type:/) { stream_type[current] = line; sub(/^    type:[ ]*/, "", stream_type[current]) }
    if (line ~ /^    units:/) { stream_units[current] = line; sub(/^    units:[ ]*/, "", stream_units[current]) }
    if (line ~ /^    noise:/) stream_noise[current] = line
  }
  close(path)
  return n
}
# The index of each column of a CSV header line in column[name].
function read_header(line,    fields, k, n) {
  n = split(line, fields, ",")
  for (k = 1; k <= n; ++k) column[fields[k]] = k
}
function write_pose(t,    half) {
  half = yaw / 2
  printf "%s %.17g %.17g %.17g 0 0 %.17g %.17g\n", t, x, y, z, sin(half), cos(half) > trajectory
  if (start_t != "") printf "%s,%.17g,%.17g,0,%.17g,%.17g,0,0,0,%.17g\n", t, pxx, pxy, pxy, pyy, var_z > covariance
}
# One step with wheel travels dl and dr [m]: the pose (midpoint heading) and the covariance, P = F P F^T + G Q G^T.
function step(dl, dr,    ds, dyaw, mid, c, s, fx, fy, gxl, gxr, gyl, gyr, gt, ql, qr, nxx, nxy, nxt, nyy, nyt) {
  ds = (dl + dr) / 2
  dyaw = (dr - dl) / baseline
  mid = yaw + dyaw / 2
  c = cos(mid); s = sin(mid)
  # F = [1 0 fx; 0 1 fy; 0 0 1]
  fx = -ds * s; fy = ds * c
  nxx = pxx + 2 * fx * pxt + fx * fx * ptt
  nxy = pxy + fx * pyt + fy * pxt + fx * fy * ptt
  nyy = pyy + 2 * fy * pyt + fy * fy * ptt
  nxt = pxt + fx * ptt
  nyt = pyt + fy * ptt
  # G = d(x, y, yaw)/d(dl, dr), Q = diag(ql, qr)
  gxl = c / 2 + ds * s / (2 * baseline); gxr = c / 2 - ds * s / (2 * baseline)
  gyl = s / 2 - ds * c / (2 * baseline); gyr = s / 2 + ds * c / (2 * baseline)
  gt = 1 / baseline
  ql = wheel_sigma * wheel_sigma * (dl < 0 ? -dl : dl)
  qr = wheel_sigma * wheel_sigma * (dr < 0 ? -dr : dr)
  pxx = nxx + gxl * gxl * ql + gxr * gxr * qr
  pxy = nxy + gxl * gyl * ql + gxr * gyr * qr
  pyy = nyy + gyl * gyl * ql + gyr * gyr * qr
  pxt = nxt - gxl * gt * ql + gxr * gt * qr
  pyt = nyt - gyl * gt * ql + gyr * gt * qr
  ptt = ptt + gt * gt * (ql + qr)
  x += ds * c; y += ds * s; yaw += dyaw
}
# The start: the first row of the first pose stream, with its stated noise; else the origin, exactly.
function read_start(    k, name, path, line, f, qx, qy, qz, qw, sp, so) {
  x = 0; y = 0; z = 0; yaw = 0; start_t = ""
  pxx = pxy = pyy = pxt = pyt = ptt = var_z = 0
  for (k = 1; k <= stream_count; ++k) if (stream_type[names[k]] == "pose") { name = names[k]; break }
  if (name == "") return
  path = rec "/" name ".csv"
  if ((getline line < path) <= 0 || (getline line < path) <= 0) fail(path ": no rows")
  close(path)
  split(line, f, ",")
  start_t = f[1] + 0; x = f[2] + 0; y = f[3] + 0; z = f[4] + 0
  qx = f[5] + 0; qy = f[6] + 0; qz = f[7] + 0; qw = f[8] + 0
  yaw = atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
  sp = value_of(stream_noise[name], "position_m") + 0
  so = value_of(stream_noise[name], "orientation_rad") + 0
  pxx = pyy = var_z = sp * sp
  ptt = so * so
}
BEGIN {
  trajectory = out "/trajectory.tum"
  covariance = out "/covariance.csv"
  stream_count = read_recording(rec "/recording.yaml")
  if (stream_count == 0) fail(rec "/recording.yaml: no streams (or no such file)")
  if (kind != "differential_drive") fail(rec "/recording.yaml: platform kind \"" kind "\" is not differential_drive")
  if (radius == "" || baseline == "" || baseline + 0 <= 0)
    fail(rec "/recording.yaml: platform.geometry needs wheel_radius_m and baseline_m")
  radius += 0; baseline += 0
  for (k = 1; k <= stream_count; ++k) if (stream_type[names[k]] == "wheel_encoders") { encoders = names[k]; break }
  if (encoders == "") fail(rec "/recording.yaml: no wheel_encoders stream")
  if (stream_units[encoders] != "" && stream_units[encoders] != "rad")
    fail(rec "/recording.yaml: stream " encoders " in " stream_units[encoders] " (only rad is read)")
  read_start()
  path = rec "/" encoders ".csv"
  if ((getline line < path) <= 0) fail(path ": empty")
  read_header(line)
  if (!("left" in column) || !("right" in column)) fail(path ": no columns left and right")
  print "# t x y z qx qy qz qw" > trajectory
  if (start_t != "") print "t,xx,xy,xz,yx,yy,yz,zx,zy,zz" > covariance
  started = 0
  while ((getline line < path) > 0) {
    split(line, f, ",")
    left = f[column["left"]] * radius; right = f[column["right"]] * radius
    if (start_t != "" && f[1] + 0 < start_t) { last_left = left; last_right = right; have_last = 1; continue }
    if (started && have_last) step(left - last_left, right - last_right)
    last_left = left; last_right = right; have_last = 1
    write_pose(f[1])
    started = 1
  }
  if (!started) fail(path ": no encoder row at or after the start pose")
}
END { if (failed) exit 2 }
'
