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

# The Simulink S-functions compiled for Windows as MATLAB would (the MEX build and the
# build for generated code) against the stand-in simstruc.h in integrations/simulink/harness
# (integrations/CMakeLists.txt has the same for Linux, where the harness also runs them).
# Only the compile is checked here; linking a MEX against libmex and running it in
# Simulink needs MATLAB.
set(_sl ${PROJECT_SOURCE_DIR}/integrations/simulink)
add_library(ccomm_sfun_mex OBJECT ${_sl}/sfun_ccomm_read.c ${_sl}/sfun_ccomm_write.c ${_sl}/ccomm_blk.c)
target_compile_definitions(ccomm_sfun_mex PRIVATE MATLAB_MEX_FILE)
add_library(ccomm_sfun_cg OBJECT ${_sl}/sfun_ccomm_read.c ${_sl}/sfun_ccomm_write.c)
foreach(t ccomm_sfun_mex ccomm_sfun_cg)
  target_include_directories(${t} PRIVATE ${_sl}/harness ${_sl} ${PROJECT_SOURCE_DIR}/src/include)
  set_target_properties(${t} PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
endforeach()
