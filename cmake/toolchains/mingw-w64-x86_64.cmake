# SPDX-License-Identifier: Apache-2.0
# Cross-compiling ccomm for Windows x64 with Debian's mingw-w64 (packages
# g++-mingw-w64-x86-64-posix, gcc-mingw-w64-x86-64-posix: the posix threading variant,
# which has std::thread). Use: cmake -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake
# (scripts/build-windows does). See docs/install.md "Windows".
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CCOMM_MINGW_TRIPLE x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${CCOMM_MINGW_TRIPLE}-gcc-posix)
set(CMAKE_CXX_COMPILER ${CCOMM_MINGW_TRIPLE}-g++-posix)
set(CMAKE_RC_COMPILER ${CCOMM_MINGW_TRIPLE}-windres)
set(CMAKE_FIND_ROOT_PATH /usr/${CCOMM_MINGW_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# Windows 10 APIs (CreateWaitableTimerExW, GetComputerNameExA); C99 printf (%zu, %llu).
add_compile_definitions(_WIN32_WINNT=0x0A00 WINVER=0x0A00 __USE_MINGW_ANSI_STDIO=1)
# The programs run without the MinGW runtime DLLs beside them (libstdc++, libgcc, winpthread).
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static")
