# Cross build for arm64 (aarch64-linux-gnu): Debian's cross compilers
# (crossbuild-essential-arm64) against an arm64 sysroot of Debian packages,
# the test binaries run under qemu-user. scripts/test-arm64.sh makes the
# sysroot and uses this file with TOUCHDOWN_ONBOARD_ONLY=ON:
#
#   cmake -S . -B build-arm64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/aarch64-linux-gnu.cmake \
#         -DTOUCHDOWN_ARM64_SYSROOT=/var/cache/touchdown/arm64-sysroot -DTOUCHDOWN_ONBOARD_ONLY=ON
#
# The sysroot: TOUCHDOWN_ARM64_SYSROOT (cache), else the environment
# variable of that name, else scripts/test-arm64.sh's default.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

if(NOT TOUCHDOWN_ARM64_SYSROOT)
  if(DEFINED ENV{TOUCHDOWN_ARM64_SYSROOT})
    set(TOUCHDOWN_ARM64_SYSROOT "$ENV{TOUCHDOWN_ARM64_SYSROOT}")
  else()
    set(TOUCHDOWN_ARM64_SYSROOT /var/cache/touchdown/arm64-sysroot)
  endif()
endif()
set(TOUCHDOWN_ARM64_SYSROOT "${TOUCHDOWN_ARM64_SYSROOT}" CACHE PATH "arm64 sysroot (scripts/test-arm64.sh)")
if(NOT EXISTS "${TOUCHDOWN_ARM64_SYSROOT}/usr/include")
  message(FATAL_ERROR "no arm64 sysroot at ${TOUCHDOWN_ARM64_SYSROOT} (scripts/test-arm64.sh makes one)")
endif()
# try_compile projects read this file again: hand them the same sysroot.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES TOUCHDOWN_ARM64_SYSROOT)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_SYSROOT "${TOUCHDOWN_ARM64_SYSROOT}")
# GCC's aarch64 note that passing std::pair<double, double> changed in GCC
# 10.1 concerns linking with objects from GCC < 10.1; everything here is GCC 12.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")

# Headers, libraries and CMake package files only from the sysroot; the
# programs the build runs (pkg-config, the emulator) from the host.
set(CMAKE_FIND_ROOT_PATH "${CMAKE_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (ODE, libccd): the host's pkg-config reads only the sysroot's
# .pc files and prefixes their paths with the sysroot.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${CMAKE_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${CMAKE_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${CMAKE_SYSROOT}/usr/lib/pkgconfig:${CMAKE_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# ctest (add_test with a target) and gtest_discover_tests run the test
# binaries through this; -L makes qemu load the arm64 dynamic loader and
# libraries from the sysroot.
find_program(TOUCHDOWN_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${TOUCHDOWN_QEMU_AARCH64};-L;${CMAKE_SYSROOT}")
