# SPDX-License-Identifier: Apache-2.0
"""The libcamera part of the QEMU test's test disk (qemu_boot_test.py): vimc.ko built for the image's
kernel (build_vimc.sh), mogao_libcamera_test, mogao-camera and mogao-track with the libraries they
need, and libcamera's vimc IPA (module, signature, proxy, vimc.conf) from the host's libcamera-ipa
package. The guest side is
selftest.sh ("libcamera-capture-test"). Nothing of this is in the shipped image.
"""
import os
import re
import shutil
import struct
import subprocess

IPA_DIR = "/usr/lib/x86_64-linux-gnu/libcamera"      # Debian 12, package libcamera-ipa
IPA_CONF = "/usr/share/libcamera/ipa/vimc/vimc.conf"
IPA_FILES = ("ipa_vimc.so", "ipa_vimc.so.sign", "vimc_ipa_proxy")
GLIBC = re.compile(r"^(libc|libm|libpthread|libdl|librt|ld-linux.*)\.so")


def kernel_version(vmlinuz):
    """The version string of a bzImage (boot protocol: setup header field kernel_version at 0x20e,
    an offset from 0x200 to a NUL-terminated string), e.g. '6.1.0-56-amd64'; None if unreadable."""
    with open(vmlinuz, "rb") as f:
        data = f.read(64 * 1024)
    if len(data) < 0x210 or data[0x202:0x206] != b"HdrS":
        return None
    (offset,) = struct.unpack_from("<H", data, 0x20E)
    text = data[offset + 0x200:offset + 0x200 + 256].split(b"\0")[0].decode("ascii", "replace")
    return text.split()[0] if text else None


def copy_with_libraries(binary, disk, name):
    shutil.copy(binary, os.path.join(disk, "bin", name))
    out = subprocess.run(["ldd", binary], check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        m = re.search(r"=> (/\S+)", line)
        if m and not GLIBC.match(os.path.basename(m.group(1))):
            dest = os.path.join(disk, "lib", os.path.basename(m.group(1)))
            if not os.path.exists(dest):
                shutil.copy(m.group(1), dest)


def stage_tools(test_binary, disk):
    """The commands a technician points at a libcamera camera, from the build the test binary is in
    (BUILD/drivers/camera/mogao_libcamera_test): mogao-camera (info libcamera:) and mogao-track
    (navigate --camera libcamera:). selftest.sh runs each one it finds. Returns their names."""
    build = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(test_binary))))
    staged = []
    for rel in (os.path.join("drivers", "camera", "mogao-camera"), os.path.join("appliance", "tools", "mogao-track")):
        path = os.path.join(build, rel)
        if os.access(path, os.X_OK):
            copy_with_libraries(path, disk, os.path.basename(rel))
            staged.append(os.path.basename(rel))
    return staged


def stage(repo, work, disk, vmlinuz, test_binary):
    """Puts vimc.ko, the test and the IPA on the test disk. Returns (True, what) or (False, why)."""
    if not test_binary or not os.access(test_binary, os.X_OK):
        return False, "no mogao_libcamera_test binary given (built without libcamera?)"
    missing = [f for f in (*[os.path.join(IPA_DIR, n) for n in IPA_FILES], IPA_CONF) if not os.path.exists(f)]
    if missing:
        return False, f"libcamera's vimc IPA is not on this host ({', '.join(missing)}; apt-get install libcamera-ipa)"
    kver = kernel_version(vmlinuz)
    if not kver:
        return False, f"cannot read the kernel version of {vmlinuz}"
    build = subprocess.run(["bash", os.path.join(repo, "image", "test", "build_vimc.sh"), kver,
                            os.path.join(work, "vimc")], capture_output=True, text=True)
    if build.returncode != 0:
        return False, f"vimc.ko for {kver} not built: {build.stderr.strip()[-600:]}"
    shutil.copy(build.stdout.strip().splitlines()[-1], os.path.join(disk, "vimc.ko"))
    copy_with_libraries(test_binary, disk, "mogao_libcamera_test")
    tools = stage_tools(test_binary, disk)
    ipa = os.path.join(disk, "libcamera", "ipa")
    conf = os.path.join(disk, "libcamera", "conf", "vimc")
    os.makedirs(ipa)
    os.makedirs(conf)
    for n in IPA_FILES:
        shutil.copy(os.path.join(IPA_DIR, n), os.path.join(ipa, n))
    shutil.copy(IPA_CONF, os.path.join(conf, "vimc.conf"))
    return True, f"vimc.ko for {kver}, {test_binary}, {', '.join(tools) or 'no tools'}, libcamera's vimc IPA"
