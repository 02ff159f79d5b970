#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Prune a kernel's module tree to an allowlist plus its dependencies (image/build).

prune_modules.py MODULES_DIR ALLOWLIST
  MODULES_DIR: /usr/lib/modules/VERSION inside the root file system (with modules.dep)
  ALLOWLIST:   regular expressions, one per line, matched at the start of each module's path below
               kernel/ (blank lines and # comments ignored)
Deletes every module that is neither allowed nor needed by an allowed one (modules.dep), then
empty folders; prints what it kept. The caller runs depmod afterwards.
"""
import os
import re
import sys


def main() -> int:
    moddir, allowfile = sys.argv[1], sys.argv[2]
    patterns = []
    for line in open(allowfile, encoding="utf-8"):
        line = line.strip()
        if line and not line.startswith("#"):
            patterns.append(re.compile(line))
    deps = {}
    for line in open(os.path.join(moddir, "modules.dep"), encoding="utf-8"):
        mod, _, rest = line.partition(":")
        deps[mod.strip()] = rest.split()
    keep = set()
    todo = [m for m in deps if any(p.match(m[len("kernel/"):]) for p in patterns)]
    while todo:
        m = todo.pop()
        if m in keep:
            continue
        keep.add(m)
        todo.extend(deps.get(m, []))
    removed = removed_bytes = kept_bytes = 0
    for mod in deps:
        path = os.path.join(moddir, mod)
        if not os.path.exists(path):
            continue
        size = os.path.getsize(path)
        if mod in keep:
            kept_bytes += size
        else:
            os.remove(path)
            removed += 1
            removed_bytes += size
    for root, dirs, files in os.walk(os.path.join(moddir, "kernel"), topdown=False):
        if not os.listdir(root):
            os.rmdir(root)
    print(f"modules: kept {len(keep)} ({kept_bytes / 2**20:.1f} MiB), "
          f"removed {removed} ({removed_bytes / 2**20:.1f} MiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
