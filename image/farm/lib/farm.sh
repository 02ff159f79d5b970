# SPDX-License-Identifier: Apache-2.0
# Shared by image/farm/build, image/farm/provision and the farm's QEMU test (sourced, bash).
#
# Disk layout of mogao-farm.img (GPT, 512-byte sectors, partitions aligned to 1 MiB):
#   1  ESP        FAT32, label ESP         systemd-boot, kernel, initramfs, loader entry
#   2  farm-root  ext4, label farm-root    mounted read-write at /
# Partition names (GPT) equal the file system labels.

MOGAO_FARM_ROOT_LABEL=farm-root
MOGAO_FARM_UID=971   # rootfs/usr/lib/sysusers.d/mogao-farm.conf
MOGAO_FARM_GID=971
# The render hosts' packet filter; provisioning checks farm-network files with its parser.
FARM_FIREWALL="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/rootfs/usr/lib/mogao/farm-firewall"

# farm_check_host_dir DIR: dies with the file and field at fault when DIR (image/farm/provision's
# HOST_DIR) is inconsistent. An admin host (etc/mogao/farm-hosts) needs farm.env and its PKI.
farm_check_host_dir() {
  local dir=$1 f line n=0 slots=0 key value
  f="$dir/etc/hostname"
  if [[ -f "$f" ]]; then
    [[ $(wc -l < "$f") -le 1 ]] && grep -qE '^[a-z0-9]([a-z0-9-]{0,62})$' "$f" \
      || img_die "$f: one host name (lower-case letters, digits, '-') expected"
  fi
  # Every host filters its ports by it (mogao-farm-firewall.service): without it, Open MPI's
  # ports would be closed to the other hosts too. Checked by the filter's own parser, so that
  # what provisioning accepts is what the host loads at boot.
  f="$dir/etc/mogao/farm-network"
  [[ -f "$f" ]] || img_die "$f missing: the farm network's prefixes, one per line (e.g. 10.77.0.0/24), from which Open MPI's ports may be reached"
  local why
  if ! why=$(sh "$FARM_FIREWALL" --print "$f" 2>&1 > /dev/null); then
    why=${why#mogao-farm-firewall: }
    img_die "${why%%: Open MPI*}"
  fi
  n=0
  [[ -f "$dir/etc/mogao/farm-hosts" ]] || return 0
  f="$dir/etc/mogao/farm-hosts"
  while IFS= read -r line || [[ -n "$line" ]]; do
    n=$((n + 1))
    line=${line%%#*}
    [[ -z "${line// /}" ]] && continue
    [[ "$line" =~ ^[[:space:]]*[A-Za-z0-9.:-]+([[:space:]]+slots=([0-9]+))?([[:space:]]+max_slots=[0-9]+)?[[:space:]]*$ ]] \
      || img_die "$f line $n: 'HOST slots=N' expected, not '$line'"
    slots=$((slots + ${BASH_REMATCH[2]:-1}))
  done < "$f"
  ((slots > 0)) || img_die "$f: no hosts"
  f="$dir/etc/mogao/farm.env"
  [[ -f "$f" ]] || img_die "$dir/etc/mogao/farm-hosts without $f (MOGAO_RANKS, MOGAO_SCENE, MOGAO_LISTEN, MOGAO_FARM_NAME)"
  local -A env=()
  n=0
  while IFS= read -r line || [[ -n "$line" ]]; do
    n=$((n + 1))
    [[ "$line" =~ ^[[:space:]]*(#.*)?$ ]] && continue
    [[ "$line" =~ ^([A-Za-z_][A-Za-z0-9_]*)=(.*)$ ]] || img_die "$f line $n: KEY=VALUE expected, not '$line'"
    key=${BASH_REMATCH[1]} value=${BASH_REMATCH[2]}
    env[$key]=$value
  done < "$f"
  for key in MOGAO_RANKS MOGAO_SCENE MOGAO_LISTEN MOGAO_FARM_NAME; do
    [[ -n "${env[$key]:-}" ]] || img_die "$f: $key is not set"
  done
  [[ "${env[MOGAO_RANKS]}" =~ ^[0-9]+$ && "${env[MOGAO_RANKS]}" -ge 2 ]] \
    || img_die "$f: MOGAO_RANKS must be a number >= 2 (the admin rank and at least one render rank), not '${env[MOGAO_RANKS]}'"
  (("${env[MOGAO_RANKS]}" <= slots)) || img_die "$f: MOGAO_RANKS=${env[MOGAO_RANKS]} but $dir/etc/mogao/farm-hosts has $slots slots"
  [[ "${env[MOGAO_SCENE]}" == /* ]] || img_die "$f: MOGAO_SCENE must be an absolute path on the hosts, not '${env[MOGAO_SCENE]}'"
  [[ "${env[MOGAO_LISTEN]}" =~ ^\[[0-9A-Fa-f:.]+\]:[0-9]+$ ]] \
    || img_die "$f: MOGAO_LISTEN must be an IPv6 endpoint like [::]:7443, not '${env[MOGAO_LISTEN]}'"
  for key in ca.pem "farm-${env[MOGAO_FARM_NAME]}.pem" "farm-${env[MOGAO_FARM_NAME]}.key"; do
    [[ -s "$dir/etc/mogao/pki/$key" ]] || img_die "$dir/etc/mogao/pki/$key missing (mogao-farm pki init-ca / issue-farm --name ${env[MOGAO_FARM_NAME]})"
  done
  # The CA's key signs appliance certificates: it stays offline, never on a networked farm host.
  [[ ! -e "$dir/etc/mogao/pki/ca.key" ]] \
    || img_die "$dir/etc/mogao/pki/ca.key: the CA's private key must not go onto a farm host (copy the folder made by mogao-farm pki export-farm)"
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
