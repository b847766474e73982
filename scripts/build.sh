#!/usr/bin/env bash
# Configures and builds SPHERA (the patched COLMAP and our libraries) in
# build/ with ccache, so repeated builds are incremental.
#
# Environment: SPHERA_COLMAP_BASE (3.10 or 4), SPHERA_BUILD_DIR (default
# build, build-4 for base 4), SPHERA_JOBS (default nproc),
# SPHERA_CMAKE_ARGS (extra cmake arguments, e.g.
# -DSPHERA_COLMAP_TARBALL=/path/to/colmap_3.10.orig.tar.gz).
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
# SPHERA_COLMAP_BASE=4 builds on upstream COLMAP 4.x (into build-4/ unless
# SPHERA_BUILD_DIR says otherwise); the default base is COLMAP 3.10.
readonly COLMAP_BASE="${SPHERA_COLMAP_BASE:-3.10}"
if [ "${COLMAP_BASE}" = 4 ]; then
  readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build-4}"
else
  readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
fi
readonly JOBS="${SPHERA_JOBS:-$(nproc)}"

# ccache hits across clones in different directories.
export CCACHE_BASEDIR="${REPO_ROOT}"
export CCACHE_DIR="${CCACHE_DIR:-${HOME}/.cache/ccache}"
export CCACHE_NOHASHDIR=true
ccache --max-size=5G >/dev/null 2>&1 || true

# shellcheck disable=SC2086
cmake -S "${REPO_ROOT}" -B "${BUILD_DIR}" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DSPHERA_COLMAP_BASE="${COLMAP_BASE}" \
  ${SPHERA_CMAKE_ARGS:-} >/dev/null
ninja -C "${BUILD_DIR}" -j "${JOBS}" "$@"
