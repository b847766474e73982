#!/usr/bin/env bash
# Fuzz targets of SPHERA's input checks, built with clang's libFuzzer under
# AddressSanitizer and UndefinedBehaviorSanitizer (Debian: clang,
# libclang-rt-14-dev; scripts/setup.sh installs them).
#
#   scripts/fuzz.sh                     short deterministic run: 20000
#                                       inputs per target, seed 1 (CI)
#   scripts/fuzz.sh --runs N            N inputs per target
#   scripts/fuzz.sh --minutes M         M minutes per target (a long run;
#                                       the targets run side by side)
#   scripts/fuzz.sh ... TARGET...       only these targets
#
# Targets (tests/fuzz/):
#   fuzz_database_check  the check of a COLMAP database file before COLMAP
#                        opens it (colmap_ext/scene/database_check.cc)
#   fuzz_image_bytes     the JPEG/PNG structure walk of feature extraction
#                        (colmap_ext/image/image_file_structure.cc)
#   fuzz_camera_params   the check of --ImageReader.camera_model/_params
#                        (colmap_ext/controllers/image_errors.cc and
#                        colmap_ext/scene/camera_params_error.cc)
#   fuzz_matching        COLMAP's geometric verifier and exhaustive matcher
#                        on every database the check above lets through
#                        (the check instrumented, matching linked from the
#                        build): no exception may leave a matching thread
#   fuzz_model_readers   COLMAP's text and binary model readers as patched
#                        (the two reader sources instrumented, the rest of
#                        COLMAP linked from the build, as build.ninja links
#                        the colmap program)
#   fuzz_rig_config      rig_configurator's JSON reader as patched
#                        (colmap/scene/rig.cc instrumented, the rest linked
#                        as for fuzz_model_readers)
#   fuzz_calibration_import  calibration_importer's readers of Kalibr,
#                        OpenCV, OCamCalib and Basalt files (calibration/,
#                        instrumented; yaml-cpp, OpenCV and Ceres from Debian)
#   fuzz_camera_presets  the camera presets' lookup and rig_preset's option
#                        checks (calibration/camera_presets.cc, built as
#                        fuzz_calibration_import)
#
# Each target starts from seeds made here from a rendered scene (a small
# database of two images, a JPEG and a PNG; a small valid model in both
# formats, each file of it a seed) and from every file in
# tests/fuzz/regressions/TARGET/ (inputs that once failed: each must pass).
# Work goes to build/fuzz/ (SPHERA_BUILD_DIR); an input that makes a target
# fail is kept as build/fuzz/crashes/TARGET/crash-*; copy it into
# tests/fuzz/regressions/TARGET/ once fixed. Needs the built colmap and
# sphera_render (scripts/build.sh). Exit code: 0 when no target failed.
set -euo pipefail

readonly REPO_ROOT="$(cd "$(dirname "$0")/.." && pwd)"
readonly BUILD_DIR="${SPHERA_BUILD_DIR:-${REPO_ROOT}/build}"
readonly WORK="${BUILD_DIR}/fuzz"
readonly COLMAP="${BUILD_DIR}/bin/colmap"
readonly RENDER="${BUILD_DIR}/synthetic/sphera_render"
readonly ALL_TARGETS=(fuzz_database_check fuzz_matching fuzz_image_bytes
                      fuzz_camera_params fuzz_model_readers fuzz_rig_config
                      fuzz_calibration_import fuzz_camera_presets)
# COLMAP's log lines of every rejected input would cost most of the time.
export GLOG_minloglevel=3

runs=20000
minutes=0
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --minutes) minutes="$2"; shift 2 ;;
    -h|--help) sed -n '2,46p' "$0"; exit 0 ;;
    fuzz_*) targets+=("$1"); shift ;;
    *) echo "fuzz.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${ALL_TARGETS[@]}")

for tool in clang++ "${COLMAP}" "${RENDER}"; do
  if ! command -v "${tool}" >/dev/null 2>&1; then
    echo "fuzz.sh: ${tool} not found (scripts/setup.sh installs clang," \
         "scripts/build.sh builds the programs)" >&2
    exit 1
  fi
done

mkdir -p "${WORK}"
log() { echo "[fuzz] $*"; }

# -- build ------------------------------------------------------------------
# Line tables are all a sanitizer's report needs (file and line of each
# frame); full debug information made the cold compilation 5-13% slower.
readonly FLAGS=(-std=c++17 -O1 -gline-tables-only -fno-omit-frame-pointer
                -fsanitize=fuzzer,address,undefined
                -fno-sanitize-recover=undefined
                -I "${REPO_ROOT}" -I "${BUILD_DIR}/colmap-src/src"
                -I /usr/include/eigen3)
# clang++ through ccache when there is one, with the settings of
# scripts/build.sh (the cache outside the clone, paths relative to it).
COMPILER=(clang++)
if command -v ccache >/dev/null 2>&1; then
  COMPILER=(ccache clang++)
  export CCACHE_BASEDIR="${REPO_ROOT}"
  export CCACHE_DIR="${CCACHE_DIR:-${HOME}/.cache/ccache}"
  export CCACHE_NOHASHDIR=true
fi
# The flags and libraries of the colmap program as build.ninja has them.
ninja_field() {  # ninja_field BUILD_LINE_PATTERN FIELD
  awk -v pattern="$1" -v field="$2" '
    index($0, pattern) == 1 { found = 1 }
    found && $1 == field { sub(/^ *[A-Z_]+ = /, ""); print; exit }' \
    "${BUILD_DIR}/build.ninja"
}
build_target() {
  local target="$1" cflags=() sources=() libraries=()
  local scene="${BUILD_DIR}/colmap-src/src/colmap/scene"
  case "${target}" in
    fuzz_image_bytes)
      sources=("${REPO_ROOT}/colmap_ext/image/image_file_structure.cc") ;;
    fuzz_calibration_import|fuzz_camera_presets)
      # shellcheck disable=SC2207
      sources=($(ls "${REPO_ROOT}"/calibration/*.cc | grep -v _test.cc))
      cflags=(-I /usr/include/opencv4)
      libraries=(-lopencv_core -lyaml-cpp -lceres -lglog) ;;
    fuzz_database_check|fuzz_matching|fuzz_camera_params|fuzz_model_readers|fuzz_rig_config)
      # The sources under test instrumented, the rest of COLMAP linked from
      # the build with the flags of one of its objects.
      local object="build colmap/src/colmap/scene/CMakeFiles/colmap_scene.dir/reconstruction_io_binary.cc.o:"
      local program="build colmap/src/colmap/exe/colmap: "
      sources=("${scene}/reconstruction_io_binary.cc"
               "${scene}/reconstruction_io_text.cc")
      [ "${target}" = fuzz_rig_config ] && sources=("${scene}/rig.cc"
          "${REPO_ROOT}/colmap_ext/scene/rig_config.cc")
      [ "${target}" = fuzz_database_check ] || [ "${target}" = fuzz_matching ] && sources=(
          "${REPO_ROOT}/colmap_ext/scene/database_check.cc"
          "${REPO_ROOT}/colmap_ext/scene/camera_params_error.cc")
      [ "${target}" = fuzz_camera_params ] && sources=(
          "${REPO_ROOT}/colmap_ext/controllers/image_errors.cc"
          "${REPO_ROOT}/colmap_ext/scene/camera_params_error.cc"
          "${REPO_ROOT}/colmap_ext/image/image_file_structure.cc")
      # shellcheck disable=SC2207
      cflags=($(ninja_field "${object}" DEFINES) $(ninja_field "${object}" INCLUDES))
      # shellcheck disable=SC2207
      libraries=($(ninja_field "${program}" LINK_LIBRARIES) -fopenmp) ;;
    *) echo "fuzz.sh: unknown target ${target}" >&2; exit 2 ;;
  esac
  local binary="${WORK}/${target}"
  sources=("${REPO_ROOT}/tests/fuzz/${target}.cc" "${sources[@]}")
  # Rebuilt when a source is newer than the binary.
  local newest
  newest="$(ls -t "${REPO_ROOT}/tests/fuzz/${target}.cc" \
            "${REPO_ROOT}"/colmap_ext/scene/*.h "${REPO_ROOT}"/colmap_ext/scene/*.cc \
            "${REPO_ROOT}"/colmap_ext/image/image_file_structure.* \
            "${REPO_ROOT}"/calibration/* \
            "$(readlink -f "${COLMAP}")" "${binary}" 2>/dev/null | head -1 || true)"
  if [ ! -x "${binary}" ] || [ "${newest}" != "${binary}" ]; then
    log "building ${target}"
    # One object per source through ccache (the instrumented COLMAP and
    # calibration sources are most of a fresh clone's fuzz.short: with a
    # warm ccache they are hits), then the link. In the build folder: the
    # libraries of build.ninja are relative to it.
    local objects=() source object
    mkdir -p "${WORK}/objects/${target}"
    for source in "${sources[@]}"; do
      object="${WORK}/objects/${target}/$(basename "${source}").o"
      (cd "${BUILD_DIR}" && "${COMPILER[@]}" "${FLAGS[@]}" "${cflags[@]}" \
         -c "${source}" -o "${object}")
      objects+=("${object}")
    done
    (cd "${BUILD_DIR}" && clang++ "${FLAGS[@]}" "${objects[@]}" \
       ${libraries[@]+"${libraries[@]}"} -o "${binary}.tmp")
    mv "${binary}.tmp" "${binary}"
  fi
}

# -- seeds ------------------------------------------------------------------
make_seeds() {
  local seeds="${WORK}/seeds"
  # "done" names the version of this recipe: seeds of an older one are remade.
  [ "$(cat "${seeds}/done" 2>/dev/null)" = 3 ] && return
  rm -rf "${seeds}" "${WORK}/scene" "${WORK}/scene_png" "${WORK}"/rig_*
  mkdir -p "${seeds}/fuzz_database_check" "${seeds}/fuzz_matching" \
    "${seeds}/fuzz_image_bytes" \
    "${seeds}/fuzz_model_readers" "${seeds}/fuzz_camera_params" \
    "${seeds}/fuzz_rig_config"
  local k=0
  for line in "PINHOLE\n500,510,320,240" "EQUIRECTANGULAR\n2048,1024" \
      "EUCM\n300,300,512,512,0.6,1.1" \
      "UNIFIED_OMNI\n280,280,512,512,1.05,-0.02,0.003,0,0" \
      "DOUBLE_SPHERE\n300,300,512,512,-0.2,0.6" "OPENCV_FISHEYE\n300,300,512,512,0,0,0,0"; do
    printf "%b" "${line}" > "${seeds}/fuzz_camera_params/seed${k}"
    k=$((k + 1))
  done
  # Two neighbours of a ring of 16: the matcher verifies their pair (it
  # exits 1 when no pair is verified).
  "${RENDER}" --output "${WORK}/scene" --layout ring --num_cameras 16 \
    --width 128 --height 96 --supersample 1 >/dev/null
  printf 'cam000.jpg\ncam001.jpg\n' > "${WORK}/scene/pair.txt"
  "${RENDER}" --output "${WORK}/scene_png" --layout ring --num_cameras 2 \
    --width 48 --height 36 --supersample 1 --format png >/dev/null
  # Rig configs: the renderer's true rigs (model, params, poses) and one
  # with prefixes and a reference only.
  for preset in dual_fisheye ring8; do
    "${RENDER}" --output "${WORK}/rig_${preset}" --rig_preset "${preset}" \
      --frames 1 --lens_size 64 --supersample 1 >/dev/null
    cp "${WORK}/rig_${preset}/rig_config.json" "${seeds}/fuzz_rig_config/${preset}.json"
  done
  printf '[{"cameras": [{"image_prefix": "a/", "ref_sensor": true}, %s]}]\n' \
    '{"image_prefix": "b/", "image_suffix": "_2.jpg"}' > "${seeds}/fuzz_rig_config/plain.json"
  printf '[{"cameras": [{"image_prefix": "a/", "ref_sensor": true, %s}]}]\n' \
    '"camera_model_name": "EUCM", "field_of_view_deg": 195, "image_circle": [32, 20, 30]' \
    > "${seeds}/fuzz_rig_config/spec.json"
  cp "${WORK}/scene/images/cam000.jpg" "${seeds}/fuzz_image_bytes/seed.jpg"
  cp "${WORK}/scene_png/images/cam000.png" "${seeds}/fuzz_image_bytes/seed.png"
  local db="${WORK}/seed.db"
  rm -f "${db}"
  "${COLMAP}" feature_extractor --database_path "${db}" \
    --image_path "${WORK}/scene/images" --image_list_path "${WORK}/scene/pair.txt" \
    --FeatureExtraction.use_gpu 0 --SiftExtraction.max_num_features 48 >/dev/null 2>&1
  "${COLMAP}" exhaustive_matcher --database_path "${db}" \
    --FeatureMatching.use_gpu 0 >/dev/null 2>&1
  # One file, no write-ahead log beside it.
  python3 - "${db}" "${seeds}/fuzz_database_check/seed.db" <<'EOF'
import sqlite3, sys
source = sqlite3.connect(sys.argv[1])
target = sqlite3.connect(sys.argv[2])
source.backup(target)
target.execute("PRAGMA journal_mode=DELETE")
target.execute("VACUUM")
target.close()
source.close()
EOF
  cp "${seeds}/fuzz_database_check/seed.db" "${seeds}/fuzz_matching/seed.db"
  # The model: bad_model_test's small valid model, in both formats; a seed
  # is a file of it behind the byte that names it (bit 0: binary, then the
  # file's index in rigs, cameras, frames, images, points3D).
  local model="${WORK}/model"
  rm -rf "${model}"
  mkdir -p "${model}/binary" "${model}/text"
  PYTHONPATH="${REPO_ROOT}/tests:${REPO_ROOT}/scripts" SPHERA_COLMAP="${COLMAP}" \
    python3 -c "from bad_model_test import write_valid_text_model as w; w('${model}/first')"
  "${COLMAP}" model_converter --input_path "${model}/first" \
    --output_path "${model}/binary" --output_type BIN >/dev/null 2>&1
  "${COLMAP}" model_converter --input_path "${model}/binary" \
    --output_path "${model}/text" --output_type TXT >/dev/null 2>&1
  python3 - "${model}" "${seeds}/fuzz_model_readers" <<'EOF'
import sys
model, seeds = sys.argv[1:]
for binary, (folder, extension) in enumerate((("text", ".txt"), ("binary", ".bin"))):
    for index, name in enumerate(("rigs", "cameras", "frames", "images", "points3D")):
        with open(f"{model}/{folder}/{name}{extension}", "rb") as f:
            data = f.read()
        with open(f"{seeds}/{folder}_{name}", "wb") as f:
            f.write(bytes([(index << 1) | binary]) + data)
EOF
  echo 3 > "${seeds}/done"
}

# Seeds of fuzz_calibration_import: a small file of each format behind the
# byte that names it (0 Kalibr, 1 OpenCV, 2 OCamCalib, 3 Basalt); written
# every run, outside make_seeds' versioned recipe.
make_calibration_seeds() {
  local seeds="${WORK}/seeds/fuzz_calibration_import"
  mkdir -p "${seeds}"
  printf '\000%s' 'cam0:
  camera_model: pinhole
  intrinsics: [458.6, 457.3, 367.2, 248.4]
  distortion_model: radtan
  distortion_coeffs: [-0.28, 0.07, 0.0002, 0.00002]
  resolution: [752, 480]
cam1:
  T_cn_cnm1:
  - [0.0, 0.0, 1.0, 0.1]
  - [0.0, 1.0, 0.0, 0.0]
  - [-1.0, 0.0, 0.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: ds
  intrinsics: [-0.2, 0.6, 300.0, 300.0, 511.5, 511.5]
  distortion_model: none
  distortion_coeffs: []
  resolution: [1024, 1024]
' > "${seeds}/kalibr"
  printf '\001%s' '%YAML:1.0
---
image_width: 640
image_height: 480
fisheye_model: 1
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 200., 0., 319.5, 0., 201., 239.5, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 4
   cols: 1
   dt: d
   data: [ 0.02, -0.005, 0.0009, -0.0001 ]
' > "${seeds}/opencv"
  printf '\002%s' '#polynomial coefficients
5 -250 0 1.2e-3 -1e-6 2e-9
#inverse polynomial
3 250 100 10
#center
239.25 319.75
#affine parameters
1.0005 0.0002 -0.0001
#image size
480 640
' > "${seeds}/ocamcalib"
  printf '\003%s' '{"value0": {"T_imu_cam": [
 {"px": 0.01, "py": 0, "pz": 0, "qx": 0, "qy": 0, "qz": 0, "qw": 1},
 {"px": -0.09, "py": 0, "pz": 0, "qx": 0, "qy": 0.7071067811865476, "qz": 0, "qw": 0.7071067811865476}],
 "intrinsics": [
 {"camera_type": "kb4", "intrinsics": {"fx": 380, "fy": 381, "cx": 319.5, "cy": 239.5, "k1": 0.01, "k2": -0.002, "k3": 0.0004, "k4": -0.00005}},
 {"camera_type": "ucm", "intrinsics": {"fx": 300, "fy": 300, "cx": 319.5, "cy": 239.5, "alpha": 0.6}}],
 "resolution": [[640, 480], [640, 480]]}}
' > "${seeds}/basalt"
}

# Seeds of fuzz_camera_presets: the lines --camera, --resolution,
# --image_width, --image_height, a resolution name and --camera_model, as
# rig_preset gets them; written every run.
make_preset_seeds() {
  local seeds="${WORK}/seeds/fuzz_camera_presets"
  mkdir -p "${seeds}"
  printf 'gopro_fusion\nphoto\n\n\n5.2k\n' > "${seeds}/by_name"
  printf 'insta360_x3\n\n5952\n2976\n11968x5984\n' > "${seeds}/by_size"
  printf 'dual_fisheye\n4000x2000\n\n\n8k\n' > "${seeds}/generic"
  printf 'VUZE\n\n\n\nlens\n' > "${seeds}/vuze"
  printf 'theta\n3k\n-1\n7\n0x0\n' > "${seeds}/bad"
  printf 'ricoh_theta_v\n2k\n\n\n4k\nOPENCV_FISHEYE\n' > "${seeds}/kb_model"
  printf 'vuze\n\n\n\nlens\nUNIFIED_OMNI\n' > "${seeds}/vuze_model"
  printf 'gopro_max\n\n\n\nphoto\nEUCM\n' > "${seeds}/stitched_model"
}

# -- run --------------------------------------------------------------------
make_seeds
make_calibration_seeds
make_preset_seeds
for target in "${targets[@]}"; do
  build_target "${target}"
done

status=0
pids=()
for target in "${targets[@]}"; do
  corpus="${WORK}/corpus/${target}"
  crashes="${WORK}/crashes/${target}"
  regressions="${REPO_ROOT}/tests/fuzz/regressions/${target}"
  mkdir -p "${corpus}" "${crashes}"
  cp -n "${WORK}/seeds/${target}"/* "${corpus}/"
  if [ -d "${regressions}" ] && [ -n "$(ls -A "${regressions}")" ]; then
    log "${target}: regression inputs"
    SPHERA_FUZZ_MODEL="${WORK}/model" \
      "${WORK}/${target}" "${regressions}"/* >"${WORK}/${target}.regressions.log" 2>&1 \
      || { log "${target}: a regression input fails"; status=1; }
  fi
  max_len=$(( $(stat -c %s "${WORK}/seeds/${target}"/* | sort -n | tail -1) + 1024 ))
  limit=(-runs="${runs}")
  [ "${minutes}" != 0 ] && limit=(-max_total_time=$(( minutes * 60 )))
  log "${target}: ${limit[*]}, inputs up to ${max_len} bytes"
  (
    cd "${crashes}"
    export SPHERA_FUZZ_MODEL="${WORK}/model"
    "${WORK}/${target}" -seed=1 -max_len="${max_len}" -timeout=20 \
      -rss_limit_mb=4096 -print_final_stats=1 "${limit[@]}" "${corpus}" \
      >"${WORK}/${target}.log" 2>&1
  ) &
  pids+=($!)
  # A short run: one target after the other (deterministic); a long run:
  # side by side.
  [ "${minutes}" = 0 ] && { wait "${pids[-1]}" || status=1; pids=(); }
done
for pid in "${pids[@]}"; do
  wait "${pid}" || status=1
done

for target in "${targets[@]}"; do
  stats="$(grep -E "stat::number_of_executed_units|cov: " "${WORK}/${target}.log" \
           | tail -2 | tr '\n' ' ')"
  log "${target}: ${stats}"
  if grep -qE "ERROR: (AddressSanitizer|libFuzzer|UndefinedBehaviorSanitizer)|runtime error:" \
       "${WORK}/${target}.log"; then
    log "${target}: FAILED, see ${WORK}/${target}.log and ${WORK}/crashes/${target}/"
    status=1
  fi
done
exit "${status}"
