#!/usr/bin/env bash
# Installs the Debian 12 packages plinth needs to build and test, only those that are missing,
# then gpio-sim for the qemu route's kernel (tools/build-gpio-sim.sh) if it is not built yet.
# Uses sudo when not run as root. Usage: tools/install-deps.sh
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libcli11-dev libtomlplusplus-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsocketcan-dev kmod iproute2 can-utils  # SocketCAN, tested on a real bus (tools/vcan-bus.sh):
  user-mode-linux                           #   route uml
  qemu-system-x86 linux-image-amd64 busybox-static xz-utils  # route qemu
  linux-headers-amd64 linux-source-6.1 gpiod  # gpio-sim in the qemu route
  python3 gnuplot-nox
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # Cortex-M4F image
  qemu-system-arm                                                            # runs it
  libgpiod-dev libsystemd-dev systemd  # relays (libgpiod), sd_notify; systemd-analyze tests the unit
  libmodbus-dev mbpoll  # plinth-monitor's Modbus TCP server, tested with mbpoll (docs/integration.md)
  libmosquitto-dev mosquitto mosquitto-clients openssl  # its MQTT publisher, tested on a broker
  nlohmann-json3-dev  # the MQTT command payloads (JSON; header-only, build time only)
  clang-14 libclang-rt-14-dev  # the sanitize preset: ASan + UBSan and libFuzzer (docs/fuzzing.md)
)

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  sudo=(sudo)
fi
need_root() {
  [ ${#sudo[@]} -eq 0 ] || command -v sudo >/dev/null ||
    { echo "install-deps: need root or sudo to $*" >&2; exit 1; }
}

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
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

if ! bash tools/build-gpio-sim.sh --check; then
  need_root "build gpio-sim into /usr/local/lib/plinth"
  "${sudo[@]}" bash tools/build-gpio-sim.sh
fi
