#!/usr/bin/env python3
"""Writes tabletop_backlit.gltf: the bundled tabletop scene lit from behind the glass sphere.

Python standard library only; run after make_tabletop.py:
    python3 data/scenes/tabletop/make_tabletop_backlit.py
Same buffers, materials, objects, cameras and environment as tabletop.gltf; only the real spot
light is moved (same colour, intensity and cone). In tabletop.gltf the spot shines from high
above the camera's side (elevation ~64 degrees seen from the sphere), so the glass sphere's
focused caustic falls on the table under the sphere, on the side away from the camera, and the
sphere hides it. Here the spot stands behind the sphere as the bundled sample's cameras see it
(they orbit the +Z side of the board, docs/reference-renderer.md) and lower (~41 degrees), so
the ray through the sphere's centre meets the table 6.9 cm from the centre, at the ball lens's
focal distance n r / (2 (n - 1)) = 6.75 cm, 5 cm in front of the sphere: the caustic is a
focused spot on the table on the camera's side, inside the sphere's tinted shadow. The spot
still lights the board (within 12 degrees of the cone's axis, inner cone 20) and the mirror
(17 degrees, from its front at a grazing 84 degrees). The bundled sample session
(data/sessions/sample) is synthesised from this scene.
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # no __pycache__ beside the scene files
sys.path.insert(0, HERE)
from make_tabletop import look_at_rotation  # noqa: E402  (the same light orientation rule)

# World frame = glTF: metres, +Y up; the board lies on the table (y = 0) centred at the origin.
SPOT_POSITION = [0.4, 0.7, -0.5]
# Between the board's centre and the sphere, so both lie well inside the inner cone.
SPOT_TARGET = [0.0, 0.0, 0.05]


def main():
    with open(os.path.join(HERE, "tabletop.gltf")) as f:
        gltf = json.load(f)
    spots = [n for n in gltf["nodes"] if n.get("name") == "spot"]
    if len(spots) != 1 or not any(n.get("name") == "glass_sphere" for n in gltf["nodes"]):
        raise SystemExit("tabletop.gltf has no spot/glass_sphere nodes: regenerate it first")
    spots[0]["translation"] = list(SPOT_POSITION)
    spots[0]["rotation"] = look_at_rotation(SPOT_POSITION, SPOT_TARGET)
    for scene in gltf["scenes"]:
        scene["name"] = scene.get("name", "tabletop") + "_backlit"
    with open(os.path.join(HERE, "tabletop_backlit.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
