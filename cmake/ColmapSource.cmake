# Prepares the patched COLMAP 3.10 source tree at configure time.
#
# Source, in order of preference:
#   SPHERA_COLMAP_EDITABLE_DIR  an editable, already patched checkout
#                               (scripts/colmap_patches.sh checkout); used as is
#   SPHERA_COLMAP_SOURCE_DIR    a pristine COLMAP 3.10 source tree
#   SPHERA_COLMAP_TARBALL       colmap_3.10.orig.tar.gz (SHA-256 checked);
#                               fetched from Debian's source registry into
#                               SPHERA_CACHE_DIR when absent
# The patch series colmap_ext/patches/*.patch is applied in name order onto a
# staging copy; files are then copied into the live tree only when their
# content changed, so a changed patch rebuilds only what it touches.

set(SPHERA_COLMAP_EDITABLE_DIR "" CACHE PATH
    "Editable patched COLMAP checkout, used as is")
set(SPHERA_COLMAP_SOURCE_DIR "" CACHE PATH "Pristine COLMAP 3.10 source tree")
set(SPHERA_CACHE_DIR "$ENV{HOME}/.cache/sphera" CACHE PATH
    "Where the verified COLMAP tarball is kept between builds")
set(SPHERA_COLMAP_TARBALL "${SPHERA_CACHE_DIR}/colmap_3.10.orig.tar.gz"
    CACHE FILEPATH "COLMAP 3.10 upstream tarball")
set(SPHERA_COLMAP_SHA256
    "61850f323e201ab6a1abbfb0e4a8b3ba1c4cedbf55e0a5716bdea1df8ae1813a")

function(sphera_prepare_colmap_source out_var)
  if(SPHERA_COLMAP_EDITABLE_DIR)
    if(NOT EXISTS "${SPHERA_COLMAP_EDITABLE_DIR}/src/colmap/sensor/models.h")
      message(FATAL_ERROR "SPHERA_COLMAP_EDITABLE_DIR=${SPHERA_COLMAP_EDITABLE_DIR} "
                          "is not a COLMAP source tree")
    endif()
    set(${out_var} "${SPHERA_COLMAP_EDITABLE_DIR}" PARENT_SCOPE)
    return()
  endif()

  file(GLOB patches "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches/*.patch")
  list(SORT patches)
  if(SPHERA_STOCK_COLMAP)
    set(patches "")
  endif()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${patches} "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches")

  # The stamp names the pristine source and every patch's content.
  set(stamp_text "source=${SPHERA_COLMAP_SOURCE_DIR}\n")
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
  endif()

  set(stage_dir "${CMAKE_BINARY_DIR}/colmap-stage")
  file(REMOVE_RECURSE "${stage_dir}")
  file(MAKE_DIRECTORY "${stage_dir}")
  if(SPHERA_COLMAP_SOURCE_DIR)
    if(NOT EXISTS "${SPHERA_COLMAP_SOURCE_DIR}/src/colmap/sensor/models.h")
      message(FATAL_ERROR "SPHERA_COLMAP_SOURCE_DIR=${SPHERA_COLMAP_SOURCE_DIR} "
                          "is not a COLMAP source tree")
    endif()
    file(COPY "${SPHERA_COLMAP_SOURCE_DIR}/" DESTINATION "${stage_dir}/colmap-3.10"
         PATTERN ".git" EXCLUDE)
  else()
    set(tarball_ok FALSE)
    if(EXISTS "${SPHERA_COLMAP_TARBALL}")
      file(SHA256 "${SPHERA_COLMAP_TARBALL}" tarball_hash)
      if(tarball_hash STREQUAL SPHERA_COLMAP_SHA256)
        set(tarball_ok TRUE)
      else()
        message(FATAL_ERROR "SPHERA_COLMAP_TARBALL=${SPHERA_COLMAP_TARBALL} has "
                            "SHA-256 ${tarball_hash}, expected ${SPHERA_COLMAP_SHA256}")
      endif()
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
    file(ARCHIVE_EXTRACT INPUT "${SPHERA_COLMAP_TARBALL}" DESTINATION "${stage_dir}")
  endif()

  find_program(PATCH_PROGRAM patch REQUIRED)
  foreach(patch ${patches})
    execute_process(
      COMMAND "${PATCH_PROGRAM}" -p1 --batch --forward --quiet -i "${patch}"
      WORKING_DIRECTORY "${stage_dir}/colmap-3.10"
      RESULT_VARIABLE patch_result OUTPUT_VARIABLE patch_output
      ERROR_VARIABLE patch_output)
    if(NOT patch_result EQUAL 0)
      message(FATAL_ERROR "Patch ${patch} does not apply:\n${patch_output}")
    endif()
  endforeach()

  # configure_file(COPYONLY) leaves a file untouched when its content is the
  # same, which keeps the build incremental.
  file(GLOB_RECURSE staged_files RELATIVE "${stage_dir}/colmap-3.10"
       "${stage_dir}/colmap-3.10/*")
  foreach(relative_path ${staged_files})
    configure_file("${stage_dir}/colmap-3.10/${relative_path}"
                   "${live_dir}/${relative_path}" COPYONLY)
  endforeach()
  file(REMOVE_RECURSE "${stage_dir}")
  file(WRITE "${stamp_file}" "${stamp_text}")
  set(${out_var} "${live_dir}" PARENT_SCOPE)
endfunction()
