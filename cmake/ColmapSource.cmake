# Prepares the patched COLMAP source tree at configure time.
#
# The base is upstream COLMAP at commit 5d968cf (4.2.0.dev0, 2026-08-08) with
# the PoseLib and faiss sources it builds with; the patch series is
# colmap_ext/patches/.
#
# Source, in order of preference:
#   SPHERA_COLMAP_EDITABLE_DIR  an editable, already patched checkout
#                               (scripts/colmap_patches.sh checkout); used as is
#   SPHERA_COLMAP_SOURCE_DIR    a pristine COLMAP source tree of the base
#   the verified tarball colmap-5d968cf.tar.gz (see below)
# The patch series is applied in name order onto a staging copy; files are
# then copied into the live tree only when their content changed, so a changed
# patch rebuilds only what it touches.
#
# The three tarballs (COLMAP, PoseLib, faiss) are looked up, in order, in
# SPHERA_PEERS_DIR (default: the folder shared/peers beside the repository,
# when present) and in SPHERA_CACHE_DIR; each can also be given on its own
# with SPHERA_COLMAP4_TARBALL, SPHERA_POSELIB_TARBALL and
# SPHERA_FAISS_TARBALL. A tarball found in SPHERA_PEERS_DIR is copied into
# SPHERA_CACHE_DIR (default ~/.cache/sphera) when that does not hold it yet,
# so that a later clone elsewhere on the machine finds it (a failed copy is
# only reported). Every tarball is checked against its pinned SHA-256 before
# use, and a missing or damaged one stops the configuration with a message
# naming the file and the expected checksum. Nothing is downloaded: the build
# needs no network when the tarballs are present. The commit id names the
# same source in COLMAP's public repository.

set(SPHERA_COLMAP_EDITABLE_DIR "" CACHE PATH
    "Editable patched COLMAP checkout, used as is")
set(SPHERA_COLMAP_SOURCE_DIR "" CACHE PATH "Pristine COLMAP source tree of the base")
set(SPHERA_CACHE_DIR "$ENV{HOME}/.cache/sphera" CACHE PATH
    "Where verified source tarballs are kept between builds")
set(SPHERA_PATCH_DIR "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches")

set(SPHERA_COLMAP_COMMIT "5d968cf38aa2")
set(SPHERA_COLMAP_NAME "colmap-5d968cf")
set(SPHERA_COLMAP_SHA256
    "1c6c1a735774d8bc442900d52aac5359dcc9c7ffe53d3daba054fa3095de8dc1")
set(SPHERA_POSELIB_NAME "PoseLib-a69263d")
set(SPHERA_POSELIB_SHA256
    "7b8d9b0aae73feeb7ba202261e1ff90dd7d166316b263210b6f9456303722e2d")
set(SPHERA_FAISS_NAME "faiss-1.14.1")
set(SPHERA_FAISS_SHA256
    "0216d38d8c5c460433815b72d3cde6725eaa5d5770576277a2abc01ffc414d20")

set(_sphera_default_peers "")
get_filename_component(_sphera_shared_peers
                       "${CMAKE_CURRENT_SOURCE_DIR}/../shared/peers" ABSOLUTE)
if(EXISTS "${_sphera_shared_peers}/${SPHERA_COLMAP_NAME}.tar.gz")
  set(_sphera_default_peers "${_sphera_shared_peers}")
endif()
set(SPHERA_PEERS_DIR "${_sphera_default_peers}" CACHE PATH
    "Folder with colmap-5d968cf, PoseLib-a69263d and faiss-1.14.1 tarballs")

set(SPHERA_COLMAP4_TARBALL "" CACHE FILEPATH "colmap-5d968cf.tar.gz")
set(SPHERA_POSELIB_TARBALL "" CACHE FILEPATH "PoseLib-a69263d.tar.gz")
set(SPHERA_FAISS_TARBALL "" CACHE FILEPATH "faiss-1.14.1.tar.gz")

# Fails with a message naming the file and both checksums when the file at
# `path` does not have the SHA-256 `expected`.
function(sphera_verify_sha256 path expected what)
  if(NOT EXISTS "${path}")
    message(FATAL_ERROR "${what}: ${path} does not exist (expected SHA-256 ${expected})")
  endif()
  file(SHA256 "${path}" actual)
  if(NOT actual STREQUAL expected)
    message(FATAL_ERROR "${what}: ${path} has SHA-256 ${actual}, expected "
                        "${expected}; the file is damaged or not the pinned "
                        "release. Remove it or pass the right file.")
  endif()
endfunction()

# Copies the verified tarball `path` into SPHERA_CACHE_DIR, so that a later
# clone elsewhere on this machine finds it without SPHERA_PEERS_DIR. The copy
# goes to a temporary name, is checked and then renamed; any failure is only
# reported, never stops the configuration.
function(sphera_cache_tarball path name sha256)
  set(cached "${SPHERA_CACHE_DIR}/${name}.tar.gz")
  set(partial "${cached}.partial")
  execute_process(COMMAND "${CMAKE_COMMAND}" -E make_directory "${SPHERA_CACHE_DIR}"
                  OUTPUT_QUIET ERROR_QUIET)
  execute_process(COMMAND "${CMAKE_COMMAND}" -E copy "${path}" "${partial}"
                  RESULT_VARIABLE copy_result OUTPUT_QUIET ERROR_QUIET)
  if(copy_result EQUAL 0 AND EXISTS "${partial}")
    file(SHA256 "${partial}" copied_sha256)
    if(copied_sha256 STREQUAL sha256)
      execute_process(COMMAND "${CMAKE_COMMAND}" -E rename "${partial}" "${cached}"
                      RESULT_VARIABLE copy_result OUTPUT_QUIET ERROR_QUIET)
    else()
      set(copy_result 1)
    endif()
  endif()
  if(copy_result EQUAL 0)
    message(STATUS "Copied ${name}.tar.gz into ${SPHERA_CACHE_DIR}")
  else()
    execute_process(COMMAND "${CMAKE_COMMAND}" -E rm -f "${partial}"
                    OUTPUT_QUIET ERROR_QUIET)
    message(STATUS "Could not copy ${path} into ${SPHERA_CACHE_DIR}; "
                   "the build goes on with ${path}")
  endif()
endfunction()

# Sets `out_var` to the tarball `name`.tar.gz: the cache variable `override`
# when set, else the first of SPHERA_PEERS_DIR and SPHERA_CACHE_DIR holding it.
# Verifies its SHA-256. A tarball found in SPHERA_PEERS_DIR is also copied into
# SPHERA_CACHE_DIR when that does not hold it yet.
function(sphera_find_tarball name sha256 override out_var)
  set(candidates "")
  if(${override})
    list(APPEND candidates "${${override}}")
  else()
    foreach(dir "${SPHERA_PEERS_DIR}" "${SPHERA_CACHE_DIR}")
      if(dir)
        list(APPEND candidates "${dir}/${name}.tar.gz")
      endif()
    endforeach()
  endif()
  foreach(candidate ${candidates})
    if(EXISTS "${candidate}")
      sphera_verify_sha256("${candidate}" "${sha256}" "${name}")
      if(NOT ${override} AND SPHERA_PEERS_DIR AND SPHERA_CACHE_DIR
         AND candidate STREQUAL "${SPHERA_PEERS_DIR}/${name}.tar.gz"
         AND NOT EXISTS "${SPHERA_CACHE_DIR}/${name}.tar.gz")
        sphera_cache_tarball("${candidate}" "${name}" "${sha256}")
      endif()
      set(${out_var} "${candidate}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  string(REPLACE ";" ", " searched "${candidates}")
  message(FATAL_ERROR
    "${name}.tar.gz (SHA-256 ${sha256}) not found; searched: ${searched}. "
    "Put it in ${SPHERA_CACHE_DIR} or pass -D${override}=/path/${name}.tar.gz "
    "(the COLMAP source is commit ${SPHERA_COLMAP_COMMIT} of COLMAP's public "
    "repository).")
endfunction()

# PoseLib and faiss, unpacked once into the build tree (a stable path, so that
# ccache hits across clones) and consumed by COLMAP's FetchContent without a
# network.
function(sphera_prepare_colmap_dependencies)
  set(deps_dir "${CMAKE_BINARY_DIR}/colmap4-deps")
  foreach(dep POSELIB FAISS)
    set(name ${SPHERA_${dep}_NAME})
    set(source_dir "${deps_dir}/${name}")
    if(NOT EXISTS "${source_dir}/CMakeLists.txt")
      sphera_find_tarball(${name} ${SPHERA_${dep}_SHA256}
                          SPHERA_${dep}_TARBALL tarball)
      file(REMOVE_RECURSE "${deps_dir}/stage-${name}")
      file(ARCHIVE_EXTRACT INPUT "${tarball}"
           DESTINATION "${deps_dir}/stage-${name}")
      if(NOT EXISTS "${deps_dir}/stage-${name}/${name}/CMakeLists.txt")
        message(FATAL_ERROR "${tarball} does not unpack to ${name}/")
      endif()
      file(RENAME "${deps_dir}/stage-${name}/${name}" "${source_dir}")
      file(REMOVE_RECURSE "${deps_dir}/stage-${name}")
    endif()
    set(FETCHCONTENT_SOURCE_DIR_${dep} "${source_dir}" CACHE PATH "" FORCE)
  endforeach()
  set(FETCHCONTENT_FULLY_DISCONNECTED ON CACHE BOOL "" FORCE)
  set(ONNX_ENABLED OFF CACHE BOOL "" FORCE)
  set(DOWNLOAD_ENABLED OFF CACHE BOOL "" FORCE)
endfunction()

function(sphera_prepare_colmap_source out_var)
  # The source tarball is verified before anything is unpacked, so a missing
  # or damaged file leaves no half-prepared tree.
  set(tarball "")
  if(NOT SPHERA_COLMAP_EDITABLE_DIR AND NOT SPHERA_COLMAP_SOURCE_DIR)
    sphera_find_tarball(${SPHERA_COLMAP_NAME} ${SPHERA_COLMAP_SHA256}
                        SPHERA_COLMAP4_TARBALL tarball)
  endif()
  sphera_prepare_colmap_dependencies()
  if(SPHERA_COLMAP_EDITABLE_DIR)
    if(NOT EXISTS "${SPHERA_COLMAP_EDITABLE_DIR}/src/colmap/sensor/models.h")
      message(FATAL_ERROR "SPHERA_COLMAP_EDITABLE_DIR=${SPHERA_COLMAP_EDITABLE_DIR} "
                          "is not a COLMAP source tree")
    endif()
    set(${out_var} "${SPHERA_COLMAP_EDITABLE_DIR}" PARENT_SCOPE)
    return()
  endif()

  file(GLOB patches "${SPHERA_PATCH_DIR}/*.patch")
  list(SORT patches)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${patches} "${SPHERA_PATCH_DIR}")

  # The stamp names the base, the pristine source and every patch's content.
  # "base=4" is the line build trees of the 4.x base have always had; the
  # tree of an older base is removed below.
  set(stamp_text "base=4\nsource=${SPHERA_COLMAP_SOURCE_DIR}\n")
  foreach(patch ${patches})
    file(SHA256 "${patch}" patch_hash)
    string(APPEND stamp_text "${patch_hash}\n")
  endforeach()
  set(live_dir "${CMAKE_BINARY_DIR}/colmap-src")
  set(stamp_file "${CMAKE_BINARY_DIR}/colmap-src.stamp")
  if(EXISTS "${stamp_file}" AND EXISTS "${live_dir}/CMakeLists.txt")
    file(READ "${stamp_file}" old_stamp)
    if(old_stamp STREQUAL stamp_text)
      set(${out_var} "${live_dir}" PARENT_SCOPE)
      return()
    endif()
    # Another base: files of the old tree must not linger.
    if(NOT old_stamp MATCHES "^base=4\n")
      file(REMOVE_RECURSE "${live_dir}")
    endif()
  endif()

  set(stage_dir "${CMAKE_BINARY_DIR}/colmap-stage")
  file(REMOVE_RECURSE "${stage_dir}")
  file(MAKE_DIRECTORY "${stage_dir}")
  if(SPHERA_COLMAP_SOURCE_DIR)
    if(NOT EXISTS "${SPHERA_COLMAP_SOURCE_DIR}/src/colmap/sensor/models.h")
      message(FATAL_ERROR "SPHERA_COLMAP_SOURCE_DIR=${SPHERA_COLMAP_SOURCE_DIR} "
                          "is not a COLMAP source tree")
    endif()
    file(COPY "${SPHERA_COLMAP_SOURCE_DIR}/" DESTINATION "${stage_dir}/colmap"
         PATTERN ".git" EXCLUDE)
    set(pristine_dir "${stage_dir}/colmap")
  else()
    file(ARCHIVE_EXTRACT INPUT "${tarball}" DESTINATION "${stage_dir}")
    set(pristine_dir "${stage_dir}/${SPHERA_COLMAP_NAME}")
    if(NOT EXISTS "${pristine_dir}/src/colmap/sensor/models.h")
      file(REMOVE_RECURSE "${stage_dir}")
      message(FATAL_ERROR "${tarball} does not unpack to a COLMAP source tree "
                          "at ${pristine_dir}")
    endif()
  endif()

  find_program(PATCH_PROGRAM patch REQUIRED)
  foreach(patch ${patches})
    execute_process(
      COMMAND "${PATCH_PROGRAM}" -p1 --batch --forward --quiet -i "${patch}"
      WORKING_DIRECTORY "${pristine_dir}"
      RESULT_VARIABLE patch_result OUTPUT_VARIABLE patch_output
      ERROR_VARIABLE patch_output)
    if(NOT patch_result EQUAL 0)
      file(REMOVE_RECURSE "${stage_dir}")
      message(FATAL_ERROR "Patch ${patch} does not apply:\n${patch_output}")
    endif()
  endforeach()

  # configure_file(COPYONLY) leaves a file untouched when its content is the
  # same, which keeps the build incremental.
  file(GLOB_RECURSE staged_files RELATIVE "${pristine_dir}" "${pristine_dir}/*")
  foreach(relative_path ${staged_files})
    configure_file("${pristine_dir}/${relative_path}"
                   "${live_dir}/${relative_path}" COPYONLY)
  endforeach()
  file(REMOVE_RECURSE "${stage_dir}")
  file(WRITE "${stamp_file}" "${stamp_text}")
  set(${out_var} "${live_dir}" PARENT_SCOPE)
endfunction()
