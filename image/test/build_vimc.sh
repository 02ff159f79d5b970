#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Builds vimc.ko (the kernel's virtual media-controller camera, drivers/media/test-drivers/vimc) for
# the appliance's kernel, for the QEMU test only: Debian 12's kernel is built without it
# (CONFIG_VIDEO_VIMC is not set in /boot/config-6.1.0-*-amd64), and it is the one virtual camera
# libcamera has a pipeline handler for (vivid is matched by none). The shipped image never has it.
#
#   build_vimc.sh KVER OUTDIR      prints the path of OUTDIR/vimc-KVER-VERSION.ko (cached)
#
# Needs the host packages linux-headers-KVER (of the image kernel's version: modversions, another
# version's symbol CRCs are refused by the kernel) and linux-source-X.Y of the same upstream version.
# The symbol CRCs come from the headers, so the source may differ in its Debian revision only (the
# security archive can move linux-source ahead of the kernel: 6.1.192-3 beside headers 6.1.192-2).
# Exit 77 with the reason on stderr when they are missing or differ; 1 when the build fails.
set -u
kver=$1 out=$2
why() { echo "$*" >&2; exit 77; }
headers=/usr/src/linux-headers-$kver
[[ -f $headers/Makefile ]] || why "no $headers (apt-get install linux-headers-$kver)"
series=$(echo "$kver" | grep -oE '^[0-9]+\.[0-9]+')
source_tar=/usr/src/linux-source-$series.tar.xz
[[ -f $source_tar ]] || why "no $source_tar (apt-get install linux-source-$series)"
hv=$(dpkg-query -W -f='${Version}' "linux-headers-$kver" 2>/dev/null)
sv=$(dpkg-query -W -f='${Version}' "linux-source-$series" 2>/dev/null)
[[ -n $hv && ${hv%-*} == "${sv%-*}" ]] \
  || why "linux-headers-$kver is '$hv' but linux-source-$series is '$sv': they must be the same upstream version"
ko=$out/vimc-$kver-$hv.ko
if [[ -s $ko ]]; then echo "$ko"; exit 0; fi

mkdir -p "$out"
src=$(mktemp -d "$out/vimc-src.XXXXXX")
trap 'rm -rf "$src"' EXIT
tar -xJf "$source_tar" -C "$src" --strip-components=1 --wildcards \
    "linux-source-$series/drivers/media/test-drivers/vimc/*" \
  || { echo "extracting vimc from $source_tar failed" >&2; exit 1; }
dir=$src/drivers/media/test-drivers/vimc
make -s -C "$headers" M="$dir" CONFIG_VIDEO_VIMC=m modules -j"$(nproc)" > "$src/build.log" 2>&1 \
  || { cat "$src/build.log" >&2; echo "building vimc.ko against $headers failed" >&2; exit 1; }
strip --strip-debug -o "$ko.tmp" "$dir/vimc.ko" && mv "$ko.tmp" "$ko" || exit 1
echo "$ko"
