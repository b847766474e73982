# Prepares the patched COLMAP source tree at configure time.
#
# SPHERA_COLMAP_BASE selects the COLMAP base:
#   3.10  COLMAP 3.10 from Debian's source registry, patch series
#         colmap_ext/patches/ (the default while the port to 4.x is completed)
#   4     upstream COLMAP 4.2.0.dev at commit 5d968cf with PoseLib and faiss
#         (cmake/Colmap4Source.cmake), patch series colmap_ext/patches4/
#
# Source, in order of preference:
#   SPHERA_COLMAP_EDITABLE_DIR  an editable, already patched checkout
#                               (scripts/colmap_patches.sh checkout); used as is
#   SPHERA_COLMAP_SOURCE_DIR    a pristine COLMAP source tree of the base
#   the base's verified tarball (3.10: SPHERA_COLMAP_TARBALL, fetched from
#   Debian's source registry into SPHERA_CACHE_DIR when absent; 4: see
#   cmake/Colmap4Source.cmake)
# The patch series is applied in name order onto a staging copy; files are
# then copied into the live tree only when their content changed, so a changed
# patch rebuilds only what it touches.

set(SPHERA_COLMAP_BASE "3.10" CACHE STRING "COLMAP base: 3.10 or 4")
set_property(CACHE SPHERA_COLMAP_BASE PROPERTY STRINGS "3.10" "4")
if(NOT SPHERA_COLMAP_BASE MATCHES "^(3\\.10|4)$")
  message(FATAL_ERROR "SPHERA_COLMAP_BASE=${SPHERA_COLMAP_BASE}: expected 3.10 or 4")
endif()

set(SPHERA_COLMAP_EDITABLE_DIR "" CACHE PATH
    "Editable patched COLMAP checkout, used as is")
set(SPHERA_COLMAP_SOURCE_DIR "" CACHE PATH "Pristine COLMAP source tree of the base")
set(SPHERA_CACHE_DIR "$ENV{HOME}/.cache/sphera" CACHE PATH
    "Where verified source tarballs are kept between builds")
set(SPHERA_COLMAP_TARBALL "${SPHERA_CACHE_DIR}/colmap_3.10.orig.tar.gz"
    CACHE FILEPATH "COLMAP 3.10 upstream tarball")
set(SPHERA_COLMAP_SHA256
    "61850f323e201ab6a1abbfb0e4a8b3ba1c4cedbf55e0a5716bdea1df8ae1813a")

if(SPHERA_COLMAP_BASE STREQUAL "4")
  include(${CMAKE_CURRENT_LIST_DIR}/Colmap4Source.cmake)
  set(SPHERA_PATCH_DIR "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches4")
else()
  set(SPHERA_PATCH_DIR "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches")
endif()

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

# Sets `out_var` to the verified COLMAP 3.10 tarball, fetching it from
# Debian's source registry when absent.
function(sphera_colmap310_tarball out_var)
  set(tarball_ok FALSE)
  if(EXISTS "${SPHERA_COLMAP_TARBALL}")
    sphera_verify_sha256("${SPHERA_COLMAP_TARBALL}" "${SPHERA_COLMAP_SHA256}"
                         "SPHERA_COLMAP_TARBALL")
    set(tarball_ok TRUE)
  endif()
  if(NOT tarball_ok)
    message(STATUS "Fetching the COLMAP 3.10 source from Debian's registry")
    execute_process(
      COMMAND bash "${CMAKE_CURRENT_SOURCE_DIR}/scripts/fetch_colmap_source.sh"
              "${SPHERA_COLMAP_TARBALL}"
      RESULT_VARIABLE fetch_result)
    if(NOT fetch_result EQUAL 0)
      message(FATAL_ERROR "Could not obtain the COLMAP 3.10 source; pass "
                          "-DSPHERA_COLMAP_TARBALL=/path/to/colmap_3.10.orig.tar.gz")
    endif()
  endif()
  set(${out_var} "${SPHERA_COLMAP_TARBALL}" PARENT_SCOPE)
endfunction()

function(sphera_prepare_colmap_source out_var)
  # The source tarball is verified before anything is unpacked, so a missing
  # or damaged file leaves no half-prepared tree.
  set(tarball "")
  if(NOT SPHERA_COLMAP_EDITABLE_DIR AND NOT SPHERA_COLMAP_SOURCE_DIR)
    if(SPHERA_COLMAP_BASE STREQUAL "4")
      sphera_find_tarball(${SPHERA_COLMAP4_NAME} ${SPHERA_COLMAP4_SHA256}
                          SPHERA_COLMAP4_TARBALL tarball)
    else()
      sphera_colmap310_tarball(tarball)
    endif()
  endif()
  if(SPHERA_COLMAP_BASE STREQUAL "4")
    sphera_prepare_colmap4_dependencies()
  endif()
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
  if(SPHERA_STOCK_COLMAP)
    set(patches "")
  endif()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${patches} "${SPHERA_PATCH_DIR}")

  # The stamp names the base, the pristine source and every patch's content.
  set(stamp_text "base=${SPHERA_COLMAP_BASE}\nsource=${SPHERA_COLMAP_SOURCE_DIR}\n")
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
    # Another base or series: files of the old tree must not linger.
    if(NOT old_stamp MATCHES "^base=${SPHERA_COLMAP_BASE}\n")
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
    if(SPHERA_COLMAP_BASE STREQUAL "4")
      set(pristine_dir "${stage_dir}/${SPHERA_COLMAP4_NAME}")
    else()
      set(pristine_dir "${stage_dir}/colmap-3.10")
    endif()
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
