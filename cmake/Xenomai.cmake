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
# --auto-init: the Cobalt library initialises itself before main(), so ccommd and the
# applications need no Xenomai-specific start-up code. The posix skin's flags include
# the linker's --wrap list (cobalt.wrappers): open, read, sendto, pthread_*,
# clock_gettime... resolve to Cobalt's versions in every target linked with them.
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --auto-init --ldflags OUTPUT_VARIABLE _xeno_ldflags
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r3)
if(NOT _r2 EQUAL 0 OR NOT _r3 EQUAL 0)
  message(FATAL_ERROR "${XENO_CONFIG} --skin=posix failed; check the Xenomai installation")
endif()
separate_arguments(XENOMAI_CFLAGS UNIX_COMMAND "${_xeno_cflags}")
separate_arguments(XENOMAI_LDFLAGS UNIX_COMMAND "${_xeno_ldflags}")
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
