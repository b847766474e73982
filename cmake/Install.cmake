# Installation and the Debian package.
#
#   cmake --install build [--prefix DIR]    colmap (with SPHERA's commands),
#                                           sphera_render and sphera_demo in
#                                           DIR/bin (default /usr/local)
#   cd build && cpack -G DEB                sphera_<version>_<arch>.deb, the
#                                           same files under /usr
#
# COLMAP's own install rules (headers, static libraries, CMake package files)
# never run: its folder is added with EXCLUDE_FROM_ALL, and SPHERA installs
# only the programs a user runs. Every library of the build is static, so the
# installed programs need no RPATH; they link only the system's shared
# libraries, from which the package's Depends are made (dpkg-shlibdeps).
if(NOT SPHERA_BUILD_COLMAP)
  return()
endif()
include(GNUInstallDirs)

# A prefix that cannot be written fails before any file is copied, with a
# message that says what to do instead of CMake's "cannot make directory".
install(CODE [[
  set(sphera_prefix "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}")
  execute_process(
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${sphera_prefix}/bin"
    RESULT_VARIABLE sphera_result OUTPUT_QUIET ERROR_VARIABLE sphera_error)
  if(sphera_result EQUAL 0)
    execute_process(
      COMMAND "${CMAKE_COMMAND}" -E touch "${sphera_prefix}/bin/.sphera-install-check"
      RESULT_VARIABLE sphera_result OUTPUT_QUIET ERROR_VARIABLE sphera_error)
    file(REMOVE "${sphera_prefix}/bin/.sphera-install-check")
  endif()
  if(NOT sphera_result EQUAL 0)
    string(STRIP "${sphera_error}" sphera_error)
    message(FATAL_ERROR
      "SPHERA cannot be installed into ${sphera_prefix}: ${sphera_prefix}/bin "
      "is not a folder this user can write (${sphera_error}). Install as root "
      "(sudo cmake --install BUILD_DIR) or into a folder of yours "
      "(cmake --install BUILD_DIR --prefix ~/.local).")
  endif()
]])

# COLMAP sets an install RPATH of $ORIGIN/../lib for its shared-library
# builds; with static libraries it would only point the program at whatever
# lies there.
set_target_properties(colmap_main sphera_render PROPERTIES INSTALL_RPATH "")
install(TARGETS colmap_main sphera_render
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(PROGRAMS scripts/demo.sh DESTINATION ${CMAKE_INSTALL_BINDIR}
        RENAME sphera_demo)
install(FILES README.md CHANGELOG.md
        DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/sphera)

# The package version: upstream COLMAP's, then SPHERA's last commit date, so
# that a later build is an upgrade.
set(SPHERA_PACKAGE_DATE "0")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(
    COMMAND "${GIT_EXECUTABLE}" log -1 --format=%cd --date=format:%Y%m%d%H%M
    WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}"
    RESULT_VARIABLE git_result OUTPUT_VARIABLE git_date
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(git_result EQUAL 0 AND git_date MATCHES "^[0-9]+$")
    set(SPHERA_PACKAGE_DATE "${git_date}")
  endif()
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME sphera)
set(CPACK_PACKAGE_VERSION "4.2.0~dev0+sphera${SPHERA_PACKAGE_DATE}")
set(CPACK_PACKAGE_VENDOR "SPHERA")
set(CPACK_PACKAGE_CONTACT "SPHERA maintainers <sphera@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "COLMAP in which every central camera is a camera on the unit sphere")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
    "Upstream COLMAP 4.x with 360-degree panoramas, fisheye lenses beyond\n"
    "180 degrees, catadioptric cameras and rigs of them in the same colmap\n"
    "command line, plus a ground-truth renderer (sphera_render) and a demo\n"
    "(sphera_demo). Command line only, CPU only.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# sqlite3: the demo's counts; not a library the programs link.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "sqlite3")
# The user's `colmap` is SPHERA's: it takes the place of Debian's package.
set(CPACK_DEBIAN_PACKAGE_CONFLICTS colmap)
set(CPACK_DEBIAN_PACKAGE_PROVIDES colmap)
set(CPACK_DEBIAN_PACKAGE_REPLACES colmap)
include(CPack)
