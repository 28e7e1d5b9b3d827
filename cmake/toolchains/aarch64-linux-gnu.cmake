# Cross build for arm64 (aarch64) Debian 12: Debian's cross GCC 12 (crossbuild-essential-arm64)
# against the sysroot scripts/sysroot_arm64.sh unpacks (Debian 12's arm64 libraries), with the
# tests run under qemu user-mode emulation (qemu-user-static). `cmake --preset arm64` uses it;
# docs/arm64.md says how. MAPLESS_SYSROOT (cache or environment) names another sysroot.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

if(NOT MAPLESS_SYSROOT)
  if(DEFINED ENV{MAPLESS_SYSROOT})
    set(MAPLESS_SYSROOT "$ENV{MAPLESS_SYSROOT}")
  else()
    get_filename_component(MAPLESS_SYSROOT "${CMAKE_CURRENT_LIST_DIR}/../../build/sysroot-arm64"
                           ABSOLUTE)
  endif()
endif()
set(MAPLESS_SYSROOT "${MAPLESS_SYSROOT}" CACHE PATH "The arm64 sysroot (scripts/sysroot_arm64.sh)")
# try_compile projects see the same sysroot.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES MAPLESS_SYSROOT)
if(NOT EXISTS "${MAPLESS_SYSROOT}/usr/include/opencv4")
  message(FATAL_ERROR "mapless: no arm64 sysroot at ${MAPLESS_SYSROOT}: make it with "
                      "scripts/sysroot_arm64.sh (or set MAPLESS_SYSROOT)")
endif()

set(CMAKE_SYSROOT "${MAPLESS_SYSROOT}")
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# Programs (idlc, fastddsgen) are the build machine's; libraries, headers and packages only the
# sysroot's.
set(CMAKE_FIND_ROOT_PATH "${MAPLESS_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config reads the sysroot's .pc files and puts the sysroot before their paths.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${MAPLESS_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${MAPLESS_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${MAPLESS_SYSROOT}/usr/share/pkgconfig:${MAPLESS_SYSROOT}/usr/lib/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# The sysroot's libraries are found at run time by the emulator (-L: its ld.so and libraries),
# and at link time through their own dependencies.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64-static -L "${MAPLESS_SYSROOT}")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-Wl,-rpath-link,${MAPLESS_SYSROOT}/usr/lib/aarch64-linux-gnu -Wl,-rpath-link,${MAPLESS_SYSROOT}/lib/aarch64-linux-gnu")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "${CMAKE_EXE_LINKER_FLAGS_INIT}")
