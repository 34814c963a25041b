#!/usr/bin/env bash
# Builds the box's bootable disk image: Debian 12 for amd64 or arm64 from Debian's packages and
# the project's own .debs, apt resolving their Depends (mmdebstrap), booted by UEFI (GRUB on
# the EFI system partition). docs/image.md says what is in it and why; in short:
#   partition 1  EFI system partition (FAT32, 40 MiB): GRUB as the removable-media loader
#                (EFI/BOOT/BOOTX64.EFI, BOOTAA64.EFI), its grub.cfg, and the folder plinth/
#                whose files the first boot takes (plinth-image-setup: the statue's scene,
#                the box file, SSH keys, network settings)
#   partition 2  the system (ext4), grown to the end of the disk at the first boot; mounted
#                read-only on /, and writable on /var alone (a bind mount): the state directory
#                with the captures, the box's state, the persistent journal, dpkg's database
# The image's own files are firmware/image/rootfs/ (networkd's CAN and Ethernet settings, the
# journal's cap, the watchdog, the first boot, the read-only root's apt hook).
#
# Usage: firmware/image/build-image.sh [--debs DIR] [options]
#   --debs DIR       the plinth packages: DIR/plinth-monitor_*_ARCH.deb (and with --with-tools
#                    plinth-tools_*_ARCH.deb); with several versions there, the newest. Without
#                    it, they are built first: cmake --workflow --preset package (package-arm64
#                    for arm64) into build/package/
#   --arch A         amd64 or arm64 (default: this machine's)
#   --out FILE       the image (default build/image/plinth-box-ARCH.img); beside it FILE.packages
#                    (every package and version in it) and FILE.sha256
#   --with-tools     plinth-tools too (the engineering tools; its Depends, python3 and gnuplot
#                    with the graphics and video libraries it links, add about 110 MB)
#   --mirror URL     Debian's archive (default http://deb.debian.org/debian)
#   --security URL   its security archive (default http://deb.debian.org/debian-security)
#   --cache DIR      keep there the downloaded .debs (DIR/debs) and the Debian base of step 1
#                    (DIR/base-ARCH-KEY.tar.zst), and take them from there next time
#   --work DIR       the build's files (default: a temporary folder, removed after)
# Needs root (mmdebstrap's root mode, the image's file owners), and tools/install-deps.sh's test
# set: mmdebstrap, e2fsprogs, dosfstools, mtools, fdisk, grub-common; for arm64 on another
# machine qemu-user-static, run through binfmt_misc (the host's registration, or one of this
# script's own in a user namespace: Linux 6.7 or newer).
# Exit status: 0 built, 1 failed (the step is named), 2 usage, 77 cannot build here (not root,
# a tool missing, no way to run arm64 programs): the reason is printed.
set -euo pipefail
me=build-image
# Debian's own programs first: mmdebstrap's helpers (mmtarfilter) run on the system's python3,
# not on one a user's PATH puts before it (a pyenv shim costs a second for each package).
export PATH=/usr/sbin:/usr/bin:/sbin:/bin:$PATH
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
src=$(cd "$here/../.." && pwd)
self=$here/$(basename "${BASH_SOURCE[0]}")

# The image's sizes, MiB (docs/image.md, "Size").
esp_mib=40
# Free space in the image's filesystem beyond its files, until the first boot grows it to the
# disk: the first boot's files and journal.
root_free_mib=32

# Debian 12's packages of the box, beside the essential set and the plinth packages (apt adds
# their Depends). No Recommends (mmdebstrap's default).
base_packages=(
  systemd systemd-sysv udev dbus  # PID 1, devices, the bus systemctl and networkctl use
  systemd-timesyncd               # time synchronisation (NTP)
  systemd-resolved                # DNS for the time servers, with a read-only /etc/resolv.conf
  initramfs-tools zstd xz-utils kmod  # the initramfs; xz for the compressed modules
  e2fsprogs dosfstools            # fsck of the root and state, and of the boot partition
  iproute2 can-utils              # ip link for CAN, candump/cansend on the box
  openssh-server                  # the site's access (keys only)
)
linux_package() { echo "linux-image-$1"; }  # ARCH: Debian's kernel flavour

# Of each package and architecture in the download cache, the newest version alone (a .deb's
# mtime is the archive's, not its download's: no age tells an old version from a new one).
prune_debs() {  # DIR
  local file base key version kept_key="" kept_version="" kept_file=""
  for file in $(find "$1" -maxdepth 1 -name '*_*_*.deb' | sort); do
    base=${file##*/}
    key="${base%%_*}_${base##*_}"
    version=${base#*_}
    version=${version%_*}
    version=${version//%3a/:}
    if [ "$key" = "$kept_key" ]; then
      if dpkg --compare-versions "$version" gt "$kept_version"; then
        rm -f "$kept_file"
        kept_version=$version kept_file=$file
      else
        rm -f "$file"
      fi
    else
      kept_key=$key kept_version=$version kept_file=$file
    fi
  done
}

fail() { echo "$me: $*" >&2; exit 1; }
cannot() { echo "$me: cannot build here: $*" >&2; exit 77; }

# --- Hook: run by mmdebstrap with the image's root as $1 -------------------------------------
if [ "${1:-}" = --essential-hook ]; then
  # Before the kernel and the rest are installed: their hooks and settings, so the kernel's own
  # postinst compresses its modules and builds the initramfs the image keeps.
  cp -a "$here/rootfs/etc/kernel" "$2/etc/"
  mkdir -p "$2/etc/initramfs-tools/conf.d"
  cp -a "$here/rootfs/etc/initramfs-tools/conf.d/." "$2/etc/initramfs-tools/conf.d/"
  exit 0
fi

# --- Options --------------------------------------------------------------------------------
debs="" arch="" out="" with_tools=0 cache="" work=""
mirror=http://deb.debian.org/debian
security=http://deb.debian.org/debian-security
usage() {
  sed -n '/^# Usage:/,/^# Needs root/p' "$self" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --debs) debs=${2:-}; shift 2 ;;
    --arch) arch=${2:-}; shift 2 ;;
    --out) out=${2:-}; shift 2 ;;
    --with-tools) with_tools=1; shift ;;
    --mirror) mirror=${2:-}; shift 2 ;;
    --security) security=${2:-}; shift 2 ;;
    --cache) cache=${2:-}; shift 2 ;;
    --work) work=${2:-}; shift 2 ;;
    -h | --help) usage ;;
    *) echo "$me: unknown option '$1'" >&2; usage ;;
  esac
done
arch=${arch:-$(dpkg --print-architecture)}
case "$arch" in
  amd64) efi_target=x86_64-efi efi_loader=BOOTX64.EFI root_type=4f68bce3-e8cd-4db1-96e7-fbcaf984b709
    console="console=tty0 console=ttyS0,115200 quiet" ;;
  arm64) efi_target=arm64-efi efi_loader=BOOTAA64.EFI root_type=b921b045-1df0-41c3-af44-4c6f280d3fae
    console="quiet" ;;
  *) fail "--arch $arch: amd64 or arm64" ;;
esac
out=${out:-$src/build/image/plinth-box-$arch.img}

# --- Can it run here? -------------------------------------------------------------------------
[ "$(id -u)" -eq 0 ] || cannot "needs root (mmdebstrap's root mode; the image's files belong to
  root and to the system users): run it with sudo"
for tool in mmdebstrap mkfs.ext4 mkfs.vfat mmd mcopy sfdisk grub-mkimage; do
  command -v "$tool" >/dev/null ||
    cannot "$tool not found (tools/install-deps.sh installs mmdebstrap, e2fsprogs, dosfstools," \
      "mtools, fdisk and grub-common)"
done

# The packages, built here when no --debs names them.
if [ -z "$debs" ]; then
  preset=package$([ "$arch" = amd64 ] || echo "-$arch")
  echo "$me: the packages: cmake --workflow --preset $preset (build/$preset.log)"
  mkdir -p "$src/build"
  (cd "$src" && cmake --workflow --preset "$preset") >"$src/build/$preset.log" 2>&1 ||
    { tail -n 30 "$src/build/$preset.log" >&2; fail "the packages' build failed"; }
  debs=$src/build/package
fi
[ -d "$debs" ] || fail "--debs $debs: no such folder"

# The newest version of each plinth package for the architecture.
newest_deb() {  # PACKAGE
  local file best="" best_version="" version
  for file in "$debs/$1"_*_"$arch".deb; do
    [ -f "$file" ] || continue
    version=$(dpkg-deb -f "$file" Version)
    if [ -z "$best" ] || dpkg --compare-versions "$version" gt "$best_version"; then
      best=$file best_version=$version
    fi
  done
  [ -n "$best" ] || fail "no $1_*_$arch.deb in $debs (cmake --workflow --preset package$(
    [ "$arch" = amd64 ] || echo "-$arch") builds it)"
  (cd "$(dirname "$best")" && echo "$PWD/$(basename "$best")")
}
plinth_debs=("$(newest_deb plinth-monitor)")
[ "$with_tools" -eq 0 ] || plinth_debs+=("$(newest_deb plinth-tools)")

# Another architecture's programs (the packages' maintainer scripts) run through binfmt_misc and
# qemu-user-static: the host's registration if it has one, else this script's own in a new user
# namespace (every user and group mapped to itself), where binfmt_misc has its own instance
# (Linux 6.7 and newer): the build machine's registrations are not touched.
host_arch=$(dpkg --print-architecture)
sandbox_binfmt=0
if [ "$arch" != "$host_arch" ] && [ -z "${PLINTH_IMAGE_IN_USERNS:-}" ]; then
  interpreter=/usr/libexec/qemu-binfmt/aarch64-binfmt-P
  registered=/proc/sys/fs/binfmt_misc/qemu-aarch64
  if [ -f "$registered" ] && grep -qx enabled "$registered" && grep -q '^flags:.*F' "$registered"
  then
    :
  elif [ -x "$interpreter" ] && [ -r /usr/lib/binfmt.d/qemu-aarch64.conf ]; then
    sandbox_binfmt=1
  else
    cannot "arm64 programs cannot run here: install qemu-user-static (tools/install-deps.sh)"
  fi
fi
if [ "$sandbox_binfmt" -eq 1 ]; then
  tools_option=()
  [ "$with_tools" -eq 0 ] || tools_option=(--with-tools)
  fifo=$(mktemp -u) && mkfifo "$fifo"
  # In the namespace: binfmt_misc mounted, qemu-aarch64 registered with F (the interpreter
  # opened now, so it need not exist inside the image), then this script again.
  # shellcheck disable=SC2016  # expanded inside the namespace
  unshare --user --mount --fork -- bash -c '
    read -r _ <"$0"; rm -f "$0"
    mnt=$(mktemp -d) && mount -t binfmt_misc binfmt_misc "$mnt" ||
      { echo "'"$me"': cannot mount binfmt_misc in a user namespace (Linux 6.7 or newer" \
          "needed; or register qemu-aarch64 on the host: qemu-user-static, binfmt-support)" >&2
        exit 77; }
    rule=$(sed -n "s/^\(:qemu-aarch64:.*:\)[A-Z]*$/\1OCPF/p" /usr/lib/binfmt.d/qemu-aarch64.conf)
    echo "$rule" >"$mnt/register" || exit 77
    PLINTH_IMAGE_IN_USERNS=1 exec "$@"' "$fifo" "$self" --debs "$debs" --arch "$arch" \
    --out "$out" --mirror "$mirror" --security "$security" \
    ${cache:+--cache "$cache"} ${work:+--work "$work"} "${tools_option[@]}" &
  pid=$!
  while [ "$(readlink "/proc/$pid/ns/user")" = "$(readlink /proc/self/ns/user)" ]; do
    kill -0 "$pid" 2>/dev/null || { wait "$pid"; exit $?; }
    sleep 0.05
  done
  echo "0 0 4294967295" >"/proc/$pid/uid_map"
  echo "0 0 4294967295" >"/proc/$pid/gid_map"
  echo go >"$fifo"
  status=0
  wait "$pid" || status=$?
  exit "$status"
fi

# --- Build ------------------------------------------------------------------------------------
start=$SECONDS
# The kernel's postinst leaves its modules and its initramfs to finish_kernels, which compresses
# the modules on every core and builds the initramfs once, after the packages whose hooks it
# takes (INITRD=No skips the kernel's own build; initramfs-tools' trigger then finds no
# initramfs to update). Under emulation (another architecture) the postinst had run 33 min
# without ending (docs/image.md).
export INITRD=No PLINTH_IMAGE_KERNEL_ON_HOST=1
if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/plinth-image.XXXXXX")
  trap 'rm -rf "$work"' EXIT
else
  rm -rf "$work" && mkdir -p "$work"
fi
work=$(cd "$work" && pwd)
root=$work/root
step() { echo "$me: [$((SECONDS - start)) s] $*"; }
if [ -n "$cache" ]; then
  mkdir -p "$cache/debs"
  cache=$(cd "$cache" && pwd)
fi

# Each kernel of the image without its initramfs: its modules compressed as
# 50-plinth-image-compress-modules would, by this machine's xz on every core, indexed by this
# machine's depmod (kmod reads any architecture's modules), and its initramfs built in the
# image's root (for another architecture emulated: its shell scripts and copies alone).
finish_kernels() {
  local modules version
  for modules in "$root"/lib/modules/*/; do
    version=$(basename "$modules")
    [ -d "$modules" ] && [ ! -f "$root/boot/initrd.img-$version" ] || continue
    step "kernel $version: modules compressed and indexed here, its initramfs in the image"
    find "$modules" -name '*.ko' -type f -print0 |
      xargs -0 -r -P "$(nproc)" -n 64 xz --check=crc32 --lzma2=dict=1MiB --force --threads=1 ||
      fail "xz of the modules of $version failed"
    depmod -b "$root" "$version" || fail "depmod of $version failed"
    unshare --mount --propagation private -- bash -c '
      set -e
      for fs in proc sys dev; do mount --rbind "/$fs" "$1/$fs"; done
      unset INITRD
      chroot "$1" update-initramfs -c -k "$2"
      # /initrd.img, which the kernel'"'"'s postinst left out under INITRD=No
      chroot "$1" linux-update-symlinks install "$2" "/boot/vmlinuz-$2"' finish "$root" "$version" \
      >>"$work/initramfs.log" 2>&1 ||
      { tail -n 30 "$work/initramfs.log" >&2
        fail "the initramfs of $version failed ($work/initramfs.log)"; }
  done
}

# 1. Debian: the essential set and base_packages, by mmdebstrap. With --cache, the result is
# kept (base-ARCH-KEY.tar.zst) and taken again while its recipe (this script's package lists and
# settings, the kernel hooks, finish_kernels) and the ISO week are the same: a week-old base
# misses at most a week of Debian's updates, which step 2 installs (apt-get upgrade).
mm=(mmdebstrap --mode=root --variant=minbase --arch="$arch" --format=directory
  --hook-dir=/usr/share/mmdebstrap/hooks/merged-usr
  --include="$(IFS=,; echo "${base_packages[*]},$(linux_package "$arch")")"
  # dpkg without fsync while the image is built (left out of the image's dpkg settings).
  --dpkgopt=force-unsafe-io
  # Documentation, manuals and translations are left out; the copyrights stay.
  --dpkgopt='path-exclude=/usr/share/doc/*' --dpkgopt='path-include=/usr/share/doc/*/copyright'
  --dpkgopt='path-exclude=/usr/share/man/*' --dpkgopt='path-exclude=/usr/share/info/*'
  --dpkgopt='path-exclude=/usr/share/locale/*' --dpkgopt='path-exclude=/usr/share/lintian/*'
  --essential-hook="\"$self\" --essential-hook \"\$1\"")
# Kernel modules a box has no use for (docs/image.md, "Size"): graphics, sound, video capture,
# radio, InfiniBand and storage-network adapters, cluster and network filesystems. Kept: storage,
# Ethernet, USB, CAN, GPIO, SPI, I2C, watchdogs, hardware monitoring, netfilter.
for tree in sound drivers/gpu drivers/media drivers/infiniband drivers/net/wireless \
  net/wireless net/mac80211 drivers/bluetooth net/bluetooth drivers/staging drivers/isdn \
  drivers/comedi drivers/iio drivers/nfc net/nfc drivers/net/wwan drivers/atm net/atm \
  drivers/ieee802154 net/ieee802154 drivers/net/ieee802154 drivers/target drivers/nvme/target \
  drivers/scsi/lpfc drivers/scsi/qla2xxx drivers/scsi/mpt3sas drivers/scsi/be2iscsi \
  drivers/scsi/bfa drivers/scsi/qedi drivers/scsi/qedf drivers/net/ethernet/mellanox \
  drivers/net/ethernet/chelsio drivers/net/ethernet/qlogic drivers/net/ethernet/intel/ice \
  drivers/net/ethernet/sfc drivers/firewire drivers/thunderbolt fs/ocfs2 fs/btrfs fs/xfs \
  fs/smb fs/nfs fs/nfsd fs/ceph net/ceph fs/gfs2 fs/f2fs fs/jfs fs/nilfs2 fs/reiserfs \
  fs/ubifs fs/dlm net/sunrpc net/rxrpc net/tipc net/rds net/sctp net/openvswitch \
  net/batman-adv net/netrom net/rose net/ax25 net/x25 net/6lowpan lib/test_bpf.ko; do
  mm+=(--dpkgopt="path-exclude=/lib/modules/*/kernel/$tree*")
  mm+=(--dpkgopt="path-exclude=/usr/lib/modules/*/kernel/$tree*")
done
if [ -n "$cache" ]; then
  mm+=(--skip=download/empty --skip=essential/unlink
    --setup-hook='mkdir -p "$1"/var/cache/apt/archives/'
    --setup-hook="sync-in \"$cache/debs\" /var/cache/apt/archives/"
    --customize-hook="sync-out /var/cache/apt/archives \"$cache/debs\"")
fi
mm+=(bookworm "$root"
  "deb $mirror bookworm main" "deb $mirror bookworm-updates main"
  "deb $security bookworm-security main")
base_key=$( {
  printf '%s\n' "$arch" "${mm[@]}" "$(date -u +%G-W%V)" "$(declare -f finish_kernels)"
  cat "$here"/rootfs/etc/kernel/*/* "$here"/rootfs/etc/initramfs-tools/conf.d/*
} | sed "s#$work#WORK#g; s#${cache:-/nonexistent}#CACHE#g" | sha256sum | cut -c1-16)
base_tar=${cache:+$cache/base-$arch-$base_key.tar.zst}
tar_options=(--numeric-owner --xattrs --xattrs-include='*' --acls)
if [ -n "$base_tar" ] && [ -f "$base_tar" ]; then
  step "Debian 12 for $arch: the base from $base_tar"
  mkdir "$root"
  zstd -q -d -c "$base_tar" | tar "${tar_options[@]}" -x -C "$root" ||
    fail "cannot unpack $base_tar"
else
  step "Debian 12 for $arch: the base (mmdebstrap; $work/mmdebstrap.log)"
  "${mm[@]}" >"$work/mmdebstrap.log" 2>&1 ||
    { tail -n 40 "$work/mmdebstrap.log" >&2; fail "mmdebstrap failed ($work/mmdebstrap.log)"; }
  # The downloaded .debs are in the cache (sync-out): not in the base.
  rm -f "$root"/var/cache/apt/archives/*.deb
  finish_kernels
  if [ -n "$base_tar" ]; then
    rm -f "$cache/base-$arch-"*.tar.zst
    tar "${tar_options[@]}" -C "$root" -cf - . | zstd -q -T0 -3 >"$base_tar.part" &&
      mv "$base_tar.part" "$base_tar"
  fi
fi

# 2. The plinth packages, apt resolving their Depends from Debian's archive (the sources
# mmdebstrap wrote), in the image's root (a chroot in a mount namespace of its own: its /proc,
# /sys, /dev are the build machine's, gone with the namespace). GRUB's EFI modules are fetched
# beside them (the package is not installed: step 4 makes the boot loader of them).
step "the plinth packages, apt resolving their Depends: ${plinth_debs[*]##*/}"
mkdir -p "$root/var/tmp/plinth-debs" "$work/grub"
cp "${plinth_debs[@]}" "$root/var/tmp/plinth-debs/"
rm -f "$root/etc/resolv.conf"
cat /etc/resolv.conf >"$root/etc/resolv.conf"
# shellcheck disable=SC2016  # expanded in the namespace
unshare --mount --propagation private -- bash -c '
  set -e
  root=$1 cache=$2 arch=$3
  for fs in proc sys dev; do mount --rbind "/$fs" "$root/$fs"; done
  [ -z "$cache" ] || mount --bind "$cache/debs" "$root/var/cache/apt/archives"
  export DEBIAN_FRONTEND=noninteractive LC_ALL=C.UTF-8
  apt="apt-get -q -y -o Acquire::Languages=none -o APT::Install-Recommends=false"
  chroot "$root" $apt update
  chroot "$root" $apt upgrade
  chroot "$root" sh -c "$apt install /var/tmp/plinth-debs/*.deb"
  chroot "$root" sh -c "cd /var/tmp && $apt download grub-efi-$arch-bin"
  # No apt clean here: with --cache, the archive is the cache (bind-mounted), kept for the next
  # build; without, step 4 empties the image'"'"'s own.
' install "$root" "$cache" "$arch" >"$work/apt.log" 2>&1 ||
  { tail -n 40 "$work/apt.log" >&2
    fail "apt could not install the plinth packages ($work/apt.log)"; }
[ -z "$cache" ] || prune_debs "$cache/debs"
dpkg-deb -x "$root"/var/tmp/grub-efi-*-bin_*.deb "$work/grub"
rm -rf "$root/var/tmp/plinth-debs" "$root"/var/tmp/grub-efi-*-bin_*.deb
chroot "$root" dpkg-query -W -f '${Package} ${Version}\n' >"$work/packages"

# 2b. A kernel that step 2 installed (a newer one from bookworm's updates), finished likewise.
finish_kernels

# 3. The image's own files, its enabled units, and what no two boxes may share.
step "the image's files and units"
cp -a "$here/rootfs/." "$root/"
mkdir -p "$root/var/log/journal" "$root/boot/efi" "$root/etc/plinth"
chroot "$root" systemctl enable systemd-networkd.service systemd-resolved.service \
  systemd-timesyncd.service plinth-image-setup.service plinth-image-readonly.service \
  plinth-monitor@can0.service \
  >>"$work/apt.log" 2>&1 || fail "systemctl enable in the image failed ($work/apt.log)"
# No first-boot wizard: a box must never wait at its console for someone to answer.
ln -sf /dev/null "$root/etc/systemd/system/systemd-firstboot.service"
# /tmp in memory: nothing of it needs to outlive a boot.
ln -sf /usr/share/systemd/tmp.mount "$root/etc/systemd/system/tmp.mount"
chroot "$root" systemctl enable tmp.mount >>"$work/apt.log" 2>&1
# resolv.conf: systemd-resolved's stub (its package sets it on a booted system only).
ln -sf ../run/systemd/resolve/stub-resolv.conf "$root/etc/resolv.conf"
echo plinth-box >"$root/etc/hostname"
printf '127.0.0.1\tlocalhost\n127.0.1.1\tplinth-box\n::1\tlocalhost ip6-localhost\n' \
  >"$root/etc/hosts"
# The first boot makes them: plinth-image-setup.service (ConditionFirstBoot).
echo uninitialized >"$root/etc/machine-id"
rm -f "$root/var/lib/dbus/machine-id" "$root"/etc/ssh/ssh_host_*
# dpkg's settings from mmdebstrap: the path excludes stay (a kernel upgrade keeps the trimmed
# module set), the build's unsafe I/O goes; mmdebstrap's apt settings go, its sources stay.
grep -v '^force-unsafe-io$' "$root/etc/dpkg/dpkg.cfg.d/99mmdebstrap" \
  >"$root/etc/dpkg/dpkg.cfg.d/50-plinth-image"
rm -f "$root/etc/dpkg/dpkg.cfg.d/99mmdebstrap" "$root/etc/apt/apt.conf.d/99mmdebstrap"

# 4. The boot loader, the filesystems and the disk.
step "boot loader: GRUB for $efi_target"
kernel_version=$(basename "$(readlink "$root/vmlinuz")" | sed 's/^vmlinuz-//')
[ -n "$kernel_version" ] && [ -f "$root/boot/initrd.img-$kernel_version" ] ||
  fail "no kernel and initramfs in the image ($root/vmlinuz, $root/boot)"
grub_modules=(part_gpt part_msdos fat ext2 normal linux configfile search search_fs_uuid
  test echo ls cat sleep reboot halt all_video gzio)
grub-mkimage -O "$efi_target" -d "$work/grub/usr/lib/grub/$efi_target" -p /EFI/BOOT \
  -o "$work/$efi_loader" "${grub_modules[@]}" ||
  fail "grub-mkimage for $efi_target failed"

# Identities: this build's filesystems and partitions (every box written from it shares them).
uuid() { cat /proc/sys/kernel/random/uuid; }
root_uuid=$(uuid) root_partuuid=$(uuid)
esp_serial=$(od -An -N4 -tx4 /dev/urandom | tr -d ' ')
esp_uuid="${esp_serial:0:4}-${esp_serial:4:4}"
esp_uuid=${esp_uuid^^}
cat >"$root/etc/fstab" <<EOF
# The box's filesystems (plinth image, docs/image.md).
# One ext4 filesystem, grown to the end of the disk at the first boot (systemd-repart, then
# x-systemd.growfs). Its mount on / is made read-only once /var is mounted
# (plinth-image-readonly.service): only /var, the state directory, is written. apt makes /
# writable around each dpkg run; by hand: plinth-image-root rw / ro.
UUID=$root_uuid / ext4 rw,noatime,errors=remount-ro,x-systemd.growfs 0 1
# The state directory: the captures, the box's state, the journal, dpkg's database.
/var /var none bind 0 0
# The boot partition, mounted when needed (the first boot reads its plinth/ folder); waited for
# up to 10 min (a slow board's first boot: the first boot needs it).
UUID=$esp_uuid /boot/efi vfat ro,noauto,nofail,umask=0077,x-systemd.device-timeout=10min 0 0
EOF
cat >"$work/grub.cfg" <<EOF
# The box's boot menu (plinth image, docs/image.md). The kernel and initramfs are read from the
# root filesystem through Debian's links /vmlinuz and /initrd.img, which each kernel upgrade
# moves (and /vmlinuz.old, /initrd.img.old to the one before). Kernel options: plinth_options.
set timeout=2
set default=0
set plinth_options="$console"
search --no-floppy --fs-uuid --set=root $root_uuid
menuentry "plinth box (Debian 12, $arch)" {
  linux /vmlinuz root=PARTUUID=$root_partuuid ro rootwait panic=10 \$plinth_options
  initrd /initrd.img
}
menuentry "plinth box, the previous kernel" {
  linux /vmlinuz.old root=PARTUUID=$root_partuuid ro rootwait panic=10 \$plinth_options
  initrd /initrd.img.old
}
EOF

step "filesystems"
rm -rf "$root/var/cache/apt/archives/"*.deb "$root"/var/cache/apt/*.bin \
  "$root/var/lib/apt/lists/"* "$root/tmp/"*
mib_of() { du -s --block-size=1M --apparent-size "$1" | cut -f1; }
# ext4's own blocks (inode tables, journal) on top of the files: about 10 %, and 16 MiB more.
root_mib=$(( $(mib_of "$root") * 110 / 100 + 16 + root_free_mib ))
# 4 KiB blocks and an inode per 8 KiB (mke2fs would take 1 KiB blocks for a filesystem this
# small, its "small" type); 1 % reserved for root's services (journald, dpkg) when the captures
# have filled the disk.
mkfs.ext4 -q -F -b 4096 -i 8192 -m 1 -L plinth-root -U "$root_uuid" -d "$root" \
  "$work/root.ext4" "${root_mib}M" || fail "mkfs.ext4 of the root ($root_mib MiB) failed"
rm -f "$work/esp.vfat"
mkfs.vfat -F 32 -S 512 -s 1 -n PLINTH-BOOT -i "$esp_serial" -C "$work/esp.vfat" \
  $((esp_mib * 1024)) >/dev/null || fail "mkfs.vfat of the boot partition failed"
export MTOOLS_SKIP_CHECK=1
mmd -i "$work/esp.vfat" ::/EFI ::/EFI/BOOT ::/plinth
mcopy -i "$work/esp.vfat" "$work/$efi_loader" "$work/grub.cfg" ::/EFI/BOOT/
mcopy -i "$work/esp.vfat" "$here/plinth-folder-README.txt" ::/plinth/README.txt

step "disk: GPT, boot $esp_mib MiB, root $root_mib MiB"
esp_type=c12a7328-f81f-11d2-ba4b-00a0c93ec93b
mkdir -p "$(dirname "$out")"
rm -f "$out"
truncate -s "$((1 + esp_mib + root_mib + 1))M" "$out"
sfdisk -q "$out" <<EOF || fail "sfdisk failed"
label: gpt
first-lba: 2048
start=1MiB, size=${esp_mib}MiB, type=$esp_type, name=boot
size=${root_mib}MiB, type=$root_type, uuid=$root_partuuid, name=plinth-root
EOF
place() {  # FILESYSTEM START_MIB
  dd if="$1" of="$out" bs=1M seek="$2" conv=notrunc,sparse status=none || fail "dd $1 failed"
}
place "$work/esp.vfat" 1
place "$work/root.ext4" $((1 + esp_mib))

cp "$work/packages" "$out.packages"
(cd "$(dirname "$out")" && sha256sum "$(basename "$out")") >"$out.sha256"
step "done: $out, $(du --apparent-size --block-size=1M "$out" | cut -f1) MiB (kernel" \
  "$kernel_version; $(wc -l <"$out.packages") packages: $out.packages)"
