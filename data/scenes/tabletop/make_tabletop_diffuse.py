#!/usr/bin/env python3
"""Writes tabletop_diffuse.gltf: the bundled tabletop scene without its specular virtual objects.

Python standard library only; run after make_tabletop.py:
    python3 data/scenes/tabletop/make_tabletop_diffuse.py
Same buffers, materials, lights, cameras and environment as tabletop.gltf; only the glass sphere
and the mirror are left out of the scene's root nodes, so the only VIRTUAL object is the diffuse
yellow box. `mirage bench` uses it to measure the diffuse/glossy real-time path (VPLs, shadows)
against the reference renderer without the error of the specular objects that the real-time
renderer does not model yet (docs/bench.md).
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))

with open(os.path.join(HERE, "tabletop.gltf")) as f:
    gltf = json.load(f)
drop = {i for i, n in enumerate(gltf["nodes"]) if n.get("name") in ("glass_sphere", "mirror")}
if len(drop) != 2:
    raise SystemExit("tabletop.gltf has no glass_sphere/mirror nodes: regenerate it first")
for scene in gltf["scenes"]:
    scene["nodes"] = [i for i in scene["nodes"] if i not in drop]
    scene["name"] = scene.get("name", "tabletop") + "_diffuse"
with open(os.path.join(HERE, "tabletop_diffuse.gltf"), "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
