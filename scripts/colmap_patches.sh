#!/usr/bin/env bash
# Developer tool for the COLMAP patch series in colmap_ext/patches/.
#
#   colmap_patches.sh checkout DIR   pristine COLMAP in DIR as a git
#                                    repository, one commit per patch applied
#   colmap_patches.sh export DIR     rewrite the patch series from the
#                                    commits in DIR after the pristine one
#
# The pristine source is upstream COLMAP 4.x at commit 5d968cf: the tarball
# colmap-5d968cf.tar.gz from SPHERA_PEERS_DIR (default ../shared/peers), else
# from ~/.cache/sphera, or the file SPHERA_COLMAP4_TARBALL names.
#
# Build against the checkout with
#   cmake -B build -DSPHERA_COLMAP_EDITABLE_DIR=DIR
# and edit it with ordinary git (commit --fixup, rebase -i, one commit per
# topic); never edit .patch files by hand.
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly PATCH_DIR="${REPO_ROOT}/colmap_ext/patches"
readonly COLMAP_SHA256="1c6c1a735774d8bc442900d52aac5359dcc9c7ffe53d3daba054fa3095de8dc1"
peers="${SPHERA_PEERS_DIR:-${REPO_ROOT}/../shared/peers}"
TARBALL="${SPHERA_COLMAP4_TARBALL:-${peers}/colmap-5d968cf.tar.gz}"
[ -f "${TARBALL}" ] || TARBALL="${HOME}/.cache/sphera/colmap-5d968cf.tar.gz"
readonly TARBALL
# The name checkouts have carried since the 4.x port, so that older ones
# still export.
readonly PRISTINE_TAG="pristine-4"

git_in() { git -C "$1" -c user.name=sphera -c user.email=sphera@localhost "${@:2}"; }

command="${1:-}"
dir="${2:-}"
if [ -z "${command}" ] || [ -z "${dir}" ]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi

case "${command}" in
  checkout)
    if [ -e "${dir}" ]; then
      echo "error: ${dir} already exists" >&2
      exit 1
    fi
    echo "${COLMAP_SHA256}  ${TARBALL}" | sha256sum --check --status || {
      echo "error: ${TARBALL} is missing or does not have SHA-256 ${COLMAP_SHA256}" >&2
      exit 1
    }
    mkdir -p "${dir}"
    tar -xzf "${TARBALL}" -C "${dir}" --strip-components=1
    git_in "${dir}" init -q
    git_in "${dir}" add -A
    git_in "${dir}" commit -q -m "COLMAP 5d968cf (pristine)"
    git_in "${dir}" tag "${PRISTINE_TAG}"
    for patch in "${PATCH_DIR}"/*.patch; do
      [ -e "${patch}" ] || continue
      git_in "${dir}" am -q --whitespace=nowarn "${patch}"
    done
    echo "editable COLMAP checkout: ${dir}"
    ;;
  export)
    git_in "${dir}" rev-parse -q --verify "${PRISTINE_TAG}" >/dev/null || {
      echo "error: ${dir} is not a checkout made by '$0 checkout'" >&2
      exit 1
    }
    if [ -n "$(git_in "${dir}" status --porcelain)" ]; then
      echo "error: ${dir} has uncommitted changes; commit them first" >&2
      exit 1
    fi
    rm -f "${PATCH_DIR}"/*.patch
    mkdir -p "${PATCH_DIR}"
    git_in "${dir}" format-patch -q --no-signature --zero-commit \
      --no-numbered -o "${PATCH_DIR}" "${PRISTINE_TAG}..HEAD"
    ls "${PATCH_DIR}"
    ;;
  *)
    echo "error: unknown command '${command}'" >&2
    exit 2
    ;;
esac
