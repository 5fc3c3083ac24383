# SPDX-License-Identifier: Apache-2.0
# Xenomai 3 (Cobalt core, POSIX skin) via xeno-config. Sets XENOMAI_CFLAGS and
# XENOMAI_LDFLAGS (lists) for ccomm_platform, which every target links, and
# XENOMAI_VERSION. Asked for Xenomai without a usable xeno-config, the configuration
# fails: a build that silently runs on plain Linux would make Linux syscalls from
# primary-mode threads. Where to look: XENOMAI_ROOT_DIR (cache or environment), or
# XENOMAI_PREFIX, else /usr/xenomai, else PATH. scripts/xenomai-check builds this way.
set(XENOMAI_ROOT_DIR "$ENV{XENOMAI_ROOT_DIR}" CACHE PATH "Xenomai 3 installation prefix (has bin/xeno-config)")
if(NOT XENOMAI_ROOT_DIR AND DEFINED ENV{XENOMAI_PREFIX})
  set(XENOMAI_ROOT_DIR "$ENV{XENOMAI_PREFIX}")
endif()
find_program(XENO_CONFIG xeno-config HINTS ${XENOMAI_ROOT_DIR} PATH_SUFFIXES bin PATHS /usr/xenomai/bin)
if(NOT XENO_CONFIG)
  message(FATAL_ERROR "CCOMM_WITH_XENOMAI=ON but xeno-config was not found: set XENOMAI_ROOT_DIR "
                      "to the Xenomai 3 prefix (the one with bin/xeno-config), or configure with "
                      "-DCCOMM_WITH_XENOMAI=OFF for plain Linux")
endif()
execute_process(COMMAND ${XENO_CONFIG} --version OUTPUT_VARIABLE XENOMAI_VERSION
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r0)
execute_process(COMMAND ${XENO_CONFIG} --core OUTPUT_VARIABLE _xeno_core
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r1)
if(NOT _r0 EQUAL 0 OR NOT _r1 EQUAL 0 OR NOT XENOMAI_VERSION MATCHES "^3\\.")
  message(FATAL_ERROR "${XENO_CONFIG}: not a Xenomai 3 installation (version '${XENOMAI_VERSION}')")
endif()
if(NOT _xeno_core STREQUAL "cobalt")
  message(FATAL_ERROR "${XENO_CONFIG}: core '${_xeno_core}'; ccomm needs the Cobalt core "
                      "(its XDDP doorbell, src/client/doorbell_xddp.cpp)")
endif()
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --cflags OUTPUT_VARIABLE _xeno_cflags
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r2)
# Auto-init: the Cobalt library initialises itself before main(), so ccommd and the
# applications need no Xenomai-specific start-up code. Executables take --auto-init (a
# main() wrapper), libccomm.so --auto-init-solib (a constructor: an application built
# without xeno-config still gets Cobalt set up); xenomai_init() runs once either way.
# The posix skin's flags include the linker's --wrap list (cobalt.wrappers): open, read,
# sendto, pthread_*, clock_gettime... resolve to Cobalt's versions in every target
# linked with them.
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --auto-init --ldflags OUTPUT_VARIABLE _xeno_exe
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r3)
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --auto-init-solib --ldflags OUTPUT_VARIABLE _xeno_solib
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r4)
execute_process(COMMAND ${XENO_CONFIG} --libdir OUTPUT_VARIABLE XENOMAI_LIBDIR
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r5)
if(NOT _r2 EQUAL 0 OR NOT _r3 EQUAL 0 OR NOT _r4 EQUAL 0 OR NOT _r5 EQUAL 0)
  message(FATAL_ERROR "${XENO_CONFIG} --skin=posix failed; check the Xenomai installation")
endif()
separate_arguments(XENOMAI_CFLAGS UNIX_COMMAND "${_xeno_cflags}")
separate_arguments(_xeno_exe UNIX_COMMAND "${_xeno_exe}")
separate_arguments(_xeno_solib UNIX_COMMAND "${_xeno_solib}")
# One list for ccomm_platform's users: flags both variants share as they are, the
# others chosen by the type of the target being linked.
set(_is_solib "$<STREQUAL:$<TARGET_PROPERTY:TYPE>,SHARED_LIBRARY>")
set(XENOMAI_LDFLAGS)
foreach(_f IN LISTS _xeno_exe)
  if(_f IN_LIST _xeno_solib)
    list(APPEND XENOMAI_LDFLAGS "${_f}")
  else()
    list(APPEND XENOMAI_LDFLAGS "$<$<NOT:${_is_solib}>:${_f}>")
  endif()
endforeach()
foreach(_f IN LISTS _xeno_solib)
  if(NOT _f IN_LIST _xeno_exe)
    list(APPEND XENOMAI_LDFLAGS "$<${_is_solib}:${_f}>")
  endif()
endforeach()
# Programs that link only libccomm.so find libcobalt through it.
add_link_options("LINKER:-rpath-link,${XENOMAI_LIBDIR}")
# Xenomai's headers are system headers to us: ccomm's -Werror is not for them.
set(_xeno_flags)
foreach(_f IN LISTS XENOMAI_CFLAGS)
  if(_f MATCHES "^-I(.+)")
    list(APPEND _xeno_flags "SHELL:-isystem ${CMAKE_MATCH_1}")  # SHELL: no de-duplication
  else()
    list(APPEND _xeno_flags "${_f}")
  endif()
endforeach()
set(XENOMAI_CFLAGS ${_xeno_flags})
message(STATUS "Xenomai ${XENOMAI_VERSION} (Cobalt, POSIX skin): ${XENO_CONFIG}")
