#!/usr/bin/env python3
"""Writes the glTF test scenes under tests/data/scenes/ (pure Python 3, no dependencies).

    python3 tests/data/scenes/make_scenes.py

The generated files are checked in; tests read them and never run this script. Re-run it after
changing it and commit the result. Values here are what tests/core/SceneLoader_test.cpp checks.

good/showcase.gltf  every supported feature, buffer and one image as base64 data URIs, one image
                    as an external PNG (mr.png), environment in scenes[0].extras
good/showcase.glb   the same scene as a binary glTF: buffer in the BIN chunk, image 0 in a
                    bufferView, image 1 still external
good/fisheye.gltf   one triangle; a fish-eye environment in asset.extras
good/translucent.gltf  one triangle, three translucent materials: MIRAGE_materials_scattering
                    with an NRRD density grid (density.nrrd), with a raw grid (density.raw), and
                    KHR_materials_diffuse_transmission + KHR_materials_volume (homogeneous)
bad/*.gltf|.glb     one defect each (see BAD below); the loader must throw mirage::FileError
"""
import base64
import copy
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
GOOD = os.path.join(HERE, "good")
BAD = os.path.join(HERE, "bad")

FLOAT, UBYTE, USHORT, UINT, SHORT = 5126, 5121, 5123, 5125, 5122


def png_rgba(width, height, pixels):
    """Minimal PNG writer: 8-bit RGBA, no filtering. pixels: list of (r, g, b, a) rows-first."""
    raw = b""
    for y in range(height):
        raw += b"\x00" + bytes(c for p in pixels[y * width:(y + 1) * width] for c in p)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def hdr_rgbe(width, height, rgb):
    """Radiance .hdr, flat (uncompressed) scanlines; width < 8 so no reader expects RLE."""
    out = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)
    for r, g, b in rgb:
        m = max(r, g, b)
        if m < 1e-32:
            out += b"\x00\x00\x00\x00"
        else:
            mant, exp = math.frexp(m)
            s = mant * 256.0 / m
            out += bytes([int(r * s), int(g * s), int(b * s), exp + 128])
    return out


def data_uri(data, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


class BufferBuilder:
    """Packs arrays into one buffer, 4-byte aligned, and records views and accessors."""

    def __init__(self):
        self.data = b""
        self.views = []
        self.accessors = []

    def view(self, blob, stride=None):
        while len(self.data) % 4:
            self.data += b"\x00"
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob)}
        if stride:
            v["byteStride"] = stride
        self.data += blob
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, fmt, comps, ctype, atype, values, normalized=False, minmax=False):
        blob = b"".join(struct.pack("<" + fmt * comps, *v) if comps > 1 else struct.pack("<" + fmt, v)
                        for v in values)
        a = {"bufferView": self.view(blob), "componentType": ctype, "count": len(values), "type": atype}
        if normalized:
            a["normalized"] = True
        if minmax:
            a["min"] = [min(v[i] for v in values) for i in range(comps)]
            a["max"] = [max(v[i] for v in values) for i in range(comps)]
        self.accessors.append(a)
        return len(self.accessors) - 1


# Texture 0: 2x2 RGBA, sRGB colour. Texture 1 (external mr.png): 2x1 linear metallic-roughness.
BASECOLOR_PNG = png_rgba(2, 2, [(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (10, 20, 30, 40)])
MR_PNG = png_rgba(2, 1, [(0, 128, 255, 255), (0, 64, 32, 255)])


def showcase(binary):
    b = BufferBuilder()
    # mesh 0 "Floor": unit quad in XZ, normals +Y, uv0, tangents, UNSIGNED_SHORT indices.
    quad = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
    floor = {
        "POSITION": b.accessor("f", 3, FLOAT, "VEC3", quad, minmax=True),
        "NORMAL": b.accessor("f", 3, FLOAT, "VEC3", [(0, 1, 0)] * 4),
        "TANGENT": b.accessor("f", 4, FLOAT, "VEC4", [(1, 0, 0, 1)] * 4),
        "TEXCOORD_0": b.accessor("f", 2, FLOAT, "VEC2", [(0, 0), (1, 0), (1, 1), (0, 1)]),
    }
    floor_idx = b.accessor("H", 1, USHORT, "SCALAR", [0, 2, 1, 0, 3, 2])
    # mesh 1 "GlassTri": no normals (flat ones generated), no indices, sparse POSITION override
    # of vertex 2: (0, 0, 0) -> (0, 1, 0).
    tri = [(0, 0, 0), (1, 0, 0), (0, 0, 0)]
    tri_pos = b.accessor("f", 3, FLOAT, "VEC3", tri)
    sparse_idx = b.view(struct.pack("<B", 2))
    sparse_val = b.view(struct.pack("<3f", 0, 1, 0))
    b.accessors[tri_pos]["sparse"] = {"count": 1, "indices": {"bufferView": sparse_idx, "componentType": UBYTE},
                                      "values": {"bufferView": sparse_val}}
    # mesh 2 "MirrorStrip": triangle strip of 4 vertices, UNSIGNED_BYTE indices, normalized
    # UNSIGNED_BYTE TEXCOORD_1; plus a LINES primitive that must be skipped with a warning.
    strip = [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)]
    strip_pos = b.accessor("f", 3, FLOAT, "VEC3", strip)
    strip_nrm = b.accessor("f", 3, FLOAT, "VEC3", [(0, 0, 1)] * 4)
    strip_uv1 = b.accessor("B", 2, UBYTE, "VEC2", [(0, 0), (0, 255), (255, 0), (255, 255)], normalized=True)
    strip_idx = b.accessor("B", 1, UBYTE, "SCALAR", [0, 1, 2, 3])
    line_idx = b.accessor("I", 1, UINT, "SCALAR", [0, 1])

    image0 = {"mimeType": "image/png", "name": "checker"}
    if binary:
        image0["bufferView"] = b.view(BASECOLOR_PNG)
    else:
        image0["uri"] = data_uri(BASECOLOR_PNG, "image/png")

    gltf = {
        "asset": {"version": "2.0", "generator": "mirage tests/data/scenes/make_scenes.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
                           "KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensionsRequired": ["KHR_materials_transmission", "KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"name": "Showcase", "nodes": [0, 4, 6, 7, 8],
                    "extras": {"mirage": {"environment": {"type": "equirectangular", "image": "env.hdr",
                                                          "intensity": 2.0, "rotation_y_deg": 90}}}}],
        "nodes": [
            {"name": "Room", "children": [1, 2, 3], "extras": {"mirage": {"real": True}}},
            {"name": "Floor", "mesh": 0, "scale": [2, 1, 2]},
            # rotation: -90 degrees about +X, so the spot's -Z axis points down (-Y).
            {"name": "Lamp", "translation": [0, 2, 0],
             "rotation": [-math.sin(math.pi / 4), 0, 0, math.cos(math.pi / 4)],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "VirtualMirror", "mesh": 2, "translation": [0, 0, -1], "extras": {"mirage": {"real": False}}},
            # column-major: uniform scale 0.5, translation (0.5, 1, 0.25)
            {"name": "GlassObject", "mesh": 1, "children": [5],
             "matrix": [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 1, 0.25, 1]},
            {"name": "GlassLight", "translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "MainCamera", "camera": 0, "translation": [0, 1.6, 3]},
            # rotation: +90 degrees about +Y, so the sun shines along world -X.
            {"name": "Sun", "rotation": [0, math.sin(math.pi / 4), 0, math.cos(math.pi / 4)],
             "extensions": {"KHR_lights_punctual": {"light": 2}}, "extras": {"mirage": {"real": True}}},
            {"name": "TopCamera", "camera": 1, "translation": [0, 5, 0]},
            {"name": "NotInScene", "mesh": 0},
        ],
        "meshes": [
            {"name": "Floor", "primitives": [{"attributes": floor, "indices": floor_idx, "material": 0}]},
            {"name": "GlassTri", "primitives": [{"attributes": {"POSITION": tri_pos}, "material": 1}]},
            {"name": "MirrorStrip", "primitives": [
                {"attributes": {"POSITION": strip_pos, "NORMAL": strip_nrm, "TEXCOORD_1": strip_uv1},
                 "indices": strip_idx, "mode": 5, "material": 2},
                {"attributes": {"POSITION": strip_pos}, "indices": line_idx, "mode": 1}]},
        ],
        "materials": [
            {"name": "FloorMat", "doubleSided": True, "alphaMode": "MASK", "alphaCutoff": 0.25,
             "emissiveFactor": [0.1, 0.2, 0.3],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}},
             "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "baseColorTexture": {"index": 0},
                                      "metallicFactor": 0.0, "roughnessFactor": 0.9,
                                      "metallicRoughnessTexture": {"index": 1}}},
            {"name": "Glass", "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.02},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                            "KHR_materials_ior": {"ior": 1.45},
                            "KHR_materials_volume": {"thicknessFactor": 0.05, "attenuationDistance": 0.3,
                                                     "attenuationColor": [0.9, 0.8, 0.7]}}},
            {"name": "Mirror", "pbrMetallicRoughness": {"metallicFactor": 1.0, "roughnessFactor": 0.01}},
        ],
        "textures": [{"source": 0}, {"source": 1, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33648}],
        "images": [image0, {"uri": "mr.png", "name": "metalRough"}],
        "cameras": [
            {"name": "MainCam", "type": "perspective",
             "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.05, "zfar": 50}},
            {"name": "TopCam", "type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}},
        ],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "KeySpot", "type": "spot", "color": [1.0, 0.9, 0.8], "intensity": 50, "range": 10,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
            {"name": "Fill", "type": "point", "intensity": 5},
            {"name": "SunLight", "type": "directional", "intensity": 3, "color": [1, 1, 0.9]},
        ]}},
        "accessors": b.accessors,
        "bufferViews": b.views,
    }
    if binary:
        gltf["buffers"] = [{"byteLength": len(b.data)}]
    else:
        gltf["buffers"] = [{"byteLength": len(b.data), "uri": data_uri(b.data)}]
    return gltf, b.data


def glb(gltf, bin_data):
    js = json.dumps(gltf, separators=(",", ":")).encode()
    while len(js) % 4:
        js += b" "
    while len(bin_data) % 4:
        bin_data += b"\x00"
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_data), 0x004E4942) + bin_data
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def triangle(extra_nodes=None):
    """The minimal valid scene the bad files are derived from: one triangle, indexed."""
    b = BufferBuilder()
    pos = b.accessor("f", 3, FLOAT, "VEC3", [(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    idx = b.accessor("H", 1, USHORT, "SCALAR", [0, 1, 2])
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "Tri", "mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.data), "uri": data_uri(b.data)}],
    }


def nrrd_float(nx, ny, nz, values, extra_header=""):
    """An NRRD file of little-endian float32 samples, x fastest."""
    header = ("NRRD0004\n# mirage test density grid\ntype: float\ndimension: 3\n"
              "sizes: %d %d %d\nencoding: raw\nendian: little\n%s\n" % (nx, ny, nz, extra_header))
    return header.encode() + struct.pack("<%df" % len(values), *values)


# Test density: 4 x 3 x 2 samples, value = 0.1 * (x + 4 y + 12 z).
DENSITY_NRRD = nrrd_float(4, 3, 2, [0.1 * i for i in range(24)])
# 2 x 2 x 2 uint8 samples (normalised by 255).
DENSITY_RAW = bytes([0, 51, 102, 153, 204, 255, 0, 255])


def translucent_scene():
    g = triangle()
    g["extensionsUsed"] = ["MIRAGE_materials_scattering", "KHR_materials_volume",
                           "KHR_materials_diffuse_transmission", "KHR_materials_ior"]
    g["materials"] = [
        {"name": "jade", "extensions": {
            "KHR_materials_ior": {"ior": 1.6},
            "KHR_materials_volume": {"thicknessFactor": 0.1},
            "MIRAGE_materials_scattering": {
                "extinction": 40.0, "albedo": [0.6, 0.9, 0.7],
                "density": {"uri": "density.nrrd", "boundsMin": [-0.5, -0.25, 0.0],
                            "boundsMax": [0.5, 0.5, 0.2]}}}},
        {"name": "milk", "extensions": {
            "MIRAGE_materials_scattering": {
                "extinction": 12.5,
                "density": {"uri": "density.raw", "dimensions": [2, 2, 2], "type": "uint8",
                            "boundsMin": [0, 0, 0], "boundsMax": [1, 1, 1]}}}},
        {"name": "wax", "extensions": {
            "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0},
            "KHR_materials_volume": {"thicknessFactor": 0.05, "attenuationDistance": 0.25,
                                     "attenuationColor": [0.9, 0.8, 0.5]}}},
    ]
    g["meshes"][0]["primitives"][0]["material"] = 0
    return g


def with_buffer(g, data):
    g["buffers"] = [{"byteLength": len(data), "uri": data_uri(data)}]
    return g


def bad_cases():
    """name -> glTF dict (or bytes). Expected messages live in SceneLoader_test.cpp."""
    cases = {}

    def case(name, edit):
        g = triangle()
        r = edit(g)
        cases[name] = g if r is None else r

    case("missing_buffer", lambda g: g["buffers"][0].update(uri="missing.bin"))
    case("buffer_length_mismatch", lambda g: g["buffers"][0].update(byteLength=g["buffers"][0]["byteLength"] + 4))
    case("accessor_index_out_of_range", lambda g: g["meshes"][0]["primitives"][0]["attributes"].update(POSITION=7))
    case("indices_accessor_out_of_range", lambda g: g["meshes"][0]["primitives"][0].update(indices=9))
    case("bufferview_index_out_of_range", lambda g: g["accessors"][0].update(bufferView=5))
    case("buffer_index_out_of_range", lambda g: g["bufferViews"][0].update(buffer=3))
    case("scene_node_out_of_range", lambda g: g["scenes"][0].update(nodes=[4]))
    case("child_node_out_of_range", lambda g: g["nodes"][0].update(children=[-2]))
    case("mesh_index_out_of_range", lambda g: g["nodes"][0].update(mesh=4))
    case("material_index_out_of_range", lambda g: g["meshes"][0]["primitives"][0].update(material=3))

    def texture_oob(g):
        g["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}}]
        g["meshes"][0]["primitives"][0]["material"] = 0
    case("texture_index_out_of_range", texture_oob)
    case("accessor_exceeds_bufferview", lambda g: g["accessors"][0].update(count=4))
    case("accessor_offset_exceeds_bufferview", lambda g: g["accessors"][0].update(byteOffset=8))
    case("bufferview_exceeds_buffer", lambda g: g["bufferViews"][1].update(byteLength=64))
    case("wrong_accessor_type", lambda g: g["accessors"][0].update(type="VEC2"))
    case("wrong_component_type", lambda g: g["accessors"][0].update(componentType=USHORT))
    case("float_indices", lambda g: g["accessors"][1].update(componentType=FLOAT, count=1))
    case("index_beyond_vertices", lambda g: with_buffer(g, struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) +
                                                          struct.pack("<3H", 0, 1, 5) + b"\0\0"))
    case("nan_in_positions", lambda g: with_buffer(g, struct.pack("<9f", 0, 0, 0, float("nan"), 0, 0, 0, 1, 0) +
                                                      struct.pack("<3H", 0, 1, 2) + b"\0\0"))
    # JSON has no NaN/Inf: a literal too large for a double is a parse error ...
    case("translation_number_overflow", lambda g: g["nodes"][0].update(translation=[0, "INF", 0]))

    # ... and finite matrices can still multiply to infinity along the hierarchy.
    def matrix_overflow(g):
        big = [1e300, 0, 0, 0, 0, 1e300, 0, 0, 0, 0, 1e300, 0, 0, 0, 0, 1]
        g["nodes"] = [{"matrix": big, "children": [1]}, {"matrix": big, "mesh": 0}]
    case("matrix_world_overflow", matrix_overflow)

    def overflow(g):
        g["nodes"] = [{"scale": [1e200, 1e200, 1e200], "children": [1]},
                      {"scale": [1e200, 1e200, 1e200], "mesh": 0}]
    case("world_transform_overflow", overflow)
    case("zero_quaternion", lambda g: g["nodes"][0].update(rotation=[0, 0, 0, 0]))

    def cycle(g):
        g["nodes"] = [{"name": "Root", "mesh": 0}, {"name": "A", "children": [2]}, {"name": "B", "children": [1]}]
    case("node_cycle", cycle)
    case("node_self_child", lambda g: g["nodes"][0].update(children=[0]))

    def two_parents(g):
        g["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
        g["scenes"][0]["nodes"] = [0, 1]
    case("node_two_parents", two_parents)
    case("unknown_required_extension", lambda g: g.update(extensionsUsed=["KHR_draco_mesh_compression"],
                                                          extensionsRequired=["KHR_draco_mesh_compression"]))

    def missing_image(g):
        g["images"] = [{"uri": "no_such_image.png"}]
        g["textures"] = [{"source": 0}]
    case("missing_image", missing_image)

    def not_png(g):
        g["images"] = [{"uri": data_uri(b"this is not an image at all", "image/png")}]
        g["textures"] = [{"source": 0}]
    case("image_not_png", not_png)
    def huge_png(g):
        # A valid PNG signature and IHDR claiming 100000 x 100000 pixels (no pixel data needed:
        # the loader must refuse from the header, before any decoder allocates 40 GB).
        ihdr = struct.pack(">IIBBBBB", 100000, 100000, 8, 6, 0, 0, 0)
        png = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + ihdr + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
        g["images"] = [{"uri": data_uri(png, "image/png")}]
        g["textures"] = [{"source": 0}]
    case("image_too_large", huge_png)
    case("duplicate_child", lambda g: g.update(nodes=[{"children": [1, 1]}, {"mesh": 0}]))
    case("light_index_out_of_range", lambda g: g["nodes"][0].update(
        extensions={"KHR_lights_punctual": {"light": 2}}))
    case("camera_index_out_of_range", lambda g: g["nodes"][0].update(camera=1))

    def bad_spot(g):
        g["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "spot": {"innerConeAngle": 0.8, "outerConeAngle": 0.5}}]}}
        g["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    case("spot_cone_inverted", bad_spot)
    def light_overflow(g):
        # Finite in JSON (a double) but beyond float range: converting it would be undefined.
        g["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1e300}]}}
        g["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    case("light_intensity_beyond_float", light_overflow)
    case("real_not_bool", lambda g: g["nodes"][0].update(extras={"mirage": {"real": "yes"}}))

    def env_missing(g):
        g["scenes"][0]["extras"] = {"mirage": {"environment": {"type": "equirectangular", "image": "nowhere.hdr"}}}
    case("environment_image_missing", env_missing)

    def count_mismatch(g):
        g["accessors"].append({"bufferView": 0, "componentType": FLOAT, "count": 2, "type": "VEC3"})
        g["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2
    case("attribute_count_mismatch", count_mismatch)
    case("invalid_mode", lambda g: g["meshes"][0]["primitives"][0].update(mode=9))
    case("no_position", lambda g: g["meshes"][0]["primitives"][0].update(attributes={}))

    def sparse_oob(g):
        data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2) + b"\0\0"
        data += struct.pack("<I", 7) + struct.pack("<3f", 1, 1, 1)
        with_buffer(g, data)
        g["bufferViews"] += [{"buffer": 0, "byteOffset": 44, "byteLength": 4},
                             {"buffer": 0, "byteOffset": 48, "byteLength": 12}]
        g["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": 2, "componentType": UINT},
                                       "values": {"bufferView": 3}}
    case("sparse_index_out_of_range", sparse_oob)

    def scattering(density=None, **fields):
        ext = dict(fields)
        if density is not None:
            ext["density"] = density
        def edit(g):
            g["materials"] = [{"extensions": {"MIRAGE_materials_scattering": ext}}]
        return edit
    box = {"boundsMin": [0, 0, 0], "boundsMax": [1, 1, 1]}
    case("scattering_no_extinction", scattering(albedo=[1, 1, 1]))
    case("scattering_albedo_out_of_range", scattering(extinction=5, albedo=[0.5, 1.5, 0.5]))
    case("scattering_density_missing", scattering(dict(box, uri="nowhere.nrrd"), extinction=5))
    case("scattering_bounds_inverted", scattering(
        {"uri": "grid_good.nrrd", "boundsMin": [0, 2, 0], "boundsMax": [1, 1, 1]}, extinction=5))
    case("scattering_nrrd_short", scattering(dict(box, uri="grid_short.nrrd"), extinction=5))
    case("scattering_nrrd_compressed", scattering(dict(box, uri="grid_gzip.nrrd"), extinction=5))
    case("scattering_negative_density", scattering(dict(box, uri="grid_negative.nrrd"), extinction=5))
    case("scattering_raw_no_dimensions", scattering(dict(box, uri="grid.raw"), extinction=5))
    case("scattering_thin_walled", lambda g: g.update(materials=[{"extensions": {
        "KHR_materials_volume": {"thicknessFactor": 0, "attenuationDistance": 0.1},
        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1}}}]))

    def deep(g):
        g["asset"]["extras"] = json.loads("[" * 500 + "]" * 500)
    case("deep_nesting", deep)
    cases["not_json"] = b"{ this is not JSON"
    cases["empty"] = b""
    g, data = showcase(True)
    cases["truncated_glb"] = glb(g, data)[:200]
    return cases


def write(path, content):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(path, mode) as f:
        f.write(content)


def main():
    g, _ = showcase(False)
    write(os.path.join(GOOD, "showcase.gltf"), json.dumps(g, indent=1) + "\n")
    g, data = showcase(True)
    write(os.path.join(GOOD, "showcase.glb"), glb(g, data))
    write(os.path.join(GOOD, "mr.png"), MR_PNG)
    # 4x2 linear HDR sky: top row bright blue-white, bottom row dim brown.
    write(os.path.join(GOOD, "env.hdr"), hdr_rgbe(4, 2, [(0.6, 0.7, 1.0)] * 4 + [(0.2, 0.15, 0.1)] * 4))
    write(os.path.join(GOOD, "fisheye.yaml"), """%YAML:1.0
---
# Placeholder fish-eye calibration (OpenCV FileStorage, Kannala-Brandt) for scene loader tests.
image_width: 640
image_height: 480
camera_model: fisheye
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 200., 0., 320., 0., 200., 240., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 4
   dt: d
   data: [ 0.01, -0.002, 0., 0. ]
""")
    fish = triangle()
    fish["asset"]["extras"] = {"mirage": {"environment": {
        "type": "fisheye", "image": "env.hdr", "calibration": "fisheye.yaml", "intensity": 0.5,
        "T_world_camera": [0.1, 2.0, -0.3, 0.0, 1.0, 0.0, 0.0]}}}
    write(os.path.join(GOOD, "fisheye.gltf"), json.dumps(fish, indent=1) + "\n")

    write(os.path.join(GOOD, "translucent.gltf"), json.dumps(translucent_scene(), indent=1) + "\n")
    write(os.path.join(GOOD, "density.nrrd"), DENSITY_NRRD)
    write(os.path.join(GOOD, "density.raw"), DENSITY_RAW)
    # Grid files the bad scenes refer to.
    write(os.path.join(BAD, "grid_good.nrrd"), nrrd_float(2, 2, 2, [1.0] * 8))
    write(os.path.join(BAD, "grid_short.nrrd"), nrrd_float(2, 2, 2, [1.0] * 7))
    write(os.path.join(BAD, "grid_negative.nrrd"), nrrd_float(2, 2, 2, [1.0] * 5 + [-0.5] + [1.0] * 2))
    write(os.path.join(BAD, "grid_gzip.nrrd"),
          nrrd_float(2, 2, 2, [1.0] * 8).replace(b"encoding: raw", b"encoding: gzip"))
    write(os.path.join(BAD, "grid.raw"), struct.pack("<8f", *([1.0] * 8)))

    for name, content in bad_cases().items():
        ext = ".glb" if name.endswith("_glb") else ".gltf"
        if isinstance(content, dict):
            # json.dumps writes Infinity for float('inf'); glTF JSON cannot hold it, so "INF"
            # placeholders become 1e999, which parses to infinity.
            text = json.dumps(content, indent=None if name == "deep_nesting" else 1).replace('"INF"', "1e999")
            write(os.path.join(BAD, name + ext), text + "\n")
        else:
            write(os.path.join(BAD, name + ext), content)


if __name__ == "__main__":
    main()
