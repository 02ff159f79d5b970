# SPDX-License-Identifier: Apache-2.0
# Shared by image/farm/build, image/farm/provision and the farm's QEMU test (sourced, bash).
#
# Disk layout of mogao-farm.img (GPT, 512-byte sectors, partitions aligned to 1 MiB):
#   1  ESP        FAT32, label ESP         systemd-boot, kernel, initramfs, loader entry
#   2  farm-root  ext4, label farm-root    mounted read-write at /
# Partition names (GPT) equal the file system labels.

MOGAO_FARM_ROOT_LABEL=farm-root
MOGAO_FARM_UID=971   # systemd/mogao-farm.sysusers (the mogao-farm package)
MOGAO_FARM_GID=971
# The render hosts' packet filter; provisioning checks farm-network files with its parser.
FARM_FIREWALL="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/rootfs/usr/lib/mogao/farm-firewall"

# farm_check_host_dir DIR: dies with the file and field at fault when DIR (image/farm/provision's
# HOST_DIR) is inconsistent or holds what the mogao-farm package owns.
farm_check_host_dir() {
  local dir=$1 f
  f="$dir/etc/hostname"
  if [[ -f "$f" ]]; then
    [[ $(wc -l < "$f") -le 1 ]] && grep -qE '^[a-z0-9]([a-z0-9-]{0,62})$' "$f" \
      || img_die "$f: one host name (lower-case letters, digits, '-') expected"
  fi
  # Every host filters its ports by it (mogao-farm-firewall.service): without it, Open MPI's
  # ports would be closed to the other hosts too. Checked by the filter's own parser, so that
  # what provisioning accepts is what the host loads at boot.
  f="$dir/etc/mogao/farm-network"
  [[ -f "$f" ]] || img_die "$f missing: the farm network's prefixes, one per line (e.g. 10.77.0.0/24)," \
    "from which Open MPI's ports may be reached"
  local why
  if ! why=$(sh "$FARM_FIREWALL" --print "$f" 2>&1 > /dev/null); then
    why=${why#mogao-farm-firewall: }
    img_die "${why%%: Open MPI*}"
  fi
  # The farm's own configuration comes with the mogao-farm package, after it is installed
  # (docs/packaging.md): dpkg would find farm.env and farm-hosts in the way of its conffiles.
  for f in etc/mogao/farm.env etc/mogao/farm-hosts etc/mogao/pki; do
    [[ ! -e "$dir/$f" ]] || img_die "$dir/$f: the farm's configuration is written after" \
      "\`apt install ./mogao-farm_*.deb\` on the host (docs/packaging.md), not provisioned into the image"
  done
}

# farm_stage_host_dir SRC DEST: SRC's tree in DEST with the ownership and modes a render host
# needs (see image/farm/provision).
farm_stage_host_dir() {
  local src=$1 dest=$2
  rm -rf "$dest"; mkdir -p "$dest"
  cp -a --no-preserve=ownership "$src/." "$dest/"
  chown -R 0:0 "$dest"
  if [[ -d "$dest/etc/mogao" ]]; then
    chown -R "0:$MOGAO_FARM_GID" "$dest/etc/mogao"
    find "$dest/etc/mogao" -type d -exec chmod 0750 {} +
    find "$dest/etc/mogao" -type f -exec chmod 0640 {} +
  fi
  if [[ -d "$dest/var/lib/mogao-farm" ]]; then
    chown -R "$MOGAO_FARM_UID:$MOGAO_FARM_GID" "$dest/var/lib/mogao-farm"
    find "$dest/var/lib/mogao-farm" -type d -exec chmod 0700 {} +
    find "$dest/var/lib/mogao-farm" -type f -exec chmod 0600 {} +
    find "$dest/var/lib/mogao-farm" -type f -name '*.pub' -exec chmod 0644 {} +
  fi
  find "$dest/etc/ssh" -maxdepth 1 -type f -name 'ssh_host_*_key' -exec chmod 0600 {} + 2>/dev/null || true
  find "$dest/etc/ssh" -maxdepth 1 -type f -name 'ssh_host_*_key.pub' -exec chmod 0644 {} + 2>/dev/null || true
}
