#!/usr/bin/env bash
# Installs what is missing, builds everything and runs all tests (unit tests
# of camera_models/, estimators/, synthetic/, colmap_ext/ and the integration
# tests that drive the built colmap program). Tests that need ../shared/data
# say so and are reported as skipped when it is absent.
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
start=$(date +%s)

"${REPO_ROOT}/scripts/setup.sh"
SPHERA_BUILD_DIR="${BUILD_DIR}" "${REPO_ROOT}/scripts/build.sh"
echo "test.sh: build ready after $(( $(date +%s) - start )) s"

cd "${BUILD_DIR}"
# As many tests at once as there are cores: the long integration tests
# (about 13 minutes each) then run side by side.
ctest --output-on-failure --timeout 3000 -j "$(nproc)" "$@"
echo "test.sh: finished after $(( $(date +%s) - start )) s"
