# Cross toolchain: Debian's aarch64-linux-gnu GCC for an arm64 board running Debian 12 (the
# package-arm64 preset, docs/install.md). The libraries come from Debian's arm64 packages
# installed beside the build machine's (multiarch: dpkg --add-architecture arm64, then e.g.
# libmosquitto-dev:arm64), in /usr/lib/aarch64-linux-gnu; tools/install-deps.sh installs them.
# qemu-aarch64 (qemu-user) runs the programs on the build machine (tools/arm64-replay.sh).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# Headers and libraries of the arm64 packages; the build machine's programs (pkg-config, git).
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
# pkg-config reads the arm64 .pc files only (multiarch folder), never the build machine's.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "")
# Programs built here run under qemu-aarch64 with the arm64 libraries (try_run, ctest).
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L /usr/aarch64-linux-gnu)
