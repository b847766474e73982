# Prepares the patched COLMAP source tree at configure time.
#
# The base is upstream COLMAP at commit 5d968cf (4.2.0.dev0, 2026-08-08) with
# the PoseLib and faiss sources it builds with (pins: cmake/ColmapPins.cmake);
# the patch series is colmap_ext/patches/.
#
# COLMAP source, in order of preference:
#   SPHERA_COLMAP_EDITABLE_DIR  an editable, already patched checkout
#                               (scripts/colmap_patches.sh checkout); used as is
#   SPHERA_COLMAP_SOURCE_DIR    a pristine COLMAP source tree of the base
#   the verified tarball colmap-5d968cf.tar.gz (see below)
#   a git checkout of the full commit SPHERA_COLMAP_GIT_COMMIT from
#   SPHERA_COLMAP_GIT_URL (default: COLMAP's public repository), kept in
#   SPHERA_CACHE_DIR; its HEAD must be that commit and its tree clean
# PoseLib and faiss, each in order of preference: its tarball
# (PoseLib-a69263d.tar.gz, faiss-1.14.1.tar.gz), else the archive upstream
# COLMAP pins, from SPHERA_POSELIB_URL / SPHERA_FAISS_URL, checked against
# SPHERA_POSELIB_URL_SHA256 / SPHERA_FAISS_URL_SHA256 (upstream's URL_HASH)
# and kept in SPHERA_CACHE_DIR/downloads.
# The patch series is applied in name order onto a staging copy; files are
# then copied into the live tree only when their content changed, so a changed
# patch rebuilds only what it touches.
#
# The three tarballs are looked up, in order, in SPHERA_PEERS_DIR (default:
# the folder shared/peers beside the repository, when present) and in
# SPHERA_CACHE_DIR; each can also be given on its own with
# SPHERA_COLMAP4_TARBALL, SPHERA_POSELIB_TARBALL and SPHERA_FAISS_TARBALL (a
# tarball given so must exist). A tarball found in SPHERA_PEERS_DIR is copied
# into SPHERA_CACHE_DIR (default ~/.cache/sphera) when that does not hold it
# yet, so that a later clone elsewhere on the machine finds it (a failed copy
# is only reported). Every tarball is checked against its pinned SHA-256
# before use; a damaged one stops the configuration with a message naming the
# file and the expected checksum. A build from the tarballs never touches the
# network. The tarballs are an offline snapshot: their PoseLib carries a
# stand-in for relpose_6pt_onesided_focal, so a build from the public
# repositories is the reference.
#
# Every download goes to a name ending in .partial and is renamed only once
# verified, so a failed or interrupted download leaves nothing half-unpacked
# and the next configuration retries. Sources that cannot be had are named in
# one message: where each was searched, what would be fetched from where, and
# the cache variable that overrides it.

include(${CMAKE_CURRENT_LIST_DIR}/ColmapPins.cmake)

set(SPHERA_COLMAP_EDITABLE_DIR "" CACHE PATH
    "Editable patched COLMAP checkout, used as is")
set(SPHERA_COLMAP_SOURCE_DIR "" CACHE PATH "Pristine COLMAP source tree of the base")
set(SPHERA_CACHE_DIR "$ENV{HOME}/.cache/sphera" CACHE PATH
    "Where verified source tarballs, checkouts and downloads are kept between builds")
set(SPHERA_PATCH_DIR "${CMAKE_CURRENT_SOURCE_DIR}/colmap_ext/patches")

set(SPHERA_COLMAP_GIT_URL "${SPHERA_COLMAP_PINNED_GIT_URL}" CACHE STRING
    "Git repository COLMAP is fetched from when no tarball is found")
set(SPHERA_COLMAP_GIT_COMMIT "${SPHERA_COLMAP_PINNED_COMMIT}" CACHE STRING
    "Full commit id fetched from SPHERA_COLMAP_GIT_URL (a mirror's own id)")
set(SPHERA_POSELIB_URL "${SPHERA_POSELIB_PINNED_URL}" CACHE STRING
    "PoseLib archive fetched when no PoseLib tarball is found")
set(SPHERA_POSELIB_URL_SHA256 "${SPHERA_POSELIB_PINNED_SHA256}" CACHE STRING
    "SHA-256 of the archive at SPHERA_POSELIB_URL")
set(SPHERA_FAISS_URL "${SPHERA_FAISS_PINNED_URL}" CACHE STRING
    "faiss archive fetched when no faiss tarball is found")
set(SPHERA_FAISS_URL_SHA256 "${SPHERA_FAISS_PINNED_SHA256}" CACHE STRING
    "SHA-256 of the archive at SPHERA_FAISS_URL")

set(SPHERA_COLMAP_COMMIT "5d968cf38aa2")
set(SPHERA_POSELIB_LABEL "PoseLib")
set(SPHERA_FAISS_LABEL "faiss")

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
# when set (it must exist), else the first of SPHERA_PEERS_DIR and
# SPHERA_CACHE_DIR holding it, else "". Sets `searched_var` to the places
# looked at. Verifies the SHA-256 of a tarball found. A tarball found in
# SPHERA_PEERS_DIR is also copied into SPHERA_CACHE_DIR when that does not
# hold it yet.
function(sphera_find_tarball name sha256 override out_var searched_var)
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
  string(REPLACE ";" ", " searched "${candidates}")
  set(${searched_var} "${searched}" PARENT_SCOPE)
  set(${out_var} "" PARENT_SCOPE)
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
  if(${override})
    message(FATAL_ERROR
      "${name}.tar.gz (SHA-256 ${sha256}) not found; searched: ${searched}. "
      "Put it in ${SPHERA_CACHE_DIR} or pass -D${override}=/path/${name}.tar.gz "
      "(the COLMAP source is commit ${SPHERA_COLMAP_COMMIT} of COLMAP's public "
      "repository).")
  endif()
endfunction()

# Runs git with `ARGN` in `dir`, never prompting for credentials; sets
# `result_var` to its exit code and `output_var` to its output, stripped.
function(sphera_git dir result_var output_var)
  execute_process(
    COMMAND "${CMAKE_COMMAND}" -E env GIT_TERMINAL_PROMPT=0
            "${GIT_EXECUTABLE}" ${ARGN}
    WORKING_DIRECTORY "${dir}" TIMEOUT 3600
    RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_STRIP_TRAILING_WHITESPACE)
  set(${result_var} "${result}" PARENT_SCOPE)
  set(${output_var} "${output}" PARENT_SCOPE)
endfunction()

# Stops the configuration unless the git checkout `dir` has HEAD at
# SPHERA_COLMAP_GIT_COMMIT and no changed tracked file: the commit id is what
# authenticates the source.
function(sphera_verify_colmap_checkout dir)
  sphera_git("${dir}" result head rev-parse HEAD)
  if(NOT result EQUAL 0 OR NOT head STREQUAL SPHERA_COLMAP_GIT_COMMIT)
    message(FATAL_ERROR "${dir}: HEAD is '${head}', expected COLMAP commit "
                        "${SPHERA_COLMAP_GIT_COMMIT}. Remove the folder; the "
                        "next configuration fetches the commit again.")
  endif()
  sphera_git("${dir}" result changes status --porcelain --untracked-files=no)
  if(NOT result EQUAL 0 OR NOT changes STREQUAL "")
    message(FATAL_ERROR "${dir}: the checkout of COLMAP commit "
                        "${SPHERA_COLMAP_GIT_COMMIT} has changes:\n${changes}\n"
                        "Remove the folder; the next configuration fetches the "
                        "commit again.")
  endif()
endfunction()

# Sets `out_var` to a verified checkout of COLMAP commit
# SPHERA_COLMAP_GIT_COMMIT: the one kept in SPHERA_CACHE_DIR, else one fetched
# from SPHERA_COLMAP_GIT_URL into a .partial folder, verified and renamed.
# On a failed fetch sets `out_var` to "" and `error_var` to git's message.
function(sphera_fetch_colmap_git out_var error_var)
  set(${out_var} "" PARENT_SCOPE)
  set(${error_var} "" PARENT_SCOPE)
  set(commit "${SPHERA_COLMAP_GIT_COMMIT}")
  string(LENGTH "${commit}" commit_length)
  if(NOT commit MATCHES "^[0-9a-f]+$" OR NOT commit_length EQUAL 40)
    message(FATAL_ERROR "SPHERA_COLMAP_GIT_COMMIT='${commit}' is not a full "
                        "40-digit commit id; only the full id authenticates "
                        "the source (COLMAP's is ${SPHERA_COLMAP_PINNED_COMMIT}).")
  endif()
  set(checkout "${SPHERA_CACHE_DIR}/colmap-${commit}")
  find_package(Git QUIET)
  if(EXISTS "${checkout}")
    if(NOT GIT_FOUND)
      message(FATAL_ERROR "git is needed to verify ${checkout}")
    endif()
    sphera_verify_colmap_checkout("${checkout}")
    set(${out_var} "${checkout}" PARENT_SCOPE)
    return()
  endif()
  if(NOT GIT_FOUND)
    set(${error_var} "git is not installed" PARENT_SCOPE)
    return()
  endif()

  set(partial "${checkout}.partial")
  file(REMOVE_RECURSE "${partial}")
  file(MAKE_DIRECTORY "${partial}")
  message(STATUS "Fetching COLMAP commit ${commit} from ${SPHERA_COLMAP_GIT_URL}")
  sphera_git("${partial}" result output init --quiet)
  if(result EQUAL 0)
    sphera_git("${partial}" result output
               fetch --quiet --depth 1 "${SPHERA_COLMAP_GIT_URL}" "${commit}")
    if(NOT result EQUAL 0)
      # A server that does not serve a commit by its id: all branches and
      # tags, then the commit among them.
      sphera_git("${partial}" result branches_output
                 fetch --quiet "${SPHERA_COLMAP_GIT_URL}"
                 "+refs/heads/*:refs/remotes/origin/*" "+refs/tags/*:refs/tags/*")
      if(result EQUAL 0)
        sphera_git("${partial}" result branches_output
                   cat-file -e "${commit}^{commit}")
        if(NOT result EQUAL 0)
          set(branches_output "the commit is on none of its branches and tags")
        endif()
      endif()
      string(APPEND output " / ${branches_output}")
    endif()
  endif()
  if(result EQUAL 0)
    sphera_git("${partial}" result output
               -c advice.detachedHead=false checkout --quiet "${commit}")
  endif()
  if(NOT result EQUAL 0)
    file(REMOVE_RECURSE "${partial}")
    string(REGEX REPLACE "[\r\n]+" " " output "${output}")
    set(${error_var} "${output}" PARENT_SCOPE)
    return()
  endif()
  sphera_git("${partial}" result head rev-parse HEAD)
  if(NOT head STREQUAL commit)
    file(REMOVE_RECURSE "${partial}")
    message(FATAL_ERROR "${SPHERA_COLMAP_GIT_URL} gave commit '${head}' for "
                        "COLMAP commit ${commit}; refused.")
  endif()
  file(RENAME "${partial}" "${checkout}")
  set(${out_var} "${checkout}" PARENT_SCOPE)
endfunction()

# Sets `out_var` to the archive of `dep` (POSELIB or FAISS) that
# SPHERA_<dep>_URL names, verified against SPHERA_<dep>_URL_SHA256: the copy
# kept in SPHERA_CACHE_DIR/downloads, else a download to a .partial file that
# is renamed once verified. On failure sets `out_var` to "" and `error_var` to
# the reason.
function(sphera_download_dependency dep out_var error_var)
  set(${out_var} "" PARENT_SCOPE)
  set(${error_var} "" PARENT_SCOPE)
  set(url "${SPHERA_${dep}_URL}")
  set(sha256 "${SPHERA_${dep}_URL_SHA256}")
  string(TOLOWER "${sha256}" sha256)
  get_filename_component(base "${url}" NAME)
  set(archive "${SPHERA_CACHE_DIR}/downloads/${SPHERA_${dep}_LABEL}-${base}")
  if(EXISTS "${archive}")
    file(SHA256 "${archive}" actual)
    if(actual STREQUAL sha256)
      set(${out_var} "${archive}" PARENT_SCOPE)
      return()
    endif()
    message(STATUS "${archive} has SHA-256 ${actual}, not ${sha256}; fetching it again")
    file(REMOVE "${archive}")
  endif()
  set(partial "${archive}.partial")
  file(MAKE_DIRECTORY "${SPHERA_CACHE_DIR}/downloads")
  message(STATUS "Fetching ${SPHERA_${dep}_LABEL} from ${url}")
  file(DOWNLOAD "${url}" "${partial}" STATUS status INACTIVITY_TIMEOUT 120
       TLS_VERIFY ON)
  list(GET status 0 code)
  if(NOT code EQUAL 0)
    list(GET status 1 reason)
    file(REMOVE "${partial}")
    set(${error_var} "download failed: ${reason}" PARENT_SCOPE)
    return()
  endif()
  file(SHA256 "${partial}" actual)
  if(NOT actual STREQUAL sha256)
    file(REMOVE "${partial}")
    set(${error_var} "the download has SHA-256 ${actual}, expected ${sha256} (not the pinned archive, removed)"
        PARENT_SCOPE)
    return()
  endif()
  file(RENAME "${partial}" "${archive}")
  set(${out_var} "${archive}" PARENT_SCOPE)
endfunction()

# Unpacks `archive`, which holds a single top-level folder with a
# CMakeLists.txt, to `source_dir` by way of a .partial folder.
function(sphera_unpack_dependency archive source_dir)
  set(partial "${source_dir}.partial")
  file(REMOVE_RECURSE "${partial}")
  file(ARCHIVE_EXTRACT INPUT "${archive}" DESTINATION "${partial}")
  file(GLOB top_level "${partial}/*")
  list(LENGTH top_level count)
  if(NOT count EQUAL 1 OR NOT EXISTS "${top_level}/CMakeLists.txt")
    file(REMOVE_RECURSE "${partial}")
    message(FATAL_ERROR "${archive} does not unpack to a single source folder "
                        "with a CMakeLists.txt")
  endif()
  file(RENAME "${top_level}" "${source_dir}")
  file(REMOVE_RECURSE "${partial}")
endfunction()

# Finds the source of `dep` (POSELIB or FAISS) without unpacking anything:
# sets SPHERA_<dep>_SOURCE_DIR (where its tree is or will be),
# SPHERA_<dep>_ARCHIVE (what to unpack there, "" when it is there already)
# and SPHERA_<dep>_SOURCE_ID (which archive the tree comes from) in the
# caller's scope, or appends to the list `errors_var` why it cannot be had.
# The tarball of the snapshot comes first, then upstream's archive. Either is
# unpacked to the same folder, colmap4-deps/<label>, whose stamp names the
# archive: the objects' paths do not depend on where a source came from, so
# that ccache serves a build from the mirrors of the public hosts with the
# objects of a build from the tarballs, and the other way round.
function(sphera_find_dependency dep errors_var)
  set(source_dir "${CMAKE_BINARY_DIR}/colmap4-deps/${SPHERA_${dep}_LABEL}")
  set(name ${SPHERA_${dep}_NAME})
  string(TOLOWER "${SPHERA_${dep}_URL_SHA256}" url_sha256)
  set(archive "")
  sphera_find_tarball(${name} ${SPHERA_${dep}_SHA256} SPHERA_${dep}_TARBALL
                      archive searched)
  if(archive)
    set(source_id "${name}.tar.gz ${SPHERA_${dep}_SHA256}")
  else()
    set(source_id "${SPHERA_${dep}_URL} ${url_sha256}")
    sphera_read_dependency_stamp("${source_dir}" unpacked_id)
    if(NOT unpacked_id STREQUAL source_id)
      sphera_download_dependency(${dep} archive error)
      if(NOT archive)
        set(errors "${${errors_var}}")
        string(APPEND errors
          "\n  ${SPHERA_${dep}_LABEL}\n"
          "    tarball ${name}.tar.gz not in: ${searched}\n"
          "    fetch: ${SPHERA_${dep}_URL} (SHA-256 ${SPHERA_${dep}_URL_SHA256})\n"
          "    failed: ${error}\n"
          "    override: -DSPHERA_${dep}_URL=<mirror> (with "
          "-DSPHERA_${dep}_URL_SHA256=<its sum>) or "
          "-DSPHERA_${dep}_TARBALL=/path/${name}.tar.gz")
        set(${errors_var} "${errors}" PARENT_SCOPE)
      endif()
    endif()
  endif()
  set(SPHERA_${dep}_SOURCE_DIR "${source_dir}" PARENT_SCOPE)
  set(SPHERA_${dep}_ARCHIVE "${archive}" PARENT_SCOPE)
  set(SPHERA_${dep}_SOURCE_ID "${source_id}" PARENT_SCOPE)
endfunction()

# Sets `out_var` to the archive a dependency's tree in `source_dir` was
# unpacked from ("" when there is no complete tree).
function(sphera_read_dependency_stamp source_dir out_var)
  set(id "")
  if(EXISTS "${source_dir}.stamp" AND EXISTS "${source_dir}/CMakeLists.txt")
    file(READ "${source_dir}.stamp" id)
    string(STRIP "${id}" id)
  endif()
  set(${out_var} "${id}" PARENT_SCOPE)
endfunction()

# PoseLib and faiss, unpacked into the build tree (a stable path, so that
# ccache hits across clones and sources) unless the tree there comes from the
# same archive, and consumed by COLMAP's FetchContent without a network.
function(sphera_unpack_colmap_dependencies)
  foreach(dep POSELIB FAISS)
    set(source_dir "${SPHERA_${dep}_SOURCE_DIR}")
    sphera_read_dependency_stamp("${source_dir}" unpacked_id)
    if(NOT unpacked_id STREQUAL SPHERA_${dep}_SOURCE_ID)
      file(REMOVE "${source_dir}.stamp")
      file(REMOVE_RECURSE "${source_dir}")
      sphera_unpack_dependency("${SPHERA_${dep}_ARCHIVE}" "${source_dir}")
      file(WRITE "${source_dir}.stamp" "${SPHERA_${dep}_SOURCE_ID}\n")
    endif()
    message(STATUS "${SPHERA_${dep}_LABEL} source: ${source_dir} "
                   "(${SPHERA_${dep}_SOURCE_ID})")
    set(FETCHCONTENT_SOURCE_DIR_${dep} "${source_dir}" CACHE PATH "" FORCE)
  endforeach()
  set(FETCHCONTENT_FULLY_DISCONNECTED ON CACHE BOOL "" FORCE)
  set(ONNX_ENABLED OFF CACHE BOOL "" FORCE)
  set(DOWNLOAD_ENABLED OFF CACHE BOOL "" FORCE)
endfunction()

function(sphera_prepare_colmap_source out_var)
  # Every source is found, fetched and verified before anything is unpacked
  # into the build tree, so a missing or damaged source leaves no
  # half-prepared tree; all missing sources are named in one message.
  set(errors "")
  set(tarball "")
  set(git_checkout "")
  if(NOT SPHERA_COLMAP_EDITABLE_DIR AND NOT SPHERA_COLMAP_SOURCE_DIR)
    sphera_find_tarball(${SPHERA_COLMAP_NAME} ${SPHERA_COLMAP_SHA256}
                        SPHERA_COLMAP4_TARBALL tarball searched)
    if(NOT tarball)
      sphera_fetch_colmap_git(git_checkout error)
      if(NOT git_checkout)
        string(APPEND errors
          "\n  COLMAP\n"
          "    tarball ${SPHERA_COLMAP_NAME}.tar.gz not in: ${searched}\n"
          "    fetch: commit ${SPHERA_COLMAP_GIT_COMMIT} of ${SPHERA_COLMAP_GIT_URL} (git)\n"
          "    failed: ${error}\n"
          "    override: -DSPHERA_COLMAP_GIT_URL=<mirror> or "
          "-DSPHERA_COLMAP4_TARBALL=/path/${SPHERA_COLMAP_NAME}.tar.gz")
      endif()
    endif()
  endif()
  foreach(dep POSELIB FAISS)
    sphera_find_dependency(${dep} errors)
    set(SPHERA_${dep}_SOURCE_DIR "${SPHERA_${dep}_SOURCE_DIR}" PARENT_SCOPE)
    set(SPHERA_${dep}_ARCHIVE "${SPHERA_${dep}_ARCHIVE}" PARENT_SCOPE)
  endforeach()
  if(errors)
    message(FATAL_ERROR
      "Sources of the build that could not be had (no tarball, and the "
      "network or the mirror did not deliver):${errors}\nTarballs are "
      "searched in SPHERA_PEERS_DIR and SPHERA_CACHE_DIR; nothing was "
      "unpacked, the next configuration tries again.")
  endif()
  sphera_unpack_colmap_dependencies()
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
  set(source "${SPHERA_COLMAP_SOURCE_DIR}")
  if(git_checkout)
    set(source "git ${SPHERA_COLMAP_GIT_COMMIT}")
  endif()
  set(stamp_text "base=4\nsource=${source}\n")
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
  if(SPHERA_COLMAP_SOURCE_DIR OR git_checkout)
    set(pristine_source "${SPHERA_COLMAP_SOURCE_DIR}")
    if(git_checkout)
      set(pristine_source "${git_checkout}")
    endif()
    if(NOT EXISTS "${pristine_source}/src/colmap/sensor/models.h")
      message(FATAL_ERROR "${pristine_source} is not a COLMAP source tree")
    endif()
    file(COPY "${pristine_source}/" DESTINATION "${stage_dir}/colmap"
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
