#!/usr/bin/env python3
"""Writes tabletop_rough.gltf and tabletop_rough35.gltf: the bundled tabletop with rough objects.

Python standard library only; run after make_tabletop.py:
    python3 data/scenes/tabletop/make_tabletop_rough.py
Same buffers, lights, cameras and environment as tabletop.gltf. The glass sphere becomes frosted
glass (roughness 0.3) and the mirror a brushed-metal panel (roughness 0.25), turned and moved
into the main camera's view (it stands left of the board, facing the camera and the spot light).
`mirage bench` uses it for the rough reflection / refraction paths against the reference
renderer's GGX conductors and dielectrics (docs/specular.md, docs/bench.md).
tabletop_rough35.gltf is tabletop.gltf unchanged but for the glass sphere's and the mirror's
roughness (0.35 both, in place): the rough render's error against the smooth render's, with the
mirror's caustic on the table (docs/specular.md, "Rough light on the tabletop").
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))

with open(os.path.join(HERE, "tabletop.gltf")) as f:
    gltf = json.load(f)
with open(os.path.join(HERE, "tabletop.gltf")) as f:
    rough35 = json.load(f)
names = {n.get("name"): i for i, n in enumerate(gltf["nodes"])}
if "glass_sphere" not in names or "mirror" not in names:
    raise SystemExit("tabletop.gltf has no glass_sphere/mirror nodes: regenerate it first")

glass = gltf["nodes"][names["glass_sphere"]]
metal = gltf["nodes"][names["mirror"]]
glass["name"] = "frosted_glass"
metal["name"] = "brushed_metal"
# Facing +Z turned 30 degrees towards +X (the camera looks down -Z from z = 0.55).
half = math.radians(30.0) / 2
metal["rotation"] = [0.0, math.sin(half), 0.0, math.cos(half)]
metal["translation"] = [-0.2, 0.0, -0.12]


def material_of(node):
    return gltf["meshes"][node["mesh"]]["primitives"][0]["material"]


mg = gltf["materials"][material_of(glass)]
mg["name"] = "frosted glass (virtual)"
mg["pbrMetallicRoughness"]["roughnessFactor"] = 0.3
mm = gltf["materials"][material_of(metal)]
mm["name"] = "brushed metal (virtual)"
mm["pbrMetallicRoughness"]["roughnessFactor"] = 0.25
mm["pbrMetallicRoughness"]["baseColorFactor"] = [0.9, 0.88, 0.85, 1.0]
for scene in gltf["scenes"]:
    scene["name"] = scene.get("name", "tabletop") + "_rough"
with open(os.path.join(HERE, "tabletop_rough.gltf"), "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")

# The sphere and the mirror at roughness 0.35 where they stand in tabletop.gltf.
names35 = {n.get("name"): i for i, n in enumerate(rough35["nodes"])}
for node in ("glass_sphere", "mirror"):
    n = rough35["nodes"][names35[node]]
    mat = rough35["materials"][rough35["meshes"][n["mesh"]]["primitives"][0]["material"]]
    mat["pbrMetallicRoughness"]["roughnessFactor"] = 0.35
with open(os.path.join(HERE, "tabletop_rough35.gltf"), "w") as f:
    json.dump(rough35, f, indent=1)
    f.write("\n")
