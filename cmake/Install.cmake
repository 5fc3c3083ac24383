# SPDX-License-Identifier: Apache-2.0
# CMake package configuration, so that an installed libccomm is found with
#   find_package(ccomm 0.1 REQUIRED)
#   target_link_libraries(app PRIVATE ccomm::ccomm)
# Installed to LIBDIR/cmake/ccomm/ beside LIBDIR/pkgconfig/ccomm.pc. The config file
# declares the imported target itself (paths relative to where it is installed, so the
# tree can be relocated) instead of exporting the build target: the build target's
# include directories point into the source tree, which an install must not carry.
include(CMakePackageConfigHelpers)

set(CCOMM_CMAKE_CONFIG_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/ccomm" CACHE STRING
    "Where ccommConfig.cmake is installed (relative to the prefix)")
# Used by ccommConfig.cmake.in through PATH_VARS (made relative to the installed file).
set(CCOMM_CONFIG_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
set(CCOMM_CONFIG_LIBDIR "${CMAKE_INSTALL_LIBDIR}")

configure_package_config_file(
  ${CMAKE_CURRENT_LIST_DIR}/ccommConfig.cmake.in
  ${CMAKE_BINARY_DIR}/cmake/ccommConfig.cmake
  INSTALL_DESTINATION ${CCOMM_CMAKE_CONFIG_DIR}
  PATH_VARS CCOMM_CONFIG_INCLUDEDIR CCOMM_CONFIG_LIBDIR)
# 0.x: a new minor version may change the API, so only the same minor version matches.
write_basic_package_version_file(
  ${CMAKE_BINARY_DIR}/cmake/ccommConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/ccommConfig.cmake ${CMAKE_BINARY_DIR}/cmake/ccommConfigVersion.cmake
        DESTINATION ${CCOMM_CMAKE_CONFIG_DIR})
