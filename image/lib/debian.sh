# SPDX-License-Identifier: Apache-2.0
# Steps of a bootable Debian 12 disk image (raw, GPT, UEFI + systemd-boot) from packages, without
# loop devices or mounts: mmdebstrap into a folder, mke2fs -d, mkfs.vfat + mtools, sfdisk + dd.
# Sourced (bash) after common.sh by image/farm/build; image/build does the same steps inline for the
# appliance (and can move onto these). Every function dies (img_die) with what went wrong.

# img_uuid_of NAME: a version-4-shaped UUID derived from NAME and SOURCE_DATE_EPOCH, so that the
# same inputs give the same image (file systems, partitions, disk).
img_uuid_of() {
  local h
  h=$(printf 'mogao:%s:%s' "$1" "${SOURCE_DATE_EPOCH:?SOURCE_DATE_EPOCH not set}" | sha256sum | cut -c1-32)
  printf '%s-%s-4%s-8%s-%s\n' "${h:0:8}" "${h:8:4}" "${h:13:3}" "${h:17:3}" "${h:20:12}"
}

# img_binary_packages BINARY: the Debian packages (of this build host, which must be Debian 12 like
# the image) that ship BINARY's shared libraries, one per line. Libraries loaded with dlopen are
# invisible to ldd: callers add those packages by name.
img_binary_packages() {
  local bin=$1 libs owners
  ldd "$bin" >/dev/null 2>&1 || img_die "ldd cannot read $bin"
  if ldd "$bin" | grep -q "not found"; then
    img_die "$bin has unresolved libraries: $(ldd "$bin" | grep 'not found' | tr -s ' \t\n' ' ')"
  fi
  libs=$(ldd "$bin" | awk '/=> \// { print $3 } /^\t\/.*ld-linux/ { print $1 }' | sort -u)
  # merged /usr: dpkg knows a library under the path its package ships, /lib or /usr/lib. One
  # dpkg-query for every candidate path (one per library is slow).
  owners=$(while read -r lib; do printf '%s\n' "$lib" "$(readlink -f "$lib")" "/usr$lib" "${lib#/usr}"; done \
      <<<"$libs" |
           sort -u | { xargs dpkg-query -S 2>/dev/null || true; } | sed -E 's/^([^:]+)(:[a-z0-9]+)?: /\1 /')
  while read -r lib; do
    local pkg="" cand
    for cand in "$lib" "$(readlink -f "$lib")" "/usr$lib" "${lib#/usr}"; do
      pkg=$(awk -v p="$cand" '$2 == p { print $1; exit }' <<<"$owners")
      [[ -n "$pkg" ]] && break
    done
    [[ -n "$pkg" ]] || img_die "no Debian package ships $lib (needed by $bin)"
    echo "$pkg"
  done <<<"$libs" | sort -u
  [[ -n "$owners" ]] || img_die "dpkg-query knows none of the libraries of $bin"
}

# img_mmdebstrap ROOT LOG CACHE PACKAGES [MMDEBSTRAP_ARGS...]: Debian $IMG_SUITE (default bookworm)
# with the comma-separated PACKAGES into the folder ROOT (essential variant, merged /usr, no
# recommends), from $IMG_MIRROR and $IMG_SECURITY_MIRROR. CACHE (may be empty): a folder of .deb
# files reused and filled, so that repeated builds download only what changed. Output goes to LOG.
img_mmdebstrap() {
  local root=$1 log=$2 cache=$3 pkgs=$4; shift 4
  local suite=${IMG_SUITE:-bookworm}
  local mirror=${IMG_MIRROR:-http://deb.debian.org/debian}
  local security=${IMG_SECURITY_MIRROR:-http://deb.debian.org/debian-security}
  local args=(--mode=root --skip=chroot/mount --variant=essential
              --hook-dir=/usr/share/mmdebstrap/hooks/merged-usr
              --aptopt='Acquire::Retries "3"' --aptopt='APT::Install-Recommends "false"'
              --include="$pkgs" "$@")
  if [[ -n "$cache" ]]; then
    mkdir -p "$cache"
    cache=$(cd "$cache" && pwd)
    args+=(--skip=essential/unlink
           --setup-hook="mkdir -p \"\$1/var/cache/apt/archives\";
                         find '$cache' -maxdepth 1 -name '*.deb' -exec cp -t \"\$1/var/cache/apt/archives/\" {} +"
           --customize-hook="find \"\$1/var/cache/apt/archives\" -maxdepth 1 -name '*.deb' \
                             -exec cp -n -t '$cache/' {} +")
  fi
  mmdebstrap "${args[@]}" "$suite" "$root" \
    "deb $mirror $suite main" "deb $mirror $suite-updates main" "deb $security $suite-security main" \
    > "$log" 2>&1 || { tail -n 40 "$log" >&2; img_die "mmdebstrap failed (log: $log)"; }
}

# img_in_root ROOT COMMAND...: COMMAND inside ROOT (chroot) with a clean environment.
img_in_root() {
  local root=$1; shift
  chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin LC_ALL=C.UTF-8 SOURCE_DATE_EPOCH="$SOURCE_DATE_EPOCH" "$@"
}

# img_kernel ROOT ALLOW_LIST LOG: keeps the kernel modules ALLOW_LIST names (prune_modules.py, with
# their dependencies), compresses them (kmod reads .ko.xz), rebuilds the index and the initramfs
# (initramfs-tools configuration must be in ROOT already). Prints the kernel version.
img_kernel() {
  local root=$1 allow=$2 log=$3 kver
  kver=$(ls "$root/usr/lib/modules" | sort -V | tail -n1)
  [[ -n "$kver" ]] || img_die "no kernel in $root/usr/lib/modules"
  python3 "$(dirname "${BASH_SOURCE[0]}")/prune_modules.py" "$root/usr/lib/modules/$kver" "$allow" >&2
  find "$root/usr/lib/modules/$kver/kernel" -name '*.ko' -print0 |
      xargs -0 -r -n 64 -P "$(nproc)" xz -q --check=crc32 -T1
  img_in_root "$root" depmod -a "$kver"
  img_in_root "$root" update-initramfs -u -k "$kver" > "$log" 2>&1 ||
      { cat "$log" >&2; img_die "update-initramfs failed"; }
  echo "$kver"
}

# img_trim ROOT: drops documentation (copyright files and /usr/share/doc/mogao stay), manuals,
# translations, apt lists and caches, backup files and the time-stamped ldconfig cache; creates
# what tmpfiles.d declares (mmdebstrap without mounts misses some folders).
img_trim() {
  local root=$1
  find "$root/usr/share/doc" -mindepth 1 -not -name copyright -not -path "$root/usr/share/doc/mogao*" \( \
      -type f -o -type l \) -delete
  find "$root/usr/share/doc" -mindepth 1 -type d -empty -delete
  rm -rf "$root/usr/share/man" "$root/usr/share/info" "$root/usr/share/lintian" "$root/usr/share/locale" \
    "$root/var/cache/apt" "$root/var/lib/apt/lists" "$root/var/cache/debconf/"*-old "$root/var/lib/dpkg/"*-old
  img_in_root "$root" ldconfig
  rm -f "$root/var/cache/ldconfig/aux-cache"
  systemd-tmpfiles --root="$root" --create >/dev/null 2>&1 || true
}

# img_esp FILE SIZE_MIB ROOT KVER TITLE CMDLINE: a FAT32 ESP with systemd-boot (the removable-media
# path and its own), ROOT's kernel KVER and initramfs, one loader entry (mogao.conf, no menu).
img_esp() {
  local file=$1 mib=$2 root=$3 kver=$4 title=$5 cmdline=$6 stage
  local sdboot=/usr/lib/systemd/boot/efi/systemd-bootx64.efi
  [[ -f $sdboot ]] || img_die "missing $sdboot (apt-get install systemd-boot-efi)"
  stage=$(mktemp -d)
  rm -f "$file"; truncate -s "${mib}M" "$file"
  mkfs.vfat -F 32 -n ESP --invariant -i "$(printf '%08X' $((SOURCE_DATE_EPOCH & 0xffffffff)))" "$file" >/dev/null \
    || img_die "mkfs.vfat $file failed"
  printf 'default mogao.conf\ntimeout 0\neditor no\nauto-entries no\nauto-firmware no\nconsole-mode keep\n' \
      > "$stage/loader.conf"
  printf 'title %s\nversion %s\nlinux /mogao/vmlinuz\ninitrd /mogao/initrd.img\noptions %s\n' \
    "$title" "$kver" "$cmdline" > "$stage/mogao.conf"
  cp "$sdboot" "$stage/BOOTX64.EFI"
  cp "$root/boot/vmlinuz-$kver" "$stage/vmlinuz"
  cp "$root/boot/initrd.img-$kver" "$stage/initrd.img"
  touch --date="@$SOURCE_DATE_EPOCH" "$stage/"*
  export MTOOLS_SKIP_CHECK=1
  { mmd -i "$file" ::/EFI ::/EFI/BOOT ::/EFI/systemd ::/loader ::/loader/entries ::/mogao &&
    mcopy -m -i "$file" "$stage/BOOTX64.EFI" ::/EFI/BOOT/BOOTX64.EFI &&
    mcopy -m -i "$file" "$stage/BOOTX64.EFI" ::/EFI/systemd/systemd-bootx64.efi &&
    mcopy -m -i "$file" "$stage/vmlinuz" "$stage/initrd.img" ::/mogao/ &&
    mcopy -m -i "$file" "$stage/loader.conf" ::/loader/loader.conf &&
    mcopy -m -i "$file" "$stage/mogao.conf" ::/loader/entries/mogao.conf; } || img_die "mtools on $file failed"
  rm -rf "$stage"
}

# img_ext4 ROOT FILE LABEL SPARE_MIB [MKE2FS_OPTIONS...]: an ext4 file system of ROOT's content
# (mke2fs -d) in FILE, sized to the content + 15 % + SPARE_MIB, time stamps clamped, checked.
# Prints its size in MiB.
img_ext4() {
  local root=$1 file=$2 label=$3 spare=$4; shift 4
  local kib files mib
  kib=$(du -sk --apparent-size "$root" | cut -f1)
  files=$(find "$root" | wc -l)
  mib=$(( (kib * 115 / 100 + 65536) / 1024 + spare ))
  find "$root" -newermt "@$SOURCE_DATE_EPOCH" -print0 | xargs -0 -r touch --no-dereference --date="@$SOURCE_DATE_EPOCH"
  rm -f "$file"; truncate -s "${mib}M" "$file"
  E2FSPROGS_FAKE_TIME=$SOURCE_DATE_EPOCH mke2fs -q -F -t ext4 -L "$label" -U "$(img_uuid_of "$label-fs")" \
    -E "root_owner=0:0,hash_seed=$(img_uuid_of "$label-hash")" -m 0 -N $((files + 4096)) "$@" \
    -d "$root" "$file" || img_die "mke2fs of $label ($file) failed"
  img_clamp_times "$file" "$SOURCE_DATE_EPOCH"
  e2fsck -fn "$file" > "$file.e2fsck.log" 2>&1 || { cat "$file.e2fsck.log" >&2; img_die "e2fsck of $label failed"; }
  rm -f "$file.e2fsck.log"
  echo "$mib"
}

# img_disk IMAGE NAME:TYPE:FILE[:ATTRS]...: a GPT disk of the given partitions in order (1 MiB
# aligned, each as large as its FILE), written with dd. TYPE: esp | root (x86-64 root) | linux.
img_disk() {
  local image=$1; shift
  local total=2 spec name type file attrs guid mib table n=0
  table=$(printf 'label: gpt\nlabel-id: %s\nunit: sectors\nfirst-lba: 2048\n' "$(img_uuid_of disk)")
  for spec in "$@"; do
    IFS=: read -r name type file attrs <<<"$spec"
    case $type in
      esp) guid=C12A7328-F81F-11D2-BA4B-00A0C93EC93B ;;
      root) guid=4F68BCE3-E8CD-4DB1-96E7-FBCAF984B709 ;;
      linux) guid=0FC63DAF-8483-4772-8E79-3D69D8477DE4 ;;
      *) img_die "img_disk: partition type '$type' of $name (esp, root or linux)" ;;
    esac
    mib=$(( ($(stat -c %s "$file") + 1048575) / 1048576 ))
    total=$((total + mib))
    table+=$'\n'"size=$((mib * 2048)), type=$guid, uuid=$(img_uuid_of "$name-part"), name=\"$name\""
    [[ -n "$attrs" ]] && table+=", attrs=\"$attrs\""
  done
  rm -f "$image" "$image.sha256" "$image.bmap"
  truncate -s "${total}M" "$image"
  sfdisk -q --no-reread --no-tell-kernel "$image" > /dev/null <<<"$table" || img_die "sfdisk on $image failed"
  for spec in "$@"; do
    n=$((n + 1))
    IFS=: read -r name type file attrs <<<"$spec"
    img_place "$image" "$n" "$file"
  done
  touch --date="@$SOURCE_DATE_EPOCH" "$image"
}

# img_ext4_put FILE STAGING: copies the tree STAGING (files, folders, symbolic links, with their
# modes and owners) into the ext4 file system FILE with debugfs, replacing files that are there:
# changes a built root file system without mounting it. Folders that exist keep their content,
# owner and mode.
img_ext4_put() {
  local file=$1 staging=$2 script existing out
  script=$(mktemp); existing=$(mktemp)
  # debugfs's mkdir of a folder that exists leaves an orphaned inode: find the existing ones first.
  ( cd "$staging" && find . -mindepth 1 -type d -printf 'stat "/%P"\n' ) > "$script"
  DEBUGFS_PAGER=__none__ debugfs -f "$script" "$file" 2>&1 |
    awk '/^debugfs: stat "/ { p = substr($0, 16); sub(/"$/, "", p) } /^Inode: .*Type: directory/ { print p }' > \
        "$existing"
  ( cd "$staging" && find . -mindepth 1 -printf '%y %m %U %G %P\n' ) | while read -r type mode uid gid rel; do
    local path=/$rel kind=10
    case $type in
      d) kind=04; grep -qxF "$path" "$existing" && continue; printf 'mkdir "%s"\n' "$path" ;;
      f) printf 'rm "%s"\nwrite "%s" "%s"\n' "$path" "$staging/$rel" "$path" ;;
      l) printf 'rm "%s"\nsymlink "%s" "%s"\n' "$path" "$path" "$(readlink "$staging/$rel")"; continue ;;
      *) img_die "$staging/$rel: only files, folders and symbolic links can be provisioned" ;;
    esac
    printf 'sif "%s" mode 0%s%04o\nsif "%s" uid %s\nsif "%s" gid %s\n' "$path" "$kind" "$((8#$mode))" \
        "$path" "$uid" "$path" "$gid"
  done > "$script"
  out=$(debugfs -w -f "$script" "$file" 2>&1) || img_die "debugfs on $file failed: $out"
  rm -f "$script" "$existing"
  # Expected noise: the echoed commands, "rm" of a file that is not there yet, inode numbers.
  out=$(grep -vE '^debugfs [0-9.]+ |^debugfs: |^Allocated inode: [0-9]+$|File not found by ext2_lookup|^$' \
      <<<"$out" || true)
  [[ -z "$out" ]] || img_die "debugfs could not write into $file: $out"
  e2fsck -fn "$file" > /dev/null 2>&1 || img_die "e2fsck of $file failed after provisioning"
}
