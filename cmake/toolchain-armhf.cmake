# SPDX-License-Identifier: Apache-2.0
# Cross-compile ccomm for 32-bit ARM hard-float Linux (the QEMU test boards and the
# Overo class of boards) with Debian's cross toolchain (crossbuild-essential-armhf).
#
#   cmake -S . -B build-armhf -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-armhf.cmake \
#         -DCCOMM_ARMHF_DEPS=/path/to/deps -DCCOMM_BUILD_TESTS=OFF
#
# libc and libstdc++ come from the cross toolchain itself (/usr/arm-linux-gnueabihf).
# The few armhf libraries ccomm links against (libsystemd, libsodium; RapidXML is header
# only) are not installed on the build host: extract their Debian armhf packages
# (dpkg-deb -x) into a directory and pass it as CCOMM_ARMHF_DEPS (or the environment
# variable of the same name). The board images do not use this file: the Isar layer
# cross-builds ccomm's Debian packages with sbuild (scripts/build-image). That keeps the host's dpkg untouched (no
# `dpkg --add-architecture`, no multi-arch version lock-step with host packages) and the
# extracted tree can be cached, keyed on the package versions.

set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(CCOMM_CROSS_TRIPLET arm-linux-gnueabihf)
set(CMAKE_C_COMPILER ${CCOMM_CROSS_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${CCOMM_CROSS_TRIPLET}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${CCOMM_CROSS_TRIPLET})

# try_compile() re-reads this file in a fresh project: forward the deps location.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES CCOMM_ARMHF_DEPS)
if(NOT CCOMM_ARMHF_DEPS AND DEFINED ENV{CCOMM_ARMHF_DEPS})
  set(CCOMM_ARMHF_DEPS "$ENV{CCOMM_ARMHF_DEPS}")
endif()

set(CMAKE_FIND_ROOT_PATH /usr/${CCOMM_CROSS_TRIPLET})
if(CCOMM_ARMHF_DEPS)
  set(CCOMM_ARMHF_DEPS "${CCOMM_ARMHF_DEPS}" CACHE PATH "Extracted armhf Debian packages (libsystemd-dev, libsodium-dev, ...)")
  list(APPEND CMAKE_FIND_ROOT_PATH "${CCOMM_ARMHF_DEPS}")
  set(_deps_libdir "${CCOMM_ARMHF_DEPS}/usr/lib/${CCOMM_CROSS_TRIPLET}")
  # pkg-config must see only the armhf .pc files, with paths rebased into the tree.
  set(ENV{PKG_CONFIG_LIBDIR} "${_deps_libdir}/pkgconfig:${CCOMM_ARMHF_DEPS}/usr/share/pkgconfig")
  set(ENV{PKG_CONFIG_SYSROOT_DIR} "${CCOMM_ARMHF_DEPS}")
  set(ENV{PKG_CONFIG_PATH} "")
  # -L for libraries named without a directory; -rpath-link so the linker finds the
  # dependencies of libsystemd.so (libcap, libgcrypt, liblz4, ...) in the same tree.
  # Nothing of this path ends up in the binaries (no -rpath).
  foreach(_kind EXE SHARED MODULE)
    set(CMAKE_${_kind}_LINKER_FLAGS_INIT "-L${_deps_libdir} -Wl,-rpath-link,${_deps_libdir}")
  endforeach()
endif()

# Headers and libraries only from the target trees, programs from the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Lets `ctest`/add_custom_command run armhf programs on the build host through
# qemu-user when it is installed (qemu-user-static).
find_program(CCOMM_QEMU_ARM NAMES qemu-arm-static qemu-arm)
if(CCOMM_QEMU_ARM)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${CCOMM_QEMU_ARM} -L /usr/${CCOMM_CROSS_TRIPLET})
  if(CCOMM_ARMHF_DEPS)
    list(APPEND CMAKE_CROSSCOMPILING_EMULATOR -E LD_LIBRARY_PATH=${_deps_libdir})
  endif()
endif()
