#!/usr/bin/env bash
# Installs every Debian package roamlab needs (idempotent; as root or through sudo), then configures and builds it in
# Release into build/. Environment: BUILD_DIR (default build), JOBS (default: number of cores), CI=true turns
# compiler warnings into errors.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libsuitesparse-dev libgeographiclib-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libmujoco-dev libqhull-dev libgl-dev libopengl-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
  libopencv-dev libgtest-dev libgmock-dev gnuplot-nox libceres-dev libbz2-dev
  libsqlite3-dev libzstd-dev liblz4-dev clang libclang-rt-dev
  slurm-wlm munge
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  echo "roamlab setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build_dir=${BUILD_DIR:-build}
werror=OFF
[ "${CI:-}" = "true" ] && werror=ON
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DROAMLAB_WERROR=$werror >/dev/null
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}"
