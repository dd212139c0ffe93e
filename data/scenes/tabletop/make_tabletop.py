#!/usr/bin/env python3
"""Writes the bundled tabletop scene (data/scenes/tabletop/): tabletop.gltf + tabletop.bin + env.pfm.

Python standard library only. Run from anywhere:  python3 data/scenes/tabletop/make_tabletop.py
The board texture (board.png) and board file (board.json) beside it come from mirage itself:
    mirage board --dpi 200 -o data/scenes/tabletop/board.png --json data/scenes/tabletop/board.json

World frame = glTF: metres, +Y up. The tag board's page lies on the table top (y = 0) centred at
the origin, page +x along world +X, page +y (down the page) along world +Z (tracking/BoardLayout.h).
REAL nodes (extras.mirage.real = true): table, floor, board, book, mug, block, the spot light.
VIRTUAL nodes (default): a glass sphere, a mirror, a diffuse yellow box, for the compositing issues.
Colours are linear. Light units: KHR_lights_punctual (candela), read radiometrically by mirage.
"""
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quat_from_axes(x, y, z):
    """Quaternion [x, y, z, w] of the rotation whose matrix columns are x, y, z."""
    m00, m01, m02 = x[0], y[0], z[0]
    m10, m11, m12 = x[1], y[1], z[1]
    m20, m21, m22 = x[2], y[2], z[2]
    tr = m00 + m11 + m22
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, qx, qy, qz = 0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s
    elif m00 > m11 and m00 > m22:
        s = math.sqrt(1.0 + m00 - m11 - m22) * 2
        w, qx, qy, qz = (m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s
    elif m11 > m22:
        s = math.sqrt(1.0 + m11 - m00 - m22) * 2
        w, qx, qy, qz = (m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s
    else:
        s = math.sqrt(1.0 + m22 - m00 - m11) * 2
        w, qx, qy, qz = (m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s
    return [qx, qy, qz, w]


def look_at_rotation(eye, target, up=(0, 1, 0)):
    """Rotation of a glTF camera/light node at eye looking at target (it looks down its -Z)."""
    f = normalize([t - e for t, e in zip(target, eye)])
    z = [-c for c in f]
    x = normalize(cross(list(up), z))
    y = cross(z, x)
    return quat_from_axes(x, y, z)


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.gltf = {
            "asset": {"version": "2.0", "generator": "mirage data/scenes/tabletop/make_tabletop.py"},
            "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior",
                               "KHR_materials_volume"],
            "buffers": [], "bufferViews": [], "accessors": [], "meshes": [], "materials": [],
            "nodes": [], "cameras": [], "images": [], "textures": [], "samplers": [],
            "extensions": {"KHR_lights_punctual": {"lights": []}},
            "scenes": [{"name": "tabletop", "nodes": []}], "scene": 0,
        }

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        off = len(self.bin)
        self.bin += data
        self.gltf["bufferViews"].append({"buffer": 0, "byteOffset": off, "byteLength": len(data), "target": target})
        return len(self.gltf["bufferViews"]) - 1

    def _accessor(self, values, comps, type_name, target, minmax=False):
        flat = [c for v in values for c in v] if comps > 1 else list(values)
        if type_name == "SCALAR":
            data = struct.pack("<%dI" % len(flat), *flat)
            ctype = 5125
        else:
            data = struct.pack("<%df" % len(flat), *flat)
            ctype = 5126
        acc = {"bufferView": self._view(data, target), "componentType": ctype, "count": len(values), "type": type_name}
        if minmax:
            acc["min"] = [min(v[i] for v in values) for i in range(comps)]
            acc["max"] = [max(v[i] for v in values) for i in range(comps)]
        self.gltf["accessors"].append(acc)
        return len(self.gltf["accessors"]) - 1

    def mesh(self, name, positions, normals, uvs, indices, material):
        prim = {"attributes": {"POSITION": self._accessor(positions, 3, "VEC3", 34962, True),
                               "NORMAL": self._accessor(normals, 3, "VEC3", 34962),
                               "TEXCOORD_0": self._accessor(uvs, 2, "VEC2", 34962)},
                "indices": self._accessor(indices, 1, "SCALAR", 34963), "material": material, "mode": 4}
        self.gltf["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.gltf["meshes"]) - 1

    def material(self, name, color, metallic=0.0, roughness=0.8, texture=None, transmission=None, ior=None,
                 attenuation=None):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": metallic,
                                                      "roughnessFactor": roughness}}
        if texture is not None:
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
        ext = {}
        if transmission is not None:
            ext["KHR_materials_transmission"] = {"transmissionFactor": transmission}
        if ior is not None:
            ext["KHR_materials_ior"] = {"ior": ior}
        if attenuation is not None:
            ext["KHR_materials_volume"] = {"thicknessFactor": 0.1, "attenuationColor": attenuation[0],
                                           "attenuationDistance": attenuation[1]}
        if ext:
            m["extensions"] = ext
        self.gltf["materials"].append(m)
        return len(self.gltf["materials"]) - 1

    def texture(self, uri):
        self.gltf["images"].append({"uri": uri})
        self.gltf["samplers"].append({"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071})
        self.gltf["textures"].append({"source": len(self.gltf["images"]) - 1,
                                      "sampler": len(self.gltf["samplers"]) - 1})
        return len(self.gltf["textures"]) - 1

    def node(self, name, real, mesh=None, translation=None, rotation=None, camera=None, light=None):
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if camera is not None:
            n["camera"] = camera
        if light is not None:
            n["extensions"] = {"KHR_lights_punctual": {"light": light}}
        if translation is not None:
            n["translation"] = list(translation)
        if rotation is not None:
            n["rotation"] = list(rotation)
        if real:
            n["extras"] = {"mirage": {"real": True}}
        self.gltf["nodes"].append(n)
        self.gltf["scenes"][0]["nodes"].append(len(self.gltf["nodes"]) - 1)

    def camera(self, name, yfov_deg, aspect=4.0 / 3.0):
        self.gltf["cameras"].append({"name": name, "type": "perspective", "perspective": {
            "yfov": math.radians(yfov_deg), "aspectRatio": aspect, "znear": 0.01, "zfar": 50.0}})
        return len(self.gltf["cameras"]) - 1

    def spot(self, name, intensity, color, inner, outer):
        lights = self.gltf["extensions"]["KHR_lights_punctual"]["lights"]
        lights.append({"name": name, "type": "spot", "color": list(color), "intensity": intensity,
                       "spot": {"innerConeAngle": inner, "outerConeAngle": outer}})
        return len(lights) - 1

    def write(self, gltf_path, bin_name):
        self.gltf["buffers"] = [{"uri": bin_name, "byteLength": len(self.bin)}]
        with open(os.path.join(os.path.dirname(gltf_path), bin_name), "wb") as f:
            f.write(self.bin)
        with open(gltf_path, "w") as f:
            json.dump(self.gltf, f, indent=1)
            f.write("\n")


def box(lo, hi):
    pos, nrm, uv, idx = [], [], [], []
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
                uv.append([1.0 if k in (1, 2) else 0.0, 1.0 if k >= 2 else 0.0])
            tri = [base, base + 1, base + 2, base, base + 2, base + 3]
            # counter-clockwise seen from outside (glTF front face)
            a, b, c = pos[tri[0]], pos[tri[1]], pos[tri[2]]
            cr = cross([b[i] - a[i] for i in range(3)], [c[i] - a[i] for i in range(3)])
            if sum(cr[i] * n[i] for i in range(3)) < 0:
                tri = [base, base + 2, base + 1, base, base + 3, base + 2]
            idx += tri
    return pos, nrm, uv, idx


def uv_sphere(r, slices=64, stacks=32):
    pos, nrm, uv, idx = [], [], [], []
    for i in range(stacks + 1):
        th = math.pi * i / stacks
        for j in range(slices + 1):
            ph = 2 * math.pi * j / slices
            n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
            pos.append([r * c for c in n])
            nrm.append(n)
            uv.append([j / slices, i / stacks])
    at = lambda i, j: i * (slices + 1) + j
    for i in range(stacks):
        for j in range(slices):
            if i > 0:
                idx += [at(i, j), at(i + 1, j), at(i, j + 1)]
            if i < stacks - 1:
                idx += [at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)]
    return pos, nrm, uv, idx


def cylinder(r, h, segs=48):
    """Closed cylinder standing on y = 0, axis +Y."""
    pos, nrm, uv, idx = [], [], [], []
    for j in range(segs + 1):
        ph = 2 * math.pi * j / segs
        c, s = math.cos(ph), -math.sin(ph)
        for y in (0.0, h):
            pos.append([r * c, y, r * s])
            nrm.append([c, 0.0, s])
            uv.append([j / segs, 1.0 - y / h])
    for j in range(segs):
        a, b, c2, d = 2 * j, 2 * j + 1, 2 * j + 2, 2 * j + 3
        idx += [a, c2, b, b, c2, d]
    for y, ny in ((0.0, -1.0), (h, 1.0)):
        centre = len(pos)
        pos.append([0.0, y, 0.0])
        nrm.append([0.0, ny, 0.0])
        uv.append([0.5, 0.5])
        for j in range(segs + 1):
            ph = 2 * math.pi * j / segs
            pos.append([r * math.cos(ph), y, -r * math.sin(ph)])
            nrm.append([0.0, ny, 0.0])
            uv.append([0.5 + 0.5 * math.cos(ph), 0.5 + 0.5 * math.sin(ph)])
        for j in range(segs):
            if ny > 0:
                idx += [centre, centre + 1 + j, centre + 2 + j]
            else:
                idx += [centre, centre + 2 + j, centre + 1 + j]
    return pos, nrm, uv, idx


def write_env_pfm(path, w=128, h=64):
    """A small room-like environment (linear RGB radiance): a warm bright window, dim walls, a
    darker floor. Equirectangular as mirage maps it (docs/reference-renderer.md): column u, row v
    looks along (sin(th) sin(ph), cos(th), -sin(th) cos(ph)) with th = v pi, ph = (u - 0.5) 2 pi."""
    rows = []
    for y in range(h):
        th = math.pi * (y + 0.5) / h
        row = []
        for x in range(w):
            ph = 2 * math.pi * ((x + 0.5) / w - 0.5)
            d = (math.sin(th) * math.sin(ph), math.cos(th), -math.sin(th) * math.cos(ph))
            if d[1] > 0:  # walls and ceiling: soft bluish-white, brighter upwards
                base = 0.10 + 0.12 * d[1]
                col = [base * 0.95, base * 1.0, base * 1.08]
            else:  # floor: dark warm
                col = [0.05, 0.045, 0.04]
            # window: towards -Z and a little left, 20-45 degrees up
            if -0.55 < math.atan2(d[0], -d[2]) < -0.05 and 0.3 < d[1] < 0.7:
                col = [1.6, 1.55, 1.45]
            row.append(col)
        rows.append(row)
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for row in reversed(rows):  # PFM stores the bottom row first
            for c in row:
                f.write(struct.pack("<3f", *c))


def main():
    with open(os.path.join(HERE, "board.json")) as f:
        board = json.load(f)
    sheet_w, sheet_h = board["sheet"]["width"], board["sheet"]["height"]

    b = Builder()
    board_tex = b.texture("board.png")
    m_table = b.material("table wood", [0.35, 0.22, 0.12], roughness=0.6)
    m_floor = b.material("floor", [0.25, 0.25, 0.27], roughness=0.9)
    m_board = b.material("board paper", [0.85, 0.85, 0.85], roughness=0.9, texture=board_tex)
    m_book = b.material("book", [0.08, 0.15, 0.45], roughness=0.7)
    m_mug = b.material("mug ceramic", [0.6, 0.12, 0.08], roughness=0.3)
    m_block = b.material("block", [0.55, 0.45, 0.25], roughness=0.8)
    m_glass = b.material("glass (virtual)", [1.0, 1.0, 1.0], roughness=0.0, transmission=1.0, ior=1.5,
                         attenuation=([0.85, 0.93, 1.0], 0.1))
    m_mirror = b.material("mirror (virtual)", [0.95, 0.95, 0.95], metallic=1.0, roughness=0.0)
    m_vbox = b.material("yellow box (virtual)", [0.8, 0.6, 0.05], roughness=0.6)

    # Table top just under the board (y = 0 is the page), floor 0.75 m below.
    b.node("table", True, b.mesh("table", *box([-0.6, -0.04, -0.4], [0.6, -0.0005, 0.4]), m_table))
    b.node("floor", True, b.mesh("floor", *box([-3, -0.77, -3], [3, -0.75, 3]), m_floor))
    # The board page: a quad on y = 0, texture (u, v) = page (x / W, y / H) (tracking/BoardImage.h).
    hw, hh = sheet_w / 2, sheet_h / 2
    quad = ([[-hw, 0, -hh], [hw, 0, -hh], [hw, 0, hh], [-hw, 0, hh]], [[0, 1, 0]] * 4,
            [[0, 0], [1, 0], [1, 1], [0, 1]], [0, 2, 1, 0, 3, 2])
    b.node("board", True, b.mesh("board", *quad, m_board))
    b.node("book", True, b.mesh("book", *box([0.2, 0, -0.33], [0.42, 0.04, -0.17]), m_book))
    b.node("mug", True, b.mesh("mug", *cylinder(0.04, 0.1), m_mug), translation=[-0.3, 0, -0.22])
    b.node("block", True, b.mesh("block", *box([-0.03, 0, -0.03], [0.03, 0.06, 0.03]), m_block),
           translation=[0.33, 0, 0.2])
    spot_pos = [0.35, 0.95, 0.45]
    b.node("spot", True, light=b.spot("spot", 1.6, [1.0, 0.95, 0.85], 0.35, 0.55), translation=spot_pos,
           rotation=look_at_rotation(spot_pos, [0, 0, 0]))
    # Virtual objects: glass sphere, mirror, diffuse box.
    b.node("glass_sphere", False, b.mesh("glass_sphere", *uv_sphere(0.045), m_glass), translation=[0.02, 0.045, 0.16])
    mirror_rot = look_at_rotation([0, 0, 0], [-1, 0, -1])  # faces +X+Z (towards the camera side)
    b.node("mirror", False, b.mesh("mirror", *box([-0.1, 0, -0.003], [0.1, 0.14, 0.003]), m_mirror),
           translation=[-0.33, 0, 0.05], rotation=mirror_rot)
    b.node("yellow_box", False, b.mesh("yellow_box", *box([-0.03, 0, -0.03], [0.03, 0.06, 0.03]), m_vbox),
           translation=[0.22, 0, 0.02])
    # Cameras: a view of the table, and a top view.
    eye = [0.0, 0.42, 0.55]
    b.node("main", True, camera=b.camera("main", 45.0), translation=eye, rotation=look_at_rotation(eye, [0, 0, 0]))
    top = [0.0, 0.9, 0.001]
    b.node("top", True, camera=b.camera("top", 40.0), translation=top,
           rotation=look_at_rotation(top, [0, 0, 0], up=(0, 0, -1)))
    b.gltf["scenes"][0]["extras"] = {"mirage": {"environment": {"type": "equirectangular", "image": "env.pfm",
                                                                "intensity": 1.0, "rotation_y_deg": 0}}}
    write_env_pfm(os.path.join(HERE, "env.pfm"))
    b.write(os.path.join(HERE, "tabletop.gltf"), "tabletop.bin")


if __name__ == "__main__":
    main()
