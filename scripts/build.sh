#!/usr/bin/env bash
# Configures and builds SPHERA (the patched COLMAP and our libraries) in
# build/ with ccache, so repeated builds are incremental.
#
# Environment: SPHERA_BUILD_DIR (default build), SPHERA_JOBS (default nproc),
# SPHERA_CMAKE_ARGS (extra cmake arguments, e.g.
# -DSPHERA_COLMAP4_TARBALL=/path/to/colmap-5d968cf.tar.gz).
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
readonly JOBS="${SPHERA_JOBS:-$(nproc)}"

# ccache hits across clones in different directories.
export CCACHE_BASEDIR="${REPO_ROOT}"
export CCACHE_DIR="${CCACHE_DIR:-${HOME}/.cache/ccache}"
export CCACHE_NOHASHDIR=true
ccache --max-size=5G >/dev/null 2>&1 || true

# shellcheck disable=SC2086
cmake -S "${REPO_ROOT}" -B "${BUILD_DIR}" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release ${SPHERA_CMAKE_ARGS:-} >/dev/null
ninja -C "${BUILD_DIR}" -j "${JOBS}" "$@"
