# SPDX-License-Identifier: Apache-2.0
# The Windows build's targets (included by src/CMakeLists.txt when WIN32): the same
# sources as on Linux, with the platform layer's Windows unit (common/CMakeLists.txt).
add_subdirectory(common)
add_subdirectory(wire)

set(_st ${CMAKE_CURRENT_LIST_DIR}/store)
add_library(ccomm_store STATIC ${_st}/segment.cpp ${_st}/reclaim.cpp ${_st}/view.cpp)
ccomm_core_target(ccomm_store)
target_link_libraries(ccomm_store PUBLIC ccomm_platform)

set(_cfg ${CMAKE_CURRENT_LIST_DIR}/config)
include(${_cfg}/sources.cmake)
list(TRANSFORM CCOMM_CONFIG_SOURCES PREPEND ${_cfg}/)
add_library(ccomm_config STATIC ${CCOMM_CONFIG_SOURCES})
ccomm_core_target(ccomm_config)
target_link_libraries(ccomm_config PUBLIC ccomm_platform)
# The build machine's /usr/include holds RapidXML: searched after MinGW's own headers.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(ccomm_config PRIVATE -idirafter ${RAPIDXML_INCLUDE_DIR})
else()
  target_include_directories(ccomm_config SYSTEM PRIVATE ${RAPIDXML_INCLUDE_DIR})
endif()

add_library(ccomm_segment_builder STATIC daemon/engine/segment_builder.cpp)
ccomm_core_target(ccomm_segment_builder)
target_link_libraries(ccomm_segment_builder PUBLIC ccomm_store ccomm_config)

set(_cl ${CMAKE_CURRENT_LIST_DIR}/client)
add_library(ccomm SHARED ${_cl}/client.cpp ${_cl}/client_open.cpp ${_cl}/client_info.cpp ${_cl}/client_realtime.cpp ${_cl}/history.cpp
            ${_cl}/system_view_reader.cpp ${_cl}/doorbell_futex.cpp)
ccomm_core_target(ccomm)
target_compile_definitions(ccomm PRIVATE CCOMM_BUILDING_DLL)
target_link_libraries(ccomm PRIVATE ccomm_store)
# ccomm.dll and its import library libccomm.dll.a (ccomm.lib for MSVC); only the
# CCOMM_API functions are exported (__declspec(dllexport) in ccomm.h).
set_target_properties(ccomm PROPERTIES PREFIX "" C_VISIBILITY_PRESET hidden CXX_VISIBILITY_PRESET hidden)
install(TARGETS ccomm RUNTIME DESTINATION bin LIBRARY DESTINATION lib ARCHIVE DESTINATION lib)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/include/ccomm/ccomm.h ${CMAKE_CURRENT_LIST_DIR}/include/ccomm/ccomm.hpp
        DESTINATION include/ccomm)

# ccommd.exe: the daemon with the Windows units of its platform code (daemon/sources.cmake);
# UDP only (raw Ethernet is Linux-only), no libsodium, no systemd.
set(_dm ${CMAKE_CURRENT_LIST_DIR}/daemon)
include(${_dm}/sources.cmake)
list(TRANSFORM CCOMM_DAEMON_SOURCES PREPEND ${_dm}/)
list(TRANSFORM CCOMM_DAEMON_WINDOWS_SOURCES PREPEND ${_dm}/)
add_library(ccomm_daemon STATIC ${CCOMM_DAEMON_SOURCES} ${CCOMM_DAEMON_WINDOWS_SOURCES}
            ${_dm}/security/auth_crypto_none.cpp ${_dm}/service/sd_notify_none.cpp)
ccomm_core_target(ccomm_daemon)
target_link_libraries(ccomm_daemon PUBLIC ccomm_segment_builder ccomm_store ccomm_wire ccomm_config ccomm_platform
                      iphlpapi ws2_32)
add_executable(ccommd ${_dm}/service/main.cpp)
ccomm_core_target(ccommd)
target_compile_definitions(ccommd PRIVATE CCOMM_VERSION="${PROJECT_VERSION}")
target_link_libraries(ccommd PRIVATE ccomm_daemon)
install(TARGETS ccommd RUNTIME DESTINATION bin)

# ccomm.exe, the command line tool, and ccomm-latency.exe, against ccomm.dll.
set(_cli ${CMAKE_CURRENT_LIST_DIR}/cli)
add_executable(ccomm_cli ${_cli}/main.cpp ${_cli}/stats.cpp ${_cli}/stats_all.cpp ${_cli}/values.cpp
               ${_cli}/external_windows.cpp)
set_target_properties(ccomm_cli PROPERTIES OUTPUT_NAME ccomm)
ccomm_core_target(ccomm_cli)
target_compile_definitions(ccomm_cli PRIVATE CCOMM_DATADIR="share/ccomm")
target_link_libraries(ccomm_cli PRIVATE ccomm ccomm_config ccomm_platform_app)
install(TARGETS ccomm_cli RUNTIME DESTINATION bin)
add_executable(ccomm-latency ${CMAKE_CURRENT_LIST_DIR}/tools/latency.cpp)
target_include_directories(ccomm-latency PRIVATE ${PROJECT_SOURCE_DIR}/src)
target_link_libraries(ccomm-latency PRIVATE ccomm ccomm_platform_app Threads::Threads)
install(TARGETS ccomm-latency RUNTIME DESTINATION bin)

# The unit tests that apply to a PC: the ones of the modules above that need no Linux
# sockets or daemon (tests/windows/run runs them under Wine).
if(CCOMM_BUILD_TESTS)
  foreach(_t state_slot_test single_writer_test event_ring_test)
    ccomm_test(${_t} store/${_t}.cpp)
  endforeach()
  target_link_libraries(event_ring_test PRIVATE ccomm_segment_builder)
  target_link_libraries(state_slot_test PRIVATE ccomm_segment_builder)
  ccomm_test(config_errors_test config/config_errors_test.cpp)
  target_link_libraries(config_errors_test PRIVATE ccomm_config)
  target_compile_definitions(config_errors_test PRIVATE CCOMM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

# The test stand-in for ccommd.exe (tests/windows/segment_host.cpp).
if(CCOMM_BUILD_TESTS)
  add_executable(segment_host ${PROJECT_SOURCE_DIR}/tests/windows/segment_host.cpp)
  ccomm_core_target(segment_host)
  target_link_libraries(segment_host PRIVATE ccomm_segment_builder)
endif()

# find_package(ccomm) for the zip (cmake/ccommConfigWindows.cmake.in).
include(CMakePackageConfigHelpers)
set(CCOMM_CONFIG_INCLUDEDIR include)
set(CCOMM_CONFIG_LIBDIR lib)
set(CCOMM_CONFIG_BINDIR bin)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ccommConfigWindows.cmake.in
  ${CMAKE_BINARY_DIR}/cmake/ccommConfig.cmake INSTALL_DESTINATION lib/cmake/ccomm
  PATH_VARS CCOMM_CONFIG_INCLUDEDIR CCOMM_CONFIG_LIBDIR CCOMM_CONFIG_BINDIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/cmake/ccommConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/ccommConfig.cmake ${CMAKE_BINARY_DIR}/cmake/ccommConfigVersion.cmake
        DESTINATION lib/cmake/ccomm)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION .)
