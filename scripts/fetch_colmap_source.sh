#!/usr/bin/env bash
# Obtains the COLMAP 3.10 upstream tarball from Debian's source registry and
# verifies its SHA-256. The registry host is derived from the machine's own
# apt sources, never written here.
#
# Usage: fetch_colmap_source.sh OUTPUT_TARBALL
set -euo pipefail

readonly EXPECTED_SHA256="61850f323e201ab6a1abbfb0e4a8b3ba1c4cedbf55e0a5716bdea1df8ae1813a"
readonly OUTPUT="${1:?usage: fetch_colmap_source.sh OUTPUT_TARBALL}"

sha_ok() { [ -f "$1" ] && echo "${EXPECTED_SHA256}  $1" | sha256sum --check --status; }

if sha_ok "${OUTPUT}"; then
  echo "COLMAP source: ${OUTPUT} (verified)"
  exit 0
fi

mkdir -p "$(dirname "${OUTPUT}")"
work_dir="$(mktemp -d)"
trap 'rm -rf "${work_dir}"' EXIT

# A deb-src entry for trixie, derived from the machine's own Debian sources.
sources_file=/etc/apt/sources.list.d/sphera-colmap-src.sources
if [ ! -f "${sources_file}" ]; then
  uris=""
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    uris="$(awk '/^URIs:/ && $2 !~ /security/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)"
  fi
  if [ -z "${uris}" ] && [ -f /etc/apt/sources.list ]; then
    uris="$(awk '$1 == "deb" && $0 !~ /security/ {for (i = 2; i <= NF; ++i) if ($i ~ /^[a-z]+:\/\//) {print $i; exit}}' /etc/apt/sources.list)"
  fi
  if [ -z "${uris}" ]; then
    echo "error: cannot derive a Debian mirror from the apt sources of this machine;" \
         "pass -DSPHERA_COLMAP_SOURCE=/path/to/colmap_3.10.orig.tar.gz instead" >&2
    exit 1
  fi
  cat > "${sources_file}" <<SRC
Types: deb-src
URIs: ${uris}
Suites: trixie
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
fi
apt-get update -qq -o Dir::Etc::sourcelist="${sources_file}" \
  -o Dir::Etc::sourceparts=- -o APT::Get::List-Cleanup=0 >/dev/null

# The .dsc is missing on the registry, so apt-get exits non-zero even when the
# orig tarball arrived: the checksum decides.
(cd "${work_dir}" && apt-get source --download-only colmap=3.10-2 >/dev/null 2>&1) || true
tarball="${work_dir}/colmap_3.10.orig.tar.gz"
if ! sha_ok "${tarball}"; then
  echo "error: could not obtain colmap_3.10.orig.tar.gz with SHA-256 ${EXPECTED_SHA256}" >&2
  exit 1
fi
mv "${tarball}" "${OUTPUT}"
echo "COLMAP source: ${OUTPUT} (downloaded, verified)"
