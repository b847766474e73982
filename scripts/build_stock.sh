#!/usr/bin/env bash
# Builds unpatched COLMAP 3.10 (same source, same compiler flags, no SPHERA
# code) into build-stock/, the baseline of the benchmarks:
# build-stock/bin/colmap.
set -euo pipefail
readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
SPHERA_BUILD_DIR="${SPHERA_STOCK_BUILD_DIR:-${REPO_ROOT}/build-stock}" \
SPHERA_CMAKE_ARGS="-DSPHERA_STOCK_COLMAP=ON ${SPHERA_CMAKE_ARGS:-}" \
  exec "${REPO_ROOT}/scripts/build.sh" sphera_colmap "$@"
