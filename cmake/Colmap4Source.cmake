# The upstream COLMAP 4.x base: COLMAP at commit 5d968cf (4.2.0.dev0,
# 2026-08-08) with the PoseLib and faiss sources it builds with.
#
# The three tarballs are looked up, in order, in SPHERA_PEERS_DIR (default: the
# folder shared/peers beside the repository, when present) and in
# SPHERA_CACHE_DIR; each can also be given on its own with
# SPHERA_COLMAP4_TARBALL, SPHERA_POSELIB_TARBALL and SPHERA_FAISS_TARBALL.
# Every tarball is checked against its pinned SHA-256 before use, and a
# missing or damaged one stops the configuration with a message naming the
# file and the expected checksum. Nothing is downloaded: the build needs no
# network when the tarballs are present. The commit id names the same source
# in COLMAP's public repository.

set(SPHERA_COLMAP4_COMMIT "5d968cf38aa2")
set(SPHERA_COLMAP4_NAME "colmap-5d968cf")
set(SPHERA_COLMAP4_SHA256
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
if(EXISTS "${_sphera_shared_peers}/${SPHERA_COLMAP4_NAME}.tar.gz")
  set(_sphera_default_peers "${_sphera_shared_peers}")
endif()
set(SPHERA_PEERS_DIR "${_sphera_default_peers}" CACHE PATH
    "Folder with colmap-5d968cf, PoseLib-a69263d and faiss-1.14.1 tarballs")

# Sets `out_var` to the tarball `name`.tar.gz: the cache variable `override`
# when set, else the first of SPHERA_PEERS_DIR and SPHERA_CACHE_DIR holding it.
# Verifies its SHA-256.
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
      set(${out_var} "${candidate}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  string(REPLACE ";" ", " searched "${candidates}")
  message(FATAL_ERROR
    "${name}.tar.gz (SHA-256 ${sha256}) not found; searched: ${searched}. "
    "Put it in ${SPHERA_CACHE_DIR} or pass -D${override}=/path/${name}.tar.gz "
    "(the COLMAP source is commit ${SPHERA_COLMAP4_COMMIT} of COLMAP's public "
    "repository).")
endfunction()

set(SPHERA_COLMAP4_TARBALL "" CACHE FILEPATH "colmap-5d968cf.tar.gz")
set(SPHERA_POSELIB_TARBALL "" CACHE FILEPATH "PoseLib-a69263d.tar.gz")
set(SPHERA_FAISS_TARBALL "" CACHE FILEPATH "faiss-1.14.1.tar.gz")

# PoseLib and faiss, unpacked once into the build tree (a stable path, so that
# ccache hits across clones) and consumed by COLMAP's FetchContent without a
# network.
function(sphera_prepare_colmap4_dependencies)
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
