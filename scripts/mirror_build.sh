#!/usr/bin/env bash
# Builds SPHERA as a clone found in the wild does, with local mirrors in the
# place of the public hosts: a fresh clone of this repository with nothing
# beside it and an empty source cache takes COLMAP by git at its commit and
# PoseLib and faiss as archives checked against their SHA-256, builds
# everything (ccache serves objects it has seen) and runs the unit tests and
# the demo with the program built from them.
#
# The mirrors are made from the tarballs in ../shared/peers (PEERS_DIR): a
# bare git repository of the COLMAP tarball's tree (a commit of its own,
# passed as SPHERA_COLMAP_GIT_COMMIT) and file:// URLs of the archives.
#
#   scripts/mirror_build.sh [WORK_DIR]     (default: a new temporary folder)
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly PEERS_DIR="${PEERS_DIR:-${REPO_ROOT}/../shared/peers}"
readonly WORK="${1:-$(mktemp -d /tmp/sphera_mirror_build.XXXXXX)}"

for tarball in colmap-5d968cf.tar.gz PoseLib-a69263d.tar.gz \
               faiss-1.14.1.tar.gz; do
  if [ ! -f "${PEERS_DIR}/${tarball}" ]; then
    echo "mirror_build.sh: ${PEERS_DIR}/${tarball} not found; the mirrors" \
         "are made from the tarballs of ../shared/peers" >&2
    exit 1
  fi
done
sha() { sha256sum "$1" | cut -d' ' -f1; }
git_q() {
  git -c user.name=sphera -c user.email=sphera@localhost "$@" >/dev/null
}

start=$(date +%s)
mkdir -p "${WORK}/mirror"
tar -xzf "${PEERS_DIR}/colmap-5d968cf.tar.gz" -C "${WORK}/mirror"
git_q -C "${WORK}/mirror/colmap-5d968cf" init --quiet
git_q -C "${WORK}/mirror/colmap-5d968cf" add --force --all
git_q -C "${WORK}/mirror/colmap-5d968cf" commit --quiet -m "COLMAP 5d968cf"
commit=$(git -C "${WORK}/mirror/colmap-5d968cf" rev-parse HEAD)
git_q clone --quiet --bare "${WORK}/mirror/colmap-5d968cf" \
  "${WORK}/mirror/colmap.git"
rm -rf "${WORK}/mirror/colmap-5d968cf"

# A clone with nothing beside it: no ../shared, an empty source cache.
git_q clone --quiet "${REPO_ROOT}" "${WORK}/clone/sphera"
export SPHERA_CMAKE_ARGS="-DSPHERA_PEERS_DIR= \
 -DSPHERA_CACHE_DIR=${WORK}/cache \
 -DSPHERA_COLMAP_GIT_URL=file://${WORK}/mirror/colmap.git \
 -DSPHERA_COLMAP_GIT_COMMIT=${commit} \
 -DSPHERA_POSELIB_URL=file://${PEERS_DIR}/PoseLib-a69263d.tar.gz \
 -DSPHERA_POSELIB_URL_SHA256=$(sha "${PEERS_DIR}/PoseLib-a69263d.tar.gz") \
 -DSPHERA_FAISS_URL=file://${PEERS_DIR}/faiss-1.14.1.tar.gz \
 -DSPHERA_FAISS_URL_SHA256=$(sha "${PEERS_DIR}/faiss-1.14.1.tar.gz")"
echo "mirror_build.sh: building a clone in ${WORK}/clone/sphera from the" \
     "mirrors (COLMAP commit ${commit})"
"${WORK}/clone/sphera/scripts/build.sh" > "${WORK}/build.log" 2>&1 || {
  tail -30 "${WORK}/build.log"; exit 1; }
grep -q "source=git ${commit}" "${WORK}/clone/sphera/build/colmap-src.stamp"
built=$(date +%s)
echo "mirror_build.sh: built from the mirrors in $((built - start)) s" \
     "(log ${WORK}/build.log)"
(cd "${WORK}/clone/sphera/build" &&
   ctest --output-on-failure -j "$(nproc)" -L unit &&
   ctest --output-on-failure -R '^cli\.demo$')
echo "mirror_build.sh: tests passed in $(( $(date +%s) - built )) s"
