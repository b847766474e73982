#!/usr/bin/env bash
# Installs what is missing, builds everything and runs all tests (unit tests
# of camera_models/, estimators/, synthetic/, colmap_ext/ and the integration
# tests that drive the built colmap program). Tests that need ../shared/data
# say so and are reported as skipped when it is absent.
#
#   scripts/test.sh              every test (what CI runs)
#   scripts/test.sh --quick      the fast loop: every test but those labelled
#                                slow (unit tests and the fast CLI tests)
#   scripts/test.sh ARGS...      extra ctest arguments, e.g. -L unit, -R rig
set -euo pipefail

ctest_args=()
if [ "${1:-}" = "--quick" ]; then
  shift
  ctest_args+=(--label-exclude slow)
fi

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
start=$(date +%s)

"${REPO_ROOT}/scripts/setup.sh"
SPHERA_BUILD_DIR="${BUILD_DIR}" "${REPO_ROOT}/scripts/build.sh"
echo "test.sh: build ready after $(( $(date +%s) - start )) s"

cd "${BUILD_DIR}"
# As many tests at once as there are cores. Each test's COST (its measured
# seconds, tests/CMakeLists.txt) makes ctest start the longest ones first, so
# that the short tests fill the other core instead of waiting at the end.
ctest --output-on-failure --timeout 3000 -j "$(nproc)" ${ctest_args[@]+"${ctest_args[@]}"} "$@"
echo "test.sh: finished after $(( $(date +%s) - start )) s"
