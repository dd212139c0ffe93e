#!/usr/bin/env python3
"""Writes tabletop_translucent.gltf: the bundled tabletop scene with a virtual translucent object.

Python standard library only; run after make_tabletop.py:
    python3 data/scenes/tabletop/make_tabletop_translucent.py
Same buffers, materials, lights, cameras and environment as tabletop.gltf, plus a VIRTUAL
"jade" cube (6 cm, on the table in front of the board) with a spherical cavity inside (the voxel
number map paper's own example: one mesh of two primitives, the box and the cavity's inward-facing
sphere, sharing one material). Its medium is MIRAGE_materials_scattering (docs/scene.md):
extinction 120 / m, a green albedo, IOR 1.5, and a density grid jade_density.nrrd (8^3 float32)
that rises from 0.4 to 1.6 along the cube's x axis. The new geometry goes into a second buffer,
tabletop_translucent.bin.
"""
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
HALF = 0.03          # cube half-size, metres
CAVITY = 0.016       # cavity radius, metres
CENTRE = [-0.12, HALF, 0.17]


def box(lo, hi):
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for side in (0, 1):
            n = [0.0, 0.0, 0.0]
            n[axis] = 1.0 if side else -1.0
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos)
            for k in range(4):
                q = [0.0, 0.0, 0.0]
                q[axis] = hi[axis] if side else lo[axis]
                q[u] = hi[u] if k in (1, 2) else lo[u]
                q[v] = hi[v] if k >= 2 else lo[v]
                pos.append(q)
                nrm.append(n)
            tri = [base, base + 1, base + 2, base, base + 2, base + 3]
            a, b, c = pos[tri[0]], pos[tri[1]], pos[tri[2]]
            e1 = [b[i] - a[i] for i in range(3)]
            e2 = [c[i] - a[i] for i in range(3)]
            cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            if sum(cr[i] * n[i] for i in range(3)) < 0:
                tri = [base, base + 2, base + 1, base, base + 3, base + 2]
            idx += tri
    return pos, nrm, idx


def inward_sphere(r, slices=32, stacks=16):
    """A sphere whose normals and winding face its centre (the wall of a cavity)."""
    pos, nrm, idx = [], [], []
    for i in range(stacks + 1):
        th = math.pi * i / stacks
        for j in range(slices + 1):
            ph = 2 * math.pi * j / slices
            n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
            pos.append([r * c for c in n])
            nrm.append([-c for c in n])
    at = lambda i, j: i * (slices + 1) + j
    for i in range(stacks):
        for j in range(slices):
            # The outward sphere's triangles with their winding reversed.
            if i > 0:
                idx += [at(i, j), at(i, j + 1), at(i + 1, j)]
            if i < stacks - 1:
                idx += [at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]
    return pos, nrm, idx


def nrrd_float(n, values):
    header = ("NRRD0004\n# tabletop_translucent.gltf: jade density, x fastest\ntype: float\ndimension: 3\n"
              "sizes: %d %d %d\nencoding: raw\nendian: little\n\n" % (n, n, n))
    return header.encode() + struct.pack("<%df" % len(values), *values)


def main():
    with open(os.path.join(HERE, "tabletop.gltf")) as f:
        gltf = json.load(f)
    blob = bytearray()
    first_view = len(gltf["bufferViews"])

    def accessor(values, comps, type_name, target, ctype=5126, minmax=False):
        fmt = "<%d%s" % (len(values) * comps, "f" if ctype == 5126 else "I")
        flat = [c for v in values for c in (v if comps > 1 else [v])]
        data = struct.pack(fmt, *flat)
        while len(blob) % 4:
            blob.append(0)
        gltf["bufferViews"].append({"buffer": 1, "byteOffset": len(blob), "byteLength": len(data),
                                    "target": target})
        blob.extend(data)
        acc = {"bufferView": len(gltf["bufferViews"]) - 1, "componentType": ctype, "count": len(values),
               "type": type_name}
        if minmax:
            acc["min"] = [min(v[i] for v in values) for i in range(comps)]
            acc["max"] = [max(v[i] for v in values) for i in range(comps)]
        gltf["accessors"].append(acc)
        return len(gltf["accessors"]) - 1

    material = {"name": "jade (virtual, translucent)",
                "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.8, 0.6, 1.0], "metallicFactor": 0.0,
                                         "roughnessFactor": 0.2},
                "extensions": {
                    "KHR_materials_ior": {"ior": 1.5},
                    "KHR_materials_volume": {"thicknessFactor": 2 * HALF},
                    "MIRAGE_materials_scattering": {
                        "extinction": 120.0, "albedo": [0.75, 0.97, 0.85],
                        "density": {"uri": "jade_density.nrrd", "boundsMin": [-HALF] * 3,
                                    "boundsMax": [HALF] * 3}}}}
    gltf["materials"].append(material)
    mat = len(gltf["materials"]) - 1
    prims = []
    for pos, nrm, idx in (box([-HALF] * 3, [HALF] * 3), inward_sphere(CAVITY)):
        prims.append({"attributes": {"POSITION": accessor(pos, 3, "VEC3", 34962, minmax=True),
                                     "NORMAL": accessor(nrm, 3, "VEC3", 34962)},
                      "indices": accessor(idx, 1, "SCALAR", 34963, ctype=5125), "material": mat, "mode": 4})
    gltf["meshes"].append({"name": "jade_cube", "primitives": prims})
    gltf["nodes"].append({"name": "jade_cube", "mesh": len(gltf["meshes"]) - 1, "translation": CENTRE,
                          "rotation": [0.0, math.sin(math.radians(15)), 0.0, math.cos(math.radians(15))]})
    gltf["scenes"][0]["nodes"].append(len(gltf["nodes"]) - 1)
    for ext in ("KHR_materials_volume", "KHR_materials_ior", "MIRAGE_materials_scattering"):
        if ext not in gltf.setdefault("extensionsUsed", []):
            gltf["extensionsUsed"].append(ext)
    gltf["buffers"].append({"uri": "tabletop_translucent.bin", "byteLength": len(blob)})
    assert first_view == len(gltf["bufferViews"]) - 6
    n = 8
    values = [0.4 + 1.2 * (x + 0.5) / n for z in range(n) for y in range(n) for x in range(n)]
    with open(os.path.join(HERE, "jade_density.nrrd"), "wb") as f:
        f.write(nrrd_float(n, values))
    with open(os.path.join(HERE, "tabletop_translucent.bin"), "wb") as f:
        f.write(blob)
    with open(os.path.join(HERE, "tabletop_translucent.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
