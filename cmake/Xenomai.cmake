# SPDX-License-Identifier: Apache-2.0
# Xenomai 3 (Cobalt core, POSIX skin) via xeno-config. Sets XENOMAI_CFLAGS and
# XENOMAI_LDFLAGS (lists) for ccomm_platform, which every target links. Without
# xeno-config the option compiles away: a normal Linux build, with a warning.
find_program(XENO_CONFIG xeno-config HINTS ENV XENOMAI_ROOT_DIR PATH_SUFFIXES bin
             PATHS /usr/xenomai/bin)
if(NOT XENO_CONFIG)
  message(WARNING "CCOMM_WITH_XENOMAI=ON but xeno-config was not found (set XENOMAI_ROOT_DIR): "
                  "building for plain Linux")
  set(CCOMM_WITH_XENOMAI OFF)
  return()
endif()
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --cflags OUTPUT_VARIABLE _xeno_cflags
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r1)
# --auto-init: the Cobalt library initialises itself before main(), so ccommd and the
# applications need no Xenomai-specific start-up code.
execute_process(COMMAND ${XENO_CONFIG} --skin=posix --auto-init --ldflags OUTPUT_VARIABLE _xeno_ldflags
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _r2)
if(NOT _r1 EQUAL 0 OR NOT _r2 EQUAL 0)
  message(FATAL_ERROR "${XENO_CONFIG} failed; check the Xenomai installation")
endif()
separate_arguments(XENOMAI_CFLAGS UNIX_COMMAND "${_xeno_cflags}")
separate_arguments(XENOMAI_LDFLAGS UNIX_COMMAND "${_xeno_ldflags}")
message(STATUS "Xenomai POSIX skin: ${XENO_CONFIG}")
