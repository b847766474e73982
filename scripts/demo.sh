#!/usr/bin/env bash
# The main job: a reconstruction with the `colmap` command line.
#
#   scripts/demo.sh                      render the default scene (the SPHERA
#                                        paper's room seen by 9 equirectangular
#                                        cameras) and reconstruct it
#   scripts/demo.sh IMAGE_DIR [MODEL]    reconstruct your own images; MODEL is a
#                                        camera model name (default
#                                        EQUIRECTANGULAR)
#
# Output goes to SPHERA_DEMO_DIR (default build/demo): database.db, sparse/,
# and for the default scene the rendered images and the ground truth.
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
readonly WORK_DIR="${SPHERA_DEMO_DIR:-${BUILD_DIR}/demo}"
readonly COLMAP="${BUILD_DIR}/bin/colmap"
readonly RENDER="${BUILD_DIR}/synthetic/sphera_render"

image_dir="${1:-}"
camera_model="${2:-EQUIRECTANGULAR}"
if [ -n "${image_dir}" ] && [ ! -d "${image_dir}" ]; then
  echo "demo: image directory '${image_dir}' does not exist" >&2
  exit 1
fi

"${REPO_ROOT}/scripts/setup.sh"
"${REPO_ROOT}/scripts/build.sh"

# Only a folder this script made (it leaves a marker) is ever replaced.
if [ -d "${WORK_DIR}" ] && [ -n "$(ls -A "${WORK_DIR}")" ] \
    && [ ! -f "${WORK_DIR}/.sphera-demo" ]; then
  echo "demo: ${WORK_DIR} exists and was not made by this script; set" \
       "SPHERA_DEMO_DIR to a new folder" >&2
  exit 1
fi
rm -rf "${WORK_DIR}"
mkdir -p "${WORK_DIR}"
touch "${WORK_DIR}/.sphera-demo"
if [ -z "${image_dir}" ]; then
  echo "demo: rendering the default scene into ${WORK_DIR}/scene"
  "${RENDER}" --output "${WORK_DIR}/scene" --layout room9 \
    --model EQUIRECTANGULAR --width 2048 --height 1024 --seed 1 --supersample 2
  image_dir="${WORK_DIR}/scene/images"
fi

database="${WORK_DIR}/database.db"
start=$(date +%s)
"${COLMAP}" feature_extractor --database_path "${database}" \
  --image_path "${image_dir}" --ImageReader.camera_model "${camera_model}" \
  --ImageReader.single_camera_per_folder 1 --FeatureExtraction.use_gpu 0
"${COLMAP}" exhaustive_matcher --database_path "${database}" \
  --FeatureMatching.use_gpu 0
mkdir -p "${WORK_DIR}/sparse"
"${COLMAP}" mapper --database_path "${database}" --image_path "${image_dir}" \
  --output_path "${WORK_DIR}/sparse"
elapsed=$(( $(date +%s) - start ))

echo
echo "=== SPHERA demo summary (${elapsed} s) ==="
echo "images:          $(sqlite3 "${database}" 'SELECT COUNT(*) FROM images')"
echo "keypoints:       $(sqlite3 "${database}" 'SELECT SUM(rows) FROM keypoints')"
echo "verified pairs:  $(sqlite3 "${database}" 'SELECT COUNT(*) FROM two_view_geometries WHERE rows > 0')"
if [ -d "${WORK_DIR}/scene/sparse_gt" ] && [ -d "${WORK_DIR}/sparse/0" ]; then
  echo "--- against the ground truth (colmap model_evaluator) ---"
  mkdir -p "${WORK_DIR}/evaluation"
  "${COLMAP}" model_evaluator --gt_path "${WORK_DIR}/scene/sparse_gt" \
    --input_path "${WORK_DIR}/sparse/0" --depth_path "${WORK_DIR}/scene/depth" \
    --output_path "${WORK_DIR}/evaluation" 2>/dev/null | tail -n 7
fi
for model in "${WORK_DIR}"/sparse/*/; do
  [ -d "${model}" ] || continue
  "${COLMAP}" model_analyzer --path "${model}" 2>&1 \
    | grep -E "Cameras|Registered images|Points|Mean reprojection error" \
    | sed "s|^.*\] ||; s|^|$(basename "${model}"): |"
done
