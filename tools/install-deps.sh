#!/usr/bin/env bash
# Installs the Debian 12 packages plinth needs, only those that are missing. Three sets:
#   --runtime  what the installed programs need to run on a box: the shared libraries and tools
#              the Debian packages' Depends name (cmake/packaging.cmake; the test
#              package_deb_contents checks the two lists agree). apt brings these itself when it
#              installs the packages (docs/install.md); this is for a box installed by hand.
#   --build    the runtime set and what builds the programs (the README's first command,
#              tools/quickstart.sh): compiler, CMake, the libraries' headers. No test tooling.
#   --all      (default) the build set and everything the tests and the cross builds use
#              (tools/test-all.sh): GoogleTest, Google Benchmark, clang, the CAN and GPIO test
#              guests (user-mode Linux, QEMU, a kernel source for gpio-sim), the Cortex-M4F
#              toolchain, the arm64 cross toolchain with arm64 (multiarch) libraries and
#              qemu-user for the package-arm64 preset, dpkg tooling; then gpio-sim for the qemu
#              route's kernel (tools/build-gpio-sim.sh) if it is not built yet.
# Uses sudo when not run as root.
# Usage: tools/install-deps.sh [--runtime | --build | --all] [--list]
#   --list  print the set's packages, one a line, and install nothing
set -euo pipefail
cd "$(dirname "$0")/.."

set_name=all
list_only=0
for arg in "$@"; do
  case "$arg" in
    --runtime) set_name=runtime ;;
    --build) set_name=build ;;
    --all) set_name=all ;;
    --list) list_only=1 ;;
    *) echo "usage: tools/install-deps.sh [--runtime | --build | --all] [--list]" >&2; exit 2 ;;
  esac
done

runtime=(
  libmosquitto1 libgpiod2 libsystemd0 libtomlplusplus3  # plinth-monitor's libraries
  systemd  # the service, its user (systemd-sysusers)
  python3 gnuplot-nox  # plinth-event-plot draws with gnuplot
)
build=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libcli11-dev libtomlplusplus-dev
  libgpiod-dev libsystemd-dev  # relays (libgpiod 1.6), sd_notify, sd_listen_fds, the journal
  libmosquitto-dev  # plinth-monitor's MQTT client (its Modbus TCP server needs no library)
  nlohmann-json3-dev  # the MQTT command payloads (JSON; header-only)
  libsocketcan-dev  # the CAN controller's state (hal/socketcan)
)
tests=(
  libgtest-dev libgmock-dev libbenchmark-dev
  kmod iproute2 can-utils  # SocketCAN, tested on a real bus (tools/vcan-bus.sh):
  user-mode-linux                           #   route uml
  qemu-system-x86 linux-image-amd64 busybox-static xz-utils  # route qemu
  linux-headers-amd64 linux-source-6.1 gpiod  # gpio-sim in the qemu route
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # Cortex-M4F image
  qemu-system-arm                                                            # runs it
  # (systemd, in the runtime set: systemd-analyze tests the units, systemd-socket-activate passes
  # the Modbus socket)
  mbpoll  # the Modbus TCP server, tested with mbpoll, a libmodbus client (docs/integration.md)
  mosquitto mosquitto-clients openssl  # the MQTT publisher, tested on a broker
  clang-14 libclang-rt-14-dev  # the sanitize preset: ASan + UBSan and libFuzzer (docs/fuzzing.md)
  dpkg-dev fakeroot  # the package preset (CPack DEB), its packages unpacked and checked
  python3-openpyxl  # tools/pwave-stations.py reads the NGA-West2 flatfile (xlsx; docs/regional.md)
  stress-ng  # keeps the cores busy while the tests run, as on a user's laptop (README, can-e2e.md)
  # The box's disk image (firmware/image/build-image.sh, docs/image.md): mmdebstrap makes the
  # Debian system (zstd keeps its base between runs), mkfs.ext4, mkfs.vfat and mtools its
  # filesystems, sfdisk its partition table, grub-mkimage its boot loader; qemu-user-static runs
  # the arm64 image's maintainer scripts (binfmt_misc). Booted by tools/image-test.sh under UEFI
  # firmware (ovmf; qemu-efi-aarch64 for qemu-system-aarch64, in qemu-system-arm), reached over
  # SSH (openssh-client).
  mmdebstrap zstd e2fsprogs dosfstools mtools fdisk grub-common qemu-user-static
  ovmf qemu-efi-aarch64 openssh-client
  # The package-arm64 preset (docs/install.md): Debian's cross compiler, the libraries for arm64
  # (multiarch), and qemu-user, which runs the arm64 plinth-monitor on this machine.
  g++-aarch64-linux-gnu qemu-user
  libtomlplusplus-dev:arm64 libgpiod-dev:arm64 libsystemd-dev:arm64
  libmosquitto-dev:arm64 libsocketcan-dev:arm64
)
case "$set_name" in
  runtime) packages=("${runtime[@]}") ;;
  build) packages=("${runtime[@]}" "${build[@]}") ;;
  all) packages=("${runtime[@]}" "${build[@]}" "${tests[@]}") ;;
esac
if [ "$list_only" -eq 1 ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  sudo=(sudo)
fi
need_root() {
  [ ${#sudo[@]} -eq 0 ] || command -v sudo >/dev/null ||
    { echo "install-deps: need root or sudo to $*" >&2; exit 1; }
}

# Packages of another architecture (name:arm64) need it added to dpkg first (multiarch).
update_needed=0
for p in "${packages[@]}"; do
  case "$p" in
    *:*)
      arch=${p#*:}
      if [ "$arch" != "$(dpkg --print-architecture)" ] &&
        ! dpkg --print-foreign-architectures | grep -qx "$arch"; then
        need_root "add the $arch architecture (dpkg --add-architecture $arch)"
        echo "install-deps: adding the $arch architecture (multiarch)"
        "${sudo[@]}" dpkg --add-architecture "$arch"
        update_needed=1
      fi
      ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ] && [ "$update_needed" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages of the $set_name set present"
elif [ ${#missing[@]} -gt 0 ]; then
  need_root "install: ${missing[*]}"
  echo "install-deps: installing ${missing[*]}"
  # A machine that boots from /boot (a boot loader there) gets the kernel's initramfs as usual;
  # elsewhere (a container) the qemu route's kernel needs none: INITRD=No saves minutes.
  initrd=()
  [ -e /boot/grub ] || [ -e /boot/efi ] || [ -e /boot/loader ] || initrd=(INITRD=No)
  "${sudo[@]}" apt-get update -q
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive "${initrd[@]}" \
    apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

if [ "$set_name" = all ] && ! bash tools/build-gpio-sim.sh --check; then
  need_root "build gpio-sim into /usr/local/lib/plinth"
  "${sudo[@]}" bash tools/build-gpio-sim.sh
fi
