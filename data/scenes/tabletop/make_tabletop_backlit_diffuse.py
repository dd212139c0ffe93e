#!/usr/bin/env python3
"""Writes tabletop_backlit_diffuse.gltf: the backlit tabletop without its specular virtual objects.

Python standard library only; run after make_tabletop_backlit.py:
    python3 data/scenes/tabletop/make_tabletop_backlit_diffuse.py
Same buffers, materials, lights, cameras and environment as tabletop_backlit.gltf; only the glass sphere
and the mirror are left out of the scene's root nodes, so the only VIRTUAL object is the diffuse
yellow box, lit by the backlit spot that lit the bundled sample: `mirage live` on the sample
compares the glass frame with this diffuse one (docs/live.md, "Frame-time budget").
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))

with open(os.path.join(HERE, "tabletop_backlit.gltf")) as f:
    gltf = json.load(f)
drop = {i for i, n in enumerate(gltf["nodes"]) if n.get("name") in ("glass_sphere", "mirror")}
if len(drop) != 2:
    raise SystemExit("tabletop_backlit.gltf has no glass_sphere/mirror nodes: regenerate it first")
for scene in gltf["scenes"]:
    scene["nodes"] = [i for i in scene["nodes"] if i not in drop]
    scene["name"] = scene.get("name", "tabletop") + "_diffuse"
with open(os.path.join(HERE, "tabletop_backlit_diffuse.gltf"), "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
