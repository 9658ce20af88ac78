#!/usr/bin/env python3
"""Checks that dependencies between the library's folders point one way (README, Layout).

Every #include "..." in src/ and include/focal/ that names a file of another folder must name a
folder listed before its own in LAYERS, unless the edge is one of ALLOWED_UPWARD. The core
library (focal::focal, the folders of CORE) includes no folder of the libraries built on it
(surfaces, evaluation, render), and src/CMakeLists.txt compiles none of their sources into it.
Prints each violation (file:line and what it names) and exits 1 if there is one. Run by ctest
(the `layers` test).
"""
import pathlib
import re
import sys

# Lowest first: a folder may include itself and the folders before it.
LAYERS = ["core", "kernels", "io", "mesh", "points", "normals", "curvature", "smoothing", "tiles", "cuda",
          "image_space", "front", "surfaces", "evaluation", "render"]

# The core library's folders, the first of LAYERS; the rest are libraries of their own on top of
# it: focal::surfaces (analytic test surfaces), focal::evaluation (error metrics against them),
# focal::render (OpenGL pictures).
CORE = LAYERS[:LAYERS.index("front") + 1]

# Upward includes that the design needs, each with its reason. check_mesh (mesh/) compares the
# given normals with the faces' area-weighted ones, which normals/ computes on the incidence the
# check already has; normals/ builds on mesh/'s prepared mesh and incidence, so neither folder
# can sit below the other.
ALLOWED_UPWARD = {
    ("src/mesh/check.cpp", "focal/normals/vertex_normals.h"),
    ("src/mesh/check.cpp", "normals/vertex_normals_from.h"),
}

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(path: str):
    """The layer of an include path ("focal/mesh/check.h", "mesh/prepared_access.h") or a file.
    The public headers at the top of include/focal (the front door, focal/curvature.h) are the
    layer "front", above every folder of the core library."""
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
            relative = path.relative_to(root).as_posix()
            if own in CORE and target not in CORE:
                upward += 1
                print(f"{relative}:{number}: the core library includes {m.group(1)} "
                      f"(the {target} library)")
            elif (LAYERS.index(target) > LAYERS.index(own)
                  and (relative, m.group(1)) not in ALLOWED_UPWARD):
                upward += 1
                print(f"{relative}:{number}: {own} includes {m.group(1)} ({target})")

# The sources of the core target: add_library(focal ...) and target_sources(focal ...).
cmake = (root / "src" / "CMakeLists.txt").read_text()
cmake = re.sub(r"#[^\n]*", "", cmake)
for call in re.finditer(r"\b(?:add_library|target_sources)\(\s*focal\s([^)]*)\)", cmake):
    for source in re.findall(r"[\w./-]+\.(?:cpp|cu)\b", call.group(1)):
        folder = source.split("/")[0]
        if folder not in CORE:
            upward += 1
            print(f"src/CMakeLists.txt: the core library compiles {source} ({folder})")
print(f"{edges} include edges between folders, {upward} violations")
sys.exit(1 if upward else 0)
