# Cross toolchain: Debian's arm-none-eabi GCC for a Cortex-M4F (single-precision FPU, hard-float
# calling convention), bare metal. The firmware image and its libraries are built with it; the
# host-only parts of the tree are skipped (CMAKE_CROSSCOMPILING, see the top-level CMakeLists).
# Debian 12: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi
#            libstdc++-arm-none-eabi-newlib qemu-system-arm   (tools/install-deps.sh)
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

# The target core. A Cortex-M7 with a double-precision FPU (QEMU's mps2-an500, same memory map)
# runs the same images: -mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16.
set(PLINTH_MCU_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16"
    CACHE STRING "arm-none-eabi code generation flags of the target core")

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
# The archivers with GCC's LTO plugin (PLINTH_MCU_LTO: the symbol index of LTO objects).
set(CMAKE_AR arm-none-eabi-gcc-ar)
set(CMAKE_RANLIB arm-none-eabi-gcc-ranlib)
set(CMAKE_NM arm-none-eabi-nm)
# The nm checks read the objects' ELF symbols, not the LTO plugin's (tools/check-freestanding.sh).
set(PLINTH_NM_TARGET elf32-littlearm)
set(CMAKE_OBJCOPY arm-none-eabi-objcopy)
set(CMAKE_SIZE arm-none-eabi-size)

# A bare-metal link needs a linker script: the compiler checks build a static library.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# Every object: the core's flags, one section per function and object (the link keeps only
# what is used), no unwind tables (nothing unwinds without exceptions), no contraction of
# a * b + c into a fused multiply-add (g++ contracts by default where the FPU has one, e.g. a
# Cortex-M7's double FMA): the same roundings as the host's baseline x86-64 build; and no errno
# from the maths functions (nothing reads it): sqrtf is then the FPU's vsqrt.f32, correctly
# rounded as newlib's, without the call and its errno path (97 bytes of flash).
set(PLINTH_MCU_COMMON_FLAGS
    "-ffunction-sections -fdata-sections -ffp-contract=off -fno-math-errno")
set(CMAKE_C_FLAGS_INIT "${PLINTH_MCU_CPU_FLAGS} ${PLINTH_MCU_COMMON_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT
    "${PLINTH_MCU_CPU_FLAGS} ${PLINTH_MCU_COMMON_FLAGS} -fno-unwind-tables -fno-asynchronous-unwind-tables")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${PLINTH_MCU_CPU_FLAGS} --specs=nano.specs -nostartfiles -Wl,--gc-sections")

# Libraries and headers of the target come from the toolchain; Eigen (header-only) and CMake
# package files from the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
