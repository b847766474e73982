#!/usr/bin/env bash
# The main job: a reconstruction with the `colmap` command line.
#
#   scripts/demo.sh                      render the default scene (the SPHERA
#                                        paper's room seen by 9 equirectangular
#                                        cameras) and reconstruct it
#   scripts/demo.sh IMAGE_DIR [MODEL]    reconstruct your own images; MODEL is a
#                                        camera model name (default
#                                        EQUIRECTANGULAR); the images of a
#                                        scene rendered by sphera_render
#                                        (SCENE/images) are evaluated against
#                                        its ground truth (SCENE/sparse_gt)
#   scripts/demo.sh --camera NAME DIR [MODEL]
#                                        a 360° camera's own files to a rig
#                                        model (colmap rig_preset --camera
#                                        list names the cameras; MODEL: the
#                                        lenses' starting model, default the
#                                        preset's, e.g. OPENCV_FISHEYE for
#                                        lenses of Kannala-Brandt
#                                        calibrations): the frames
#                                        split into lens images and masks
#                                        (both lenses in one frame, or FR/ and
#                                        BK/ folders), or the lens files cut
#                                        to their circles with their masks
#                                        (one file per lens); the
#                                        preset's rig config; matching, the
#                                        lens directions checked against the
#                                        images (colmap rig_check), mapping
#                                        (when the images split, once more
#                                        with the lenses' intrinsics held,
#                                        into sparse_held/, kept if its
#                                        largest model holds more images)
#                                        and the rig's calibration, with a
#                                        line for a lens whose axis the
#                                        mapper and rig_check put more than
#                                        2 degrees apart
#
# It prints one line per stage with its counts (images extracted, pairs
# verified, images registered), a progress line while a stage runs on a
# terminal, and a summary; the output of every command (setup, build,
# COLMAP) goes to the log file it names, demo.log in the output folder.
# RANSAC and the mapper draw from SPHERA_DEMO_SEED (default 0), so that
# runs on the same images draw the same samples (matching on several
# threads can still differ by a verified match); another seed is another
# draw. SPHERA_DEMO_FLAT_FIELD=1 has the splitter divide out each lens's
# light fall-off towards the rim (dual_fisheye_splitter --flat_field 1).
# Output goes to SPHERA_DEMO_DIR (default build/demo): database.db,
# sparse/, demo.log, and for the default scene the rendered images and the
# ground truth.
#
# From a clone it installs the packages and builds first (scripts/setup.sh,
# scripts/build.sh). SPHERA_COLMAP and SPHERA_RENDER name the programs to run
# instead, without setup and build. Installed (as sphera_demo beside colmap
# and sphera_render) it runs those, and writes to ./sphera_demo by default.
set -euo pipefail

readonly SCRIPT_DIR="$(cd "$(dirname "$0")" && pwd)"
if [ -x "${SCRIPT_DIR}/colmap" ] && [ ! -f "${SCRIPT_DIR}/build.sh" ]; then
  readonly INSTALLED=1
  readonly WORK_DIR="${SPHERA_DEMO_DIR:-${PWD}/sphera_demo}"
  readonly COLMAP="${SPHERA_COLMAP:-${SCRIPT_DIR}/colmap}"
  readonly RENDER="${SPHERA_RENDER:-${SCRIPT_DIR}/sphera_render}"
else
  readonly INSTALLED=0
  readonly REPO_ROOT="$(cd "${SCRIPT_DIR}/.." && pwd)"
  readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
  readonly WORK_DIR="${SPHERA_DEMO_DIR:-${BUILD_DIR}/demo}"
  readonly COLMAP="${SPHERA_COLMAP:-${BUILD_DIR}/bin/colmap}"
  readonly RENDER="${SPHERA_RENDER:-${BUILD_DIR}/synthetic/sphera_render}"
fi
readonly LOG="${WORK_DIR}/demo.log"
readonly SEED="${SPHERA_DEMO_SEED:-0}"
readonly FLAT_FIELD="${SPHERA_DEMO_FLAT_FIELD:-0}"

camera=""
lens_model=""
if [ "${1:-}" = "--camera" ]; then
  if [ $# -ne 3 ] && [ $# -ne 4 ]; then
    echo "demo: usage: scripts/demo.sh --camera NAME DIR [MODEL]" >&2
    exit 1
  fi
  camera="$2"
  lens_model="${4:-}"
  shift 2
fi
image_dir="${1:-}"
camera_model="${2:-EQUIRECTANGULAR}"
if [ -n "${image_dir}" ] && [ ! -d "${image_dir}" ]; then
  echo "demo: image directory '${image_dir}' does not exist" >&2
  exit 1
fi
if [ -n "${image_dir}" ]; then
  image_dir="$(cd "${image_dir}" && pwd)"
fi

# Only a folder this script made (it leaves a marker) is ever replaced.
if [ -d "${WORK_DIR}" ] && [ -n "$(ls -A "${WORK_DIR}")" ] \
    && [ ! -f "${WORK_DIR}/.sphera-demo" ]; then
  echo "demo: ${WORK_DIR} exists and was not made by this script; set" \
       "SPHERA_DEMO_DIR to a new folder" >&2
  exit 1
fi
case "${image_dir}/" in
  "${WORK_DIR}"/*)
    echo "demo: the images must lie outside ${WORK_DIR}, which the demo" \
         "replaces" >&2
    exit 1 ;;
esac
rm -rf "${WORK_DIR}"
mkdir -p "${WORK_DIR}"
touch "${WORK_DIR}/.sphera-demo"
: > "${LOG}"
echo "demo: the output of every command goes to ${LOG}"

stage_pid=""
trap '[ -z "${stage_pid}" ] || kill "${stage_pid}" 2>/dev/null' EXIT

# run_stage LABEL PROGRESS_SED COMMAND...: runs COMMAND with its output
# appended to the log. On a terminal, one line shows the stage's progress
# meanwhile: the last log line that the sed expression PROGRESS_SED turns
# into text. Sets stage_seconds; on failure shows the end of the log and
# exits with the command's code.
run_stage() {
  local label="$1" progress_sed="$2"
  shift 2
  local start status=0 progress
  start=$(date +%s)
  printf '\n=== %s: %s\n' "${label}" "$*" >> "${LOG}"
  "$@" >> "${LOG}" 2>&1 &
  stage_pid=$!
  if [ -t 1 ]; then
    while kill -0 "${stage_pid}" 2>/dev/null; do
      progress="$(tail -n 200 "${LOG}" | sed -n "${progress_sed}" | tail -n 1)"
      printf '\r\033[K  %s %s (%d s)' "${label}" "${progress}" \
        "$(( $(date +%s) - start ))"
      sleep 1
    done
    printf '\r\033[K'
  fi
  wait "${stage_pid}" || status=$?
  stage_pid=""
  stage_seconds=$(( $(date +%s) - start ))
  if [ "${status}" -ne 0 ]; then
    echo "demo: ${label} failed (exit ${status}); the end of ${LOG}:" >&2
    tail -n 15 "${LOG}" >&2
    exit "${status}"
  fi
}

sql() {
  sqlite3 "${database}" "$1"
}

if [ "${INSTALLED}" -eq 0 ] && [ -z "${SPHERA_COLMAP:-}" ]; then
  "${REPO_ROOT}/scripts/setup.sh"
  run_stage "build" 's/^\(\[[0-9]*\/[0-9]*\]\).*/\1/p' \
    env SPHERA_BUILD_DIR="${BUILD_DIR}" "${REPO_ROOT}/scripts/build.sh"
  echo "build:              ${BUILD_DIR} ready (${stage_seconds} s)"
fi
for program in "${COLMAP}" "${RENDER}"; do
  if [ ! -x "${program}" ]; then
    echo "demo: ${program} is not an executable program" >&2
    exit 1
  fi
done

if [ -z "${image_dir}" ]; then
  run_stage "rendering" 's/^\[\([0-9]*\/[0-9]*\)\].*/\1 images/p' \
    "${RENDER}" --output "${WORK_DIR}/scene" --layout room9 \
    --model EQUIRECTANGULAR --width 2048 --height 1024 --seed 1 --supersample 2
  image_dir="${WORK_DIR}/scene/images"
  echo "rendering:          the default scene, $(find "${image_dir}" -type f \
    | wc -l) panoramas 2048x1024 (${stage_seconds} s)"
fi

database="${WORK_DIR}/database.db"
start=$(date +%s)
# A camera preset: the rig config, and the lens images and masks split from
# the camera's frames where it stores both lenses in one frame or folder.
rig_config=""
mask_args=()
if [ -n "${camera}" ]; then
  model_args=()
  [ -z "${lens_model}" ] || model_args=(--camera_model "${lens_model}")
  # How the camera stores its lenses, from its line in the preset list.
  preset_line="$("${COLMAP}" rig_preset --camera list 2>/dev/null \
    | grep "^${camera}: " || true)"
  case "${preset_line}" in
    "") run_stage "camera preset" 's/^$//p' "${COLMAP}" rig_preset \
          --camera "${camera}" --output_path "${WORK_DIR}/rig_config.json"
        exit 1 ;;
    *"stitched in the camera"*) preset_kind=stitched ;;
    # Both lenses in one frame, a folder per lens, or a file per lens: the
    # splitter writes the lens images, their masks and the rig config.
    *) preset_kind=frames ;;
  esac
  case "${preset_kind}" in
    stitched)
      # A lens model for stitched panoramas: rig_preset names the mistake.
      [ -z "${lens_model}" ] || run_stage "camera preset" 's/^$//p' \
        "${COLMAP}" rig_preset --camera "${camera}" "${model_args[@]}" \
        --output_path "${WORK_DIR}/preset_rig_config.json"
      camera_model=EQUIRECTANGULAR
      echo "camera preset:      ${camera}: stitched panoramas, one camera" ;;
    frames)
      if [ -d "${image_dir}/FR" ] && [ -d "${image_dir}/BK" ]; then
        inputs=(--front_path "${image_dir}/FR" --back_path "${image_dir}/BK")
      else
        inputs=(--input_path "${image_dir}")
      fi
      # The generic preset finds the circles in the frames; each lens starts
      # from the preset's lens on its own circle.
      preset_args=(--camera "${camera}" ${model_args[@]+"${model_args[@]}"})
      run_stage "splitting" 's/.*\[\([0-9]*\/[0-9]*\)\].*/\1 frames/p' \
        "${COLMAP}" dual_fisheye_splitter ${preset_args[@]+"${preset_args[@]}"} \
        "${inputs[@]}" --flat_field "${FLAT_FIELD}" \
        --output_path "${WORK_DIR}/split"
      image_dir="${WORK_DIR}/split/images"
      rig_config="${WORK_DIR}/split/rig_config.json"
      mask_args=(--ImageReader.mask_path "${WORK_DIR}/split/masks")
      camera_model="$(python3 -c 'import json, sys
print(json.load(open(sys.argv[1]))[0]["cameras"][0].get(
    "camera_model_name", "DOUBLE_SPHERE"))' "${rig_config}")"
      echo "splitting:          $(find "${image_dir}" -type f | wc -l) lens" \
        "images and their masks (${stage_seconds} s)" ;;
  esac
fi
run_stage "feature extraction" \
  's/.*Processed file \[\([0-9]*\/[0-9]*\)\].*/\1 images/p' \
  "${COLMAP}" feature_extractor --database_path "${database}" \
  --image_path "${image_dir}" --ImageReader.camera_model "${camera_model}" \
  --ImageReader.single_camera_per_folder 1 --FeatureExtraction.use_gpu 0 \
  ${mask_args[@]+"${mask_args[@]}"}
echo "feature extraction: $(sql 'SELECT COUNT(*) FROM images') images," \
  "$(sql 'SELECT SUM(rows) FROM keypoints') keypoints (${stage_seconds} s)"
if [ -n "${rig_config}" ]; then
  run_stage "rig configuration" 's/^$//p' "${COLMAP}" rig_configurator \
    --database_path "${database}" --rig_config_path "${rig_config}"
  echo "rig configuration:  $(sql 'SELECT COUNT(*) FROM rigs') rig(s)," \
    "$(sql 'SELECT COUNT(*) FROM frames') frames (${stage_seconds} s)"
fi

run_stage "matching" 's/.*Processing block \[\(.*\)\].*/block \1/p' \
  "${COLMAP}" exhaustive_matcher --database_path "${database}" \
  --FeatureMatching.use_gpu 0 --TwoViewGeometry.random_seed "${SEED}"
echo "matching:           $(sql 'SELECT COUNT(*) FROM two_view_geometries
  WHERE rows > 0') of $(sql 'SELECT COUNT(*) FROM matches') image pairs" \
  "verified (${stage_seconds} s)"

if [ -n "${rig_config}" ]; then
  run_stage "rig check" 's/^$//p' "${COLMAP}" rig_check \
    --database_path "${database}"
  echo "rig check:          the lens directions agree with the verified" \
    "pairs inside frames (${stage_seconds} s)"
fi

# map_into DIR [OPTION ...]: the mapper's models in DIR/0, DIR/1, ...
map_into() {
  local dir="$1"
  shift
  rm -rf "${dir}"
  mkdir -p "${dir}"
  run_stage "mapping" \
    's/.*Registering image #[0-9]* (num_reg_frames=\([0-9]*\)).*/\1 images registered/p' \
    "${COLMAP}" mapper --database_path "${database}" \
    --image_path "${image_dir}" --output_path "${dir}" \
    --Mapper.random_seed "${SEED}" "$@"
}

# scan_models DIR: how many models, the images of each, the largest model
# (most images, then most points) and its counts.
scan_models() {
  local model statistics count points
  models=0
  registered=""
  largest=0
  largest_points=0
  best_model=""
  for model in "$1"/*/; do
    [ -d "${model}" ] || continue
    models=$(( models + 1 ))
    statistics="$("${COLMAP}" model_analyzer --path "${model}" 2>&1)"
    count="$(sed -n 's/.*Registered images: \([0-9]*\).*/\1/p' \
      <<<"${statistics}")"
    points="$(sed -n 's/.*Points: \([0-9]*\).*/\1/p' <<<"${statistics}")"
    registered="${registered:+${registered} + }${count}"
    if [ "${count:-0}" -gt "${largest}" ] || { [ "${count:-0}" -eq "${largest}" ] \
        && [ "${points:-0}" -gt "${largest_points}" ]; }; then
      largest="${count:-0}"
      largest_points="${points:-0}"
      best_model="${model%/}"
    fi
  done
  # Models of one run may share images: the largest model's count, and
  # each model's beside it when there are several.
  if [ "${models}" -gt 1 ]; then
    where="the largest of ${models} models (${registered})"
  else
    where="${models} model"
  fi
}

num_images="$(sql 'SELECT COUNT(*) FROM images')"
sparse_dir="${WORK_DIR}/sparse"
map_into "${sparse_dir}"
scan_models "${sparse_dir}"
echo "mapping:            ${largest} of ${num_images}" \
  "images registered in ${where} (${stage_seconds} s)"
# A short rig capture can leave the lenses' self-calibration too little to
# go on, and the run splits; mapped again with the lenses held at the
# preset's (or the rig config's) intrinsics, the kept run is the one whose
# largest model holds more images.
if [ -n "${rig_config}" ] && [ "${largest}" -lt "${num_images}" ]; then
  refined_largest="${largest}"
  map_into "${WORK_DIR}/sparse_held" --Mapper.ba_refine_focal_length 0 \
    --Mapper.ba_refine_extra_params 0
  scan_models "${WORK_DIR}/sparse_held"
  held_line="${largest} of ${num_images} images registered in ${where}"
  if [ "${largest}" -gt "${refined_largest}" ]; then
    verdict="kept"
    sparse_dir="${WORK_DIR}/sparse_held"
  else
    verdict="not kept"
    scan_models "${sparse_dir}"
  fi
  echo "  intrinsics held:  ${held_line} (${verdict}; ${stage_seconds} s)"
fi
if [ -n "${rig_config}" ] && [ -n "${best_model}" ]; then
  mkdir -p "${WORK_DIR}/rig_calibration"
  run_stage "rig calibration" 's/^$//p' "${COLMAP}" rig_calibration \
    --input_path "${best_model}" \
    --output_path "${WORK_DIR}/rig_calibration"
  echo "rig calibration:    lens poses and intrinsics of model" \
    "$(basename "${best_model}") in ${WORK_DIR}/rig_calibration" \
    "(${stage_seconds} s)"
fi
elapsed=$(( $(date +%s) - start ))

echo
echo "=== SPHERA demo summary (${elapsed} s) ==="
echo "images:          $(sql 'SELECT COUNT(*) FROM images')"
echo "keypoints:       $(sql 'SELECT SUM(rows) FROM keypoints')"
echo "verified pairs:  $(sql 'SELECT COUNT(*) FROM two_view_geometries WHERE rows > 0')"
# A scene rendered by sphera_render holds its ground truth beside images/.
scene_dir="$(dirname "${image_dir}")"
if [ -d "${scene_dir}/sparse_gt" ] && [ -n "${best_model}" ]; then
  echo "--- against the ground truth (colmap model_evaluator) ---"
  mkdir -p "${WORK_DIR}/evaluation"
  "${COLMAP}" model_evaluator --gt_path "${scene_dir}/sparse_gt" \
    --input_path "${best_model}" --depth_path "${scene_dir}/depth" \
    --output_path "${WORK_DIR}/evaluation" 2>>"${LOG}" | tail -n 7
fi
for model in "${sparse_dir}"/*/; do
  [ -d "${model}" ] || continue
  "${COLMAP}" model_analyzer --path "${model}" 2>&1 \
    | grep -E "Cameras|Registered images|Points|Mean reprojection error" \
    | sed "s|^.*\] ||; s|^|$(basename "${model}"): |"
done
if [ -f "${WORK_DIR}/rig_calibration/rig_config.json" ]; then
  echo "--- the rig (colmap rig_calibration) ---"
  rig_lines="$(sed -n '/^=== rig calibration/,$p' "${LOG}" | awk '
    /^Rig [0-9]+: .*\(lengths in / {
      units = $0; sub(/^[^(]*\(/, "", units); sub(/\)$/, "", units)
      print units }
    /^  [^ ].* \(camera [0-9]+,/ { lens = $1 }
    /pose in the rig:/ { sub(/.*pose in the rig: /, ""); print lens ": " $0 }')"
  # The lens axes the matches inside frames measured (colmap rig_check),
  # before mapping: a second reading of the same lenses.
  check_lines="$(sed -n '/^=== rig check/,/^=== mapping/p' "${LOG}" | awk '
    /measured axis at/ {
      lens = $0; sub(/^[^(]*\(/, "", lens); sub(/\/?\).*/, "", lens)
      axis = $0; sub(/.*measured axis at /, "", axis)
      print lens ": matches inside frames put its axis at " axis }')"
  echo "${rig_lines}"
  [ -z "${check_lines}" ] || echo "${check_lines}"
  # Two readings of a lens's axis more than 2 degrees apart: the capture
  # did not pin the lens in the rig (too short, or turning in place).
  printf '%s\n%s\n' "${rig_lines}" "${check_lines}" | awk '
    function direction(line, parts) {
      match(line, /azimuth -?[0-9.]+ deg, elevation -?[0-9.]+/)
      split(substr(line, RSTART, RLENGTH), parts, " ")
      return parts[2] " " parts[5]
    }
    /: turned .*its axis at azimuth/ { mapped[$1] = direction($0) }
    /: matches inside frames put its axis at/ { checked[$1] = direction($0) }
    END {
      rad = atan2(0, -1) / 180
      for (lens in checked) {
        if (!(lens in mapped)) continue
        split(mapped[lens], m, " "); split(checked[lens], c, " ")
        cosine = sin(m[2] * rad) * sin(c[2] * rad) + \
          cos(m[2] * rad) * cos(c[2] * rad) * cos((m[1] - c[1]) * rad)
        if (cosine > 1) cosine = 1
        angle = atan2(sqrt(1 - cosine * cosine), cosine) / rad
        if (angle > 2)
          printf "%s the two readings of its axis are %.1f deg apart: the" \
            " capture does not pin the lens in the rig (more frames, moved" \
            " between, not turned in place)\n", lens, angle
      }
    }'
fi
echo "log: ${LOG}"
