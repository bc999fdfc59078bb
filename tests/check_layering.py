#!/usr/bin/env python3
"""Checks that no #include in lib/ runs against the library's layering (README, "Layout").

Each folder of lib/ is a layer, and each public header (lib/include/homcull/) belongs to one.
A file may include the public headers of its own layer and of the layers below it, and the
private headers (lib/<layer>/...) of its own layer and of the layers whose internals it is
built on (PRIVATE_USES). Usage: check_layering.py [repository root]. Exit status 1 and one
line per include that breaks the rules; 0 when there is none.
"""
import os
import re
import sys

# The layers below each layer, whose public headers it may include.
USES = {
    "common": set(),
    "raster": {"common"},
    "buffer": {"common", "raster"},
    "hom": {"common", "raster", "buffer"},
    "capi": {"common", "raster", "buffer", "sort"},
    "sort": {"common"},
    "scene": {"common", "raster", "buffer", "hom", "sort"},
    "tbb": {"common"},
    "truth": {"common", "raster", "buffer", "hom", "sort", "scene"},
    "io": {"common", "raster", "buffer", "hom", "sort", "scene", "truth"},
}
# The layers whose private headers a layer may include besides its own: common's helpers are
# everyone's; the buffer is built on the rasterizer's internals, and the occlusion maps and the
# C interface on the buffer's.
PRIVATE_USES = {layer: {"common"} for layer in USES}
PRIVATE_USES["buffer"] |= {"raster"}
PRIVATE_USES["hom"] |= {"raster", "buffer"}
PRIVATE_USES["capi"] |= {"raster", "buffer"}

# The layer of each public header (homcull/truth/* and homcull/io/* are truth's and io's).
PUBLIC = {
    "common": ["error.hpp", "aabb.hpp", "camera.hpp", "frustum.hpp", "isa.hpp", "parallel_for.hpp", "detail/memory.hpp"],
    "raster": ["triangle_input.hpp"],
    "buffer": ["occlusion_buffer.hpp", "occluder_clusters.hpp"],
    "hom": ["occlusion_maps.hpp"],
    "capi": ["homcull.h", "homcull.hpp"],
    "sort": ["visibility_sort.hpp"],
    "scene": ["scene.hpp", "generate.hpp", "object_hierarchy.hpp", "occluder_lod.hpp", "occluder_selection.hpp",
              "scene_culler.hpp", "scene_sort.hpp", "soup_subdivision.hpp", "visibility_grid.hpp", "world_triangles.hpp"],
    "tbb": ["tbb_parallel_for.hpp"],
}
PUBLIC_LAYER = {header: layer for layer, headers in PUBLIC.items() for header in headers}

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def public_layer(header):
    """The layer of a public header named as after "homcull/", or None when it is unknown."""
    first = header.split("/")[0]
    if first in ("truth", "io") and "/" in header:
        return first
    return PUBLIC_LAYER.get(header)


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    lib = os.path.join(root, "lib")
    problems, checked = [], 0
    for folder, _, names in os.walk(lib):
        for name in sorted(names):
            if not re.search(r"\.(c|cpp|h|hpp)$", name):
                continue
            path = os.path.join(folder, name)
            relative = os.path.relpath(path, lib).replace(os.sep, "/")
            if relative.startswith("include/homcull/"):
                layer = public_layer(relative[len("include/homcull/"):])
                if layer is None:
                    problems.append(f"lib/{relative}: a public header of no layer (add it to PUBLIC in tests/check_layering.py)")
                    continue
            else:
                layer = relative.split("/")[0]
                if layer not in USES:
                    problems.append(f"lib/{relative}: in lib/{layer}/, which is not a layer (add it to USES in tests/check_layering.py)")
                    continue
            checked += 1
            with open(path, encoding="utf-8") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = m.group(2)
                    where = f"lib/{relative}:{number}: {layer} includes {target}"
                    if target.startswith("homcull/"):
                        to = public_layer(target[len("homcull/"):])
                        if to is None:
                            problems.append(f"{where}, a public header of no layer")
                        elif to != layer and to not in USES[layer]:
                            problems.append(f"{where}, a public header of {to}, which {layer} does not use")
                    elif m.group(1) == '"':
                        to = target.split("/")[0]
                        if "/" not in target or to not in USES:
                            continue  # a file of the same folder, or a third-party header
                        if to != layer and to not in PRIVATE_USES[layer]:
                            problems.append(f"{where}, a private header of {to}")
    for p in problems:
        print(p)
    print(f"check_layering: {checked} files, {len(problems)} includes against the layering", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
