#!/usr/bin/env python3
"""Checks that dependencies between the library's folders point one way (README, Layout).

Every #include "..." in src/ and include/focal/ that names a file of another folder must name a
folder listed before its own in LAYERS. Prints each upward edge (file:line -> included) and
exits 1 if there is one. Run by ctest (the `layers` test).
"""
import pathlib
import re
import sys

# Lowest first: a folder may include itself and the folders before it.
LAYERS = ["core", "kernels", "io", "mesh", "points", "normals", "curvature", "tiles", "cuda",
          "image_space", "surfaces", "evaluation", "render", "front"]

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(path: str):
    """The layer of an include path ("focal/mesh/check.h", "curvature/detail.h") or a file.
    The public headers at the top of include/focal (the front door, focal/curvature.h) are the
    top layer, "front"."""
    parts = pathlib.PurePosixPath(path).parts
    if parts and parts[0] == "focal":
        parts = parts[1:]
        if len(parts) == 1 and parts[0].endswith(".h"):
            return "front"
    return parts[0] if parts and parts[0] in LAYERS else None


edges = upward = 0
for base in (root / "src", root / "include" / "focal"):
    for path in sorted(base.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".cu") or not path.is_file():
            continue
        if path == root / "include" / "focal" / "focal.h":
            continue  # the one header that includes everything
        relative = str(path.relative_to(base))
        own = folder_of("focal/" + relative if base.name == "focal" else relative)
        if own is None:
            print(f"{path.relative_to(root)}: not in a layer folder")
            upward += 1
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            m = include.match(line)
            if not m:
                continue
            target = folder_of(m.group(1))
            if target is None or target == own:
                continue
            edges += 1
            if LAYERS.index(target) > LAYERS.index(own):
                upward += 1
                print(f"{path.relative_to(root)}:{number}: {own} includes {m.group(1)} ({target})")
print(f"{edges} include edges between folders, {upward} upward")
sys.exit(1 if upward else 0)
