#!/usr/bin/env python3
"""Writes the textured room scene (data/scenes/room/): room.gltf + room.bin + the textures.

Python standard library only. Run from anywhere:  python3 data/scenes/room/make_room.py
It reuses the tabletop's builder (data/scenes/tabletop/make_tabletop.py), board (board.json,
board.png) and environment (env.pfm): the same table, board, book, mug, block, spot light and
virtual objects at the same places, so everything said about the tabletop holds here. What
differs: the real surfaces carry texture, as real rooms do, for natural-feature tracking
(docs/tracking.md, "Extended tracking"):
  - the table top is wood with grain, knots and plank seams (wood.png, repeated every 0.40 m),
  - the floor is a speckled stone tile floor (floor.png, repeated every 1.0 m),
  - four walls 2.2 m high at 2.5 m from the table carry a mottled plaster with a tile border
    (wall.png, repeated every 2.2 m); there is no ceiling, so the environment still lights the
    room from above.
All textures are procedural (tileable value noise drawn by this script; no external images),
sRGB-encoded PNG, with the same licence as the project.
World frame = glTF: metres, +Y up; the board page lies on the table top (y = 0) centred at the
origin (tracking/BoardLayout.h).
"""
import math
import os
import random
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
TABLETOP = os.path.join(os.path.dirname(HERE), "tabletop")
sys.path.insert(0, TABLETOP)
import make_tabletop as tt  # noqa: E402  (the shared glTF builder and meshes)


def write_png(path, w, h, pixels):
    """8-bit RGB PNG; pixels: bytes of w*h*3 (rows top to bottom)."""
    raw = bytearray()
    for y in range(h):
        raw.append(0)  # filter: none
        raw += pixels[y * w * 3:(y + 1) * w * 3]

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(bytes(raw), 9)))
        f.write(chunk(b"IEND", b""))


class TileNoise:
    """Tileable value noise on [0, 1)^2: a periodic lattice of `cells` x `rows` random values
    (rows = cells unless given), smoothly interpolated (values in [0, 1])."""

    def __init__(self, cells, rng, rows=None):
        self.n, self.m = cells, rows or cells
        self.v = [[rng.random() for _ in range(self.n)] for _ in range(self.m)]

    def at(self, u, v):
        x, y = u * self.n, v * self.m
        ix, iy = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - ix, y - iy
        sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
        n = self.n
        r0, r1 = self.v[iy % self.m], self.v[(iy + 1) % self.m]
        a = r0[ix % n] + (r0[(ix + 1) % n] - r0[ix % n]) * sx
        b = r1[ix % n] + (r1[(ix + 1) % n] - r1[ix % n]) * sx
        return a + (b - a) * sy


def fbm(octaves, u, v):
    """Sum of octaves [(noise, weight)], normalised to [0, 1]."""
    s = sum(w * o.at(u, v) for o, w in octaves)
    return s / sum(w for _, w in octaves)


def clamp8(x):
    return max(0, min(255, int(round(x))))


def wood(size, rng):
    """Planks along u with grain lines bent by noise, knots and dark seams between planks."""
    warp = [(TileNoise(4, rng), 1.0), (TileNoise(8, rng), 0.5), (TileNoise(16, rng), 0.25)]
    fibre = [(TileNoise(16, rng, 128), 1.0), (TileNoise(32, rng, 256), 0.6)]
    spots = [(TileNoise(48, rng), 1.0), (TileNoise(96, rng), 0.7)]
    planks = 5
    offsets = [rng.random() for _ in range(planks)]
    knots = [(rng.random(), rng.random(), 0.012 + 0.02 * rng.random()) for _ in range(9)]
    light, dark = (196, 142, 88), (112, 66, 34)
    px = bytearray()
    for y in range(size):
        v = y / size
        plank = int(v * planks)
        pv = v * planks - plank
        for x in range(size):
            u = (x / size + offsets[plank]) % 1.0
            w = fbm(warp, u, v)
            g = 0.5 + 0.5 * math.sin(2 * math.pi * (pv * 7 + 3.0 * w + 0.4 * math.sin(2 * math.pi * u)))
            for kx, ky, kr in knots:  # knots: rings around a point, the grain bends round them
                dx, dy = (u - kx + 0.5) % 1.0 - 0.5, (v - ky + 0.5) % 1.0 - 0.5
                d = math.hypot(dx * 2.5, dy)
                if d < 3 * kr:
                    g = 0.5 + 0.5 * math.sin(d / kr * 9.0)
                    if d < 0.6 * kr:
                        g = 0.05
            # Pores: short dark streaks along the grain (noise cells 8x longer along u), and
            # darker patches; both give the grain corners that a tracker can hold on to.
            f = fbm(fibre, u, v)
            s = fbm(spots, u, v)
            t = 0.5 * g + 0.25 * s
            if f < 0.38:
                t -= 0.5 * (0.38 - f) / 0.38 + 0.15
            if pv < 0.012 or pv > 0.988:  # seam between planks
                t = -0.3
            px += bytes(clamp8(dark[c] + (light[c] - dark[c]) * t) for c in range(3))
    return px


def floor(size, rng):
    """Stone tiles (4 x 4 per texture) with speckles, a mottled tone and grout lines."""
    tone = [(TileNoise(8, rng), 1.0), (TileNoise(16, rng), 0.5)]
    speck = [(TileNoise(96, rng), 1.0), (TileNoise(192, rng), 0.8)]
    tiles = 4
    tint = [[0.8 + 0.4 * rng.random() for _ in range(tiles)] for _ in range(tiles)]
    px = bytearray()
    for y in range(size):
        v = y / size
        ty = int(v * tiles)
        fy = v * tiles - ty
        for x in range(size):
            u = x / size
            tx = int(u * tiles)
            fx = u * tiles - tx
            s = fbm(speck, u, v)
            k = 1.0 if s < 0.62 else (0.35 if s > 0.72 else 1.0 - (s - 0.62) * 6.5)  # dark flecks
            b = (0.55 + 0.45 * fbm(tone, u, v)) * tint[ty][tx] * k
            if fx < 0.015 or fy < 0.015:  # grout
                b = 0.25
            px += bytes(clamp8(c * b) for c in (190, 180, 165))
    return px


def wall(size, rng):
    """Mottled plaster with a band of square tiles along its lower edge (the texture's bottom)."""
    mottle = [(TileNoise(6, rng), 1.0), (TileNoise(12, rng), 0.6), (TileNoise(24, rng), 0.4),
              (TileNoise(64, rng), 0.3)]
    tiles = 8
    colours = [(rng.choice([(70, 95, 140), (180, 90, 60), (230, 225, 210)])) for _ in range(tiles)]
    px = bytearray()
    for y in range(size):
        v = y / size
        for x in range(size):
            u = x / size
            m = fbm(mottle, u, v)
            col = [c * (0.55 + 0.7 * m) for c in (205, 200, 185)]
            if v > 0.8:  # tile band
                t = int(u * tiles)
                fu, fv = u * tiles - t, (v - 0.8) / 0.2
                col = [c * (0.8 + 0.3 * m) for c in colours[(t + int(fv * 2)) % tiles]]
                if fu < 0.04 or abs(fv - 0.5) < 0.02:
                    col = (60, 60, 60)
            px += bytes(clamp8(c) for c in col)
    return px


def quad(corners, normal, uv_scale):
    """A quad with corners p0..p3 (counter-clockwise seen along -normal) and texture coordinates
    in metres / uv_scale (the texture repeats every uv_scale metres)."""
    p0, p1, p3 = corners[0], corners[1], corners[3]
    eu = [p1[i] - p0[i] for i in range(3)]
    ev = [p3[i] - p0[i] for i in range(3)]
    lu, lv = math.sqrt(sum(c * c for c in eu)), math.sqrt(sum(c * c for c in ev))
    uvs = [[0, 0], [lu / uv_scale, 0], [lu / uv_scale, lv / uv_scale], [0, lv / uv_scale]]
    return [list(c) for c in corners], [list(normal)] * 4, uvs, [0, 1, 2, 0, 2, 3]


def main():
    rng = random.Random(20260401)
    textures = {"wood.png": (wood, 512), "floor.png": (floor, 512), "wall.png": (wall, 256)}
    for name, (fn, size) in textures.items():
        path = os.path.join(HERE, name)
        if not os.path.exists(path) or "--force" in sys.argv:
            write_png(path, size, size, fn(size, rng))
    # The tabletop's board texture and environment image, copied beside the scene: a scene may
    # name only files inside its own folder (docs/scene.md).
    import shutil
    for name in ("board.png", "env.pfm"):
        shutil.copyfile(os.path.join(TABLETOP, name), os.path.join(HERE, name))

    import json
    with open(os.path.join(TABLETOP, "board.json")) as f:
        board = json.load(f)
    sheet_w, sheet_h = board["sheet"]["width"], board["sheet"]["height"]

    b = tt.Builder()
    b.gltf["asset"]["generator"] = "mirage data/scenes/room/make_room.py"
    b.gltf["scenes"][0]["name"] = "room"
    board_tex = b.texture("board.png")
    wood_tex, floor_tex, wall_tex = b.texture("wood.png"), b.texture("floor.png"), b.texture("wall.png")
    for t in (wood_tex, floor_tex, wall_tex):  # repeat (the board texture stays clamped)
        b.gltf["samplers"][b.gltf["textures"][t]["sampler"]].update({"wrapS": 10497, "wrapT": 10497})
    m_table = b.material("table wood", [1.0, 1.0, 1.0], roughness=0.6, texture=wood_tex)
    m_floor = b.material("floor stone", [1.0, 1.0, 1.0], roughness=0.9, texture=floor_tex)
    m_wall = b.material("wall plaster", [1.0, 1.0, 1.0], roughness=0.95, texture=wall_tex)
    m_board = b.material("board paper", [0.85, 0.85, 0.85], roughness=0.9, texture=board_tex)
    m_book = b.material("book", [0.08, 0.15, 0.45], roughness=0.7)
    m_mug = b.material("mug ceramic", [0.6, 0.12, 0.08], roughness=0.3)
    m_block = b.material("block", [0.55, 0.45, 0.25], roughness=0.8)
    m_glass = b.material("glass (virtual)", [1.0, 1.0, 1.0], roughness=0.0, transmission=1.0, ior=1.5,
                         attenuation=([0.85, 0.93, 1.0], 0.1))
    m_mirror = b.material("mirror (virtual)", [0.95, 0.95, 0.95], metallic=1.0, roughness=0.0)
    m_vbox = b.material("yellow box (virtual)", [0.8, 0.6, 0.05], roughness=0.6)

    # Table: the textured top (just under the board page at y = 0) on a plain box body.
    top_y = -0.0005
    b.node("table_top", True, b.mesh("table_top", *quad(
        [[-0.6, top_y, 0.4], [0.6, top_y, 0.4], [0.6, top_y, -0.4], [-0.6, top_y, -0.4]], [0, 1, 0], 0.4),
        m_table))
    b.node("table", True, b.mesh("table", *tt.box([-0.6, -0.04, -0.4], [0.6, -0.001, 0.4]), m_table))
    fy = -0.75
    b.node("floor", True, b.mesh("floor", *quad(
        [[-2.5, fy, 2.5], [2.5, fy, 2.5], [2.5, fy, -2.5], [-2.5, fy, -2.5]], [0, 1, 0], 1.0), m_floor))
    # Walls facing the room; texture v grows downwards, so the tile band is at the floor.
    top = fy + 2.2
    walls = [([[-2.5, top, -2.5], [2.5, top, -2.5], [2.5, fy, -2.5], [-2.5, fy, -2.5]], [0, 0, 1]),
             ([[2.5, top, 2.5], [-2.5, top, 2.5], [-2.5, fy, 2.5], [2.5, fy, 2.5]], [0, 0, -1]),
             ([[-2.5, top, 2.5], [-2.5, top, -2.5], [-2.5, fy, -2.5], [-2.5, fy, 2.5]], [1, 0, 0]),
             ([[2.5, top, -2.5], [2.5, top, 2.5], [2.5, fy, 2.5], [2.5, fy, -2.5]], [-1, 0, 0])]
    for i, (corners, n) in enumerate(walls):
        # The texture spans the wall's height once: its tile band (the bottom 20 %) meets the floor.
        pos, nrm, uv, idx = quad(corners, n, 2.2)
        b.node("wall_%d" % i, True, b.mesh("wall_%d" % i, pos, nrm, uv, idx, m_wall))
    hw, hh = sheet_w / 2, sheet_h / 2
    board_quad = ([[-hw, 0, -hh], [hw, 0, -hh], [hw, 0, hh], [-hw, 0, hh]], [[0, 1, 0]] * 4,
                  [[0, 0], [1, 0], [1, 1], [0, 1]], [0, 2, 1, 0, 3, 2])
    b.node("board", True, b.mesh("board", *board_quad, m_board))
    b.node("book", True, b.mesh("book", *tt.box([0.2, 0, -0.33], [0.42, 0.04, -0.17]), m_book))
    b.node("mug", True, b.mesh("mug", *tt.cylinder(0.04, 0.1), m_mug), translation=[-0.3, 0, -0.22])
    b.node("block", True, b.mesh("block", *tt.box([-0.03, 0, -0.03], [0.03, 0.06, 0.03]), m_block),
           translation=[0.33, 0, 0.2])
    spot_pos = [0.35, 0.95, 0.45]
    b.node("spot", True, light=b.spot("spot", 1.6, [1.0, 0.95, 0.85], 0.35, 0.55), translation=spot_pos,
           rotation=tt.look_at_rotation(spot_pos, [0, 0, 0]))
    b.node("glass_sphere", False, b.mesh("glass_sphere", *tt.uv_sphere(0.045), m_glass),
           translation=[0.02, 0.045, 0.16])
    mirror_rot = tt.look_at_rotation([0, 0, 0], [-1, 0, -1])
    b.node("mirror", False, b.mesh("mirror", *tt.box([-0.1, 0, -0.003], [0.1, 0.14, 0.003]), m_mirror),
           translation=[-0.33, 0, 0.05], rotation=mirror_rot)
    b.node("yellow_box", False, b.mesh("yellow_box", *tt.box([-0.03, 0, -0.03], [0.03, 0.06, 0.03]), m_vbox),
           translation=[0.22, 0, 0.02])
    eye = [0.0, 0.42, 0.55]
    b.node("main", True, camera=b.camera("main", 45.0), translation=eye,
           rotation=tt.look_at_rotation(eye, [0, 0, 0]))
    b.gltf["scenes"][0]["extras"] = {"mirage": {"environment": {
        "type": "equirectangular", "image": "env.pfm", "intensity": 1.0, "rotation_y_deg": 0}}}
    b.write(os.path.join(HERE, "room.gltf"), "room.bin")


if __name__ == "__main__":
    main()
