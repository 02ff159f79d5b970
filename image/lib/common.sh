# SPDX-License-Identifier: Apache-2.0
# Shared by image/build, image/provision and the QEMU test (sourced, bash).
#
# Disk layout of mogao-kiosk.img (GPT, 512-byte sectors, partitions aligned to 1 MiB):
#   1  ESP           FAT32, label ESP           systemd-boot, per slot a kernel and initramfs
#                                               (/mogao/a, /mogao/b), one loader entry per slot
#   2  mogao-root-a  ext4 (no journal), label mogao-root: root of slot a, read-only at / when it runs
#   3  mogao-config  ext4, label mogao-config, mounted read-write at /var/lib/mogao;
#                    its etc/ folder is bind-mounted read-only at /etc/mogao
#   4  mogao-root-b  root of slot b (empty until the first update; docs/updates.md)
# The root file systems of both slots carry the label mogao-root (the same file system image goes
# into either slot); the loader entries name their root by PARTUUID.

MOGAO_ROOT_LABEL=mogao-root
MOGAO_CONFIG_LABEL=mogao-config
MOGAO_ROOT_A_PART=2
MOGAO_CONFIG_PART=3
MOGAO_ROOT_B_PART=4
MOGAO_KIOSK_UID=970   # usr/lib/sysusers.d/mogao.conf in image/rootfs
MOGAO_KIOSK_GID=970

img_log() { echo "[$(basename "$0")] $*" >&2; }
img_die() { echo "[$(basename "$0")] error: $*" >&2; exit 1; }

# img_partition IMAGE N: prints "START_SECTOR SIZE_SECTORS" of partition N (sfdisk --dump).
img_partition() {
  local image=$1 n=$2 line
  line=$(sfdisk --dump "$image" 2>/dev/null | grep -E "^[^ ]*${n} :" | head -n1) \
    || img_die "$image has no partition $n"
  local start size
  start=$(sed -E 's/.*start= *([0-9]+).*/\1/' <<<"$line")
  size=$(sed -E 's/.*size= *([0-9]+).*/\1/' <<<"$line")
  [[ "$start" =~ ^[0-9]+$ && "$size" =~ ^[0-9]+$ ]] || img_die "cannot read partition $n of $image"
  echo "$start $size"
}

# img_extract IMAGE N FILE: copies partition N into FILE (sparse).
img_extract() {
  local start size
  read -r start size < <(img_partition "$1" "$2")
  dd if="$1" of="$3" bs=512 skip="$start" count="$size" conv=sparse status=none
}

# img_place IMAGE N FILE: writes FILE into partition N (FILE must not be larger).
img_place() {
  local start size bytes
  read -r start size < <(img_partition "$1" "$2")
  bytes=$(stat -c %s "$3")
  (( bytes <= size * 512 )) || img_die "$3 ($bytes bytes) does not fit partition $2 ($((size * 512)) bytes)"
  dd if="$3" of="$1" bs=1M seek="$((start * 512))" oflag=seek_bytes conv=notrunc,sparse status=none
}

# img_make_config_fs STAGING FILE SIZE_BYTES [UUID HASH_SEED]: the configuration partition's ext4
# file system from the folder STAGING (ownership and modes as they are in STAGING). Without UUID and
# HASH_SEED, mke2fs picks random ones.
img_make_config_fs() {
  local staging=$1 file=$2 bytes=$3 ids=() ext=root_owner=0:0
  if [[ -n "${4:-}" ]]; then ids=(-U "$4"); ext+=",hash_seed=$5"; fi
  rm -f "$file"
  truncate -s "$bytes" "$file"
  mke2fs -q -F -t ext4 -L "$MOGAO_CONFIG_LABEL" -m 0 -E "$ext" "${ids[@]}" -d "$staging" "$file" \
    || img_die "mke2fs of the configuration partition failed (too small for $staging?)"
}

# img_stage_config SRC DEST: lays out the configuration partition's tree in DEST from the folder
# SRC (which mirrors /etc/mogao: kiosk.toml, pki/, calibration files, optional network/*.network).
# SRC may be empty (unprovisioned image). etc/ is root:mogao-kiosk 0750 with files 0640 (the kiosk
# reads, never writes); state/ belongs to the kiosk.
img_stage_config() {
  local src=$1 dest=$2
  rm -rf "$dest"
  mkdir -p "$dest/etc" "$dest/state"
  if [[ -n "$src" ]]; then
    cp -a --no-preserve=ownership "$src/." "$dest/etc/"
  fi
  chown -R "0:$MOGAO_KIOSK_GID" "$dest/etc"
  find "$dest/etc" -type d -exec chmod 0750 {} +
  find "$dest/etc" -type f -exec chmod 0640 {} +
  # networkd (user systemd-network) reads network/*.network: world-readable, no secrets there.
  if [[ -d "$dest/etc/network" ]]; then
    chmod 0755 "$dest/etc" "$dest/etc/network"
    find "$dest/etc/network" -type f -exec chmod 0644 {} +
  fi
  chown "$MOGAO_KIOSK_UID:$MOGAO_KIOSK_GID" "$dest/state"
  chmod 0750 "$dest/state"
  chmod 0755 "$dest"
}

# img_clamp_times FILE EPOCH: sets atime and ctime of every inode of the ext4 image FILE to EPOCH.
# mke2fs 1.47.0 -d copies them from the source files, where ctime cannot be set and reading a file
# moves its atime; mtimes are clamped in the source already. mke2fs -d allocates inodes in order,
# so the used ones are 2 and 11..N; the caller checks the result with e2fsck.
img_clamp_times() {
  local file=$1 epoch=$2 used
  used=$(dumpe2fs -h "$file" 2>/dev/null | awk -F: \
      '/^Inode count/ { c = $2 } /^Free inodes/ { f = $2 } END { print c - f }')
  [[ "$used" =~ ^[0-9]+$ ]] || img_die "cannot read the inode count of $file"
  { for n in 2 $(seq 11 "$used"); do printf 'sif <%d> ctime @%d\nsif <%d> atime @%d\n' "$n" "$epoch" "$n" "$epoch";
      done; } |
    E2FSPROGS_FAKE_TIME=$epoch debugfs -w -f - "$file" > /dev/null 2>&1 || img_die "debugfs on $file failed"
}

# img_write_checksums IMAGE: IMAGE.sha256 (sha256sum format) and, with bmaptool, IMAGE.bmap.
img_write_checksums() {
  local image=$1 dir base
  dir=$(dirname "$image"); base=$(basename "$image")
  (cd "$dir" && sha256sum "$base" > "$base.sha256")
  if command -v bmaptool >/dev/null 2>&1; then
    bmaptool -q create -o "$image.bmap" "$image" || img_log "warning: bmaptool create failed"
  fi
}

# img_build_preconditions TOOL...: whether an image can be built here (the image tests skip, not
# fail, when it cannot). Prints the reason and returns 1 when a tool, systemd-boot or the Debian
# mirror ($MOGAO_IMAGE_MIRROR, default deb.debian.org) is missing; returns 0 otherwise.
img_build_preconditions() {
  local tool mirror=${MOGAO_IMAGE_MIRROR:-http://deb.debian.org/debian}
  for tool in "$@"; do
    command -v "$tool" >/dev/null \
      || { echo "$tool not found (apt-get install mmdebstrap e2fsprogs dosfstools mtools fdisk xz-utils)"; return 1; }
  done
  [[ -f /usr/lib/systemd/boot/efi/systemd-bootx64.efi ]] \
    || { echo "systemd-boot not found (apt-get install systemd-boot-efi)"; return 1; }
  python3 - "$mirror/dists/bookworm/Release" 2>/dev/null <<'PY' ||
import sys, urllib.request
urllib.request.urlopen(urllib.request.Request(sys.argv[1], method="HEAD"), timeout=20)
PY
    { echo "the Debian mirror $mirror is not reachable"; return 1; }
}
