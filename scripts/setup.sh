#!/usr/bin/env bash
# Installs the Debian packages SPHERA builds and runs with (Debian bookworm,
# as root or with sudo). Installs only what is missing, so it is cheap to
# call before every build.
set -euo pipefail

readonly PACKAGES=(
  # toolchain
  build-essential cmake ninja-build ccache git patch ca-certificates
  dpkg-dev xz-utils
  # COLMAP
  libeigen3-dev libgoogle-glog-dev libgflags-dev libceres-dev libflann-dev
  libfreeimage-dev libmetis-dev libsqlite3-dev libboost-program-options-dev
  libboost-filesystem-dev libboost-graph-dev libboost-system-dev
  libsuitesparse-dev libgtest-dev libgl-dev
  # more of COLMAP: image I/O (OpenImageIO), OpenMP, BLAS/LAPACK;
  # OpenImageIO's CMake files need the tools and Imath's Python package
  libopenimageio-dev openimageio-tools python3-imath libcurl4-openssl-dev
  libomp-dev libblas-dev liblapack-dev
  # SPHERA: image remapping; calibration files (OpenCV FileStorage, Kalibr
  # YAML, Basalt JSON)
  libopencv-dev libyaml-cpp-dev nlohmann-json3-dev
  # tests, benchmarks and plots
  python3 python3-numpy python3-scipy python3-matplotlib sqlite3
  # fuzz targets: libFuzzer, AddressSanitizer, UBSan (scripts/fuzz.sh)
  clang libclang-rt-14-dev
)

missing=()
for package in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "${package}" 2>/dev/null \
      | grep -q "install ok installed"; then
    missing+=("${package}")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi
echo "setup: installing ${missing[*]}"
${SUDO} apt-get update -qq
DEBIAN_FRONTEND=noninteractive ${SUDO} apt-get install -y -qq \
  "${missing[@]}" >/dev/null
echo "setup: done"
