# SPDX-License-Identifier: Apache-2.0
# The Windows build (docs/install.md "Windows"): libccomm as ccomm.dll with its import
# library, and the unit tests that apply to a PC, built with GoogleTest from source
# (Debian's googletest package ships it in /usr/src/googletest; GTEST_SOURCE_DIR
# elsewhere). No libsystemd, no libsodium, no raw Ethernet on Windows.
set(CCOMM_WITH_SYSTEMD OFF)
set(CCOMM_WITH_SODIUM OFF)
if(CCOMM_BUILD_TESTS)
  set(GTEST_SOURCE_DIR /usr/src/googletest CACHE PATH "GoogleTest sources (built with this toolchain)")
  set(gtest_force_shared_crt ON CACHE BOOL "" FORCE)
  set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
  set(BUILD_GMOCK OFF CACHE BOOL "" FORCE)
  add_subdirectory(${GTEST_SOURCE_DIR} ${CMAKE_BINARY_DIR}/googletest EXCLUDE_FROM_ALL SYSTEM)
  add_library(GTest::gtest ALIAS gtest)
  add_library(GTest::gtest_main ALIAS gtest_main)
  enable_testing()
endif()
add_subdirectory(src)
