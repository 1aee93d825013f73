#!/usr/bin/env python3
"""An apartment as a user's modeller hands it over, for trying visgate on a level unlike the
built-ins: a bare OBJ without an MTL, in millimetres, Z up, with

- walls of zero thickness (single quads), one of them wound to face out;
- a door ajar 20 degrees on a 10 mm hinge gap, a 40 mm panel;
- a window to the void (nothing outside it);
- a table on four legs and a column in the living room;
- a room C reached only through a corridor from room B.

    bench/apartment.py OUT

writes OUT/apartment.obj and four scene files beside it, each one light and the same four
cameras: apartment-a.toml (a lamp in the living room A), apartment-c.toml (a lamp in room C),
apartment-spot.toml (a spot in room B aimed at the door) and apartment-sun.toml (a lamp
outside A's window, whose light paths mostly leave the level). Run the bare OBJ first to see
what visgate makes of it (`visgate bake OUT/apartment.obj`), then the scene files, which say
`metres_per_unit = 0.001` and `up = "z"` (README, "A third level unlike the built-ins").
"""

import math
import sys
from pathlib import Path

# Millimetres throughout; Z up.
HEIGHT = 2700.0
DOOR_W, DOOR_H, DOOR_T = 900.0, 2100.0, 40.0
HINGE_GAP = 10.0
DOOR_OPEN_DEG = 20.0


class Mesh:
    """Triangles in OBJ objects; quads are given counter-clockwise seen from their front."""

    def __init__(self):
        self.vertices = []
        self.objects = []

    def object(self, name):
        self.objects.append((name, []))

    def quad(self, a, b, c, d):
        base = len(self.vertices) + 1
        self.vertices.extend([a, b, c, d])
        faces = self.objects[-1][1]
        faces.append((base, base + 1, base + 2))
        faces.append((base, base + 2, base + 3))

    def box(self, lo, hi):
        """An axis-aligned box, its faces out."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        self.quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0))  # -z
        self.quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))  # +z
        self.quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))  # -y
        self.quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))  # +y
        self.quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))  # -x
        self.quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))  # +x

    def wall(self, p, q, z0, z1, facing_left=True):
        """A zero-thickness wall from p to q (x, y), between heights z0 and z1, facing to the
        left of p -> q (or to its right)."""
        a, b = (p[0], p[1], z0), (q[0], q[1], z0)
        c, d = (q[0], q[1], z1), (p[0], p[1], z1)
        # (q - p) x up faces right of p -> q: the order that faces left is b, a, d, c.
        if facing_left:
            self.quad(b, a, d, c)
        else:
            self.quad(a, b, c, d)

    def write(self, path):
        lines = ["# visgate bench/apartment.py: millimetres, Z up, no materials"]
        lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in self.vertices]
        for name, faces in self.objects:
            lines.append(f"o {name}")
            lines += [f"f {a} {b} {c}" for a, b, c in faces]
        path.write_text("\n".join(lines) + "\n")


def wall_with_opening(m, p, q, lo, hi, z0, z1, facing_left=True):
    """A wall from p to q with an opening from distance lo to hi along it, between heights z0
    and z1 (z0 = 0: a doorway)."""
    length = math.dist(p, q)
    at = lambda s: (p[0] + (q[0] - p[0]) * s / length, p[1] + (q[1] - p[1]) * s / length)
    m.wall(p, at(lo), 0.0, HEIGHT, facing_left)
    m.wall(at(hi), q, 0.0, HEIGHT, facing_left)
    m.wall(at(lo), at(hi), z1, HEIGHT, facing_left)
    if z0 > 0.0:
        m.wall(at(lo), at(hi), 0.0, z0, facing_left)


def door(m, hinge, closed_dir, open_deg):
    """A door panel hinged at `hinge` (x, y), closed along the unit vector `closed_dir`, turned
    open by open_deg about the hinge, HINGE_GAP from it."""
    a = math.radians(open_deg)
    ux = closed_dir[0] * math.cos(a) - closed_dir[1] * math.sin(a)
    uy = closed_dir[0] * math.sin(a) + closed_dir[1] * math.cos(a)
    nx, ny = -uy, ux
    s0, s1 = HINGE_GAP, HINGE_GAP + DOOR_W
    corners = [
        (hinge[0] + ux * s + nx * t, hinge[1] + uy * s + ny * t)
        for s, t in [(s0, 0.0), (s1, 0.0), (s1, DOOR_T), (s0, DOOR_T)]
    ]
    bottom = [(x, y, 0.0) for x, y in corners]
    top = [(x, y, DOOR_H) for x, y in corners]
    m.quad(*reversed(bottom))
    m.quad(*top)
    for i in range(4):
        j = (i + 1) % 4
        m.quad(bottom[i], bottom[j], top[j], top[i])


def table(m, x, y):
    """A table 1600 x 900, its top 40 mm thick at 720-760 mm, on four 50 mm legs."""
    m.box((x, y, 720.0), (x + 1600.0, y + 900.0, 760.0))
    for lx, ly in [(x + 50, y + 50), (x + 1500, y + 50), (x + 50, y + 800), (x + 1500, y + 800)]:
        m.box((lx, ly, 0.0), (lx + 50.0, ly + 50.0, 720.0))


def apartment():
    m = Mesh()
    # Living room A: x 0-5000, y 0-6000; room B: x 5000-9000, y 0-3500; corridor into room
    # C: x 5000-9000, y 3500-6000 (C behind a partition at x 7000 with a doorway).
    m.object("floor")
    m.quad((0, 0, 0), (9000, 0, 0), (9000, 6000, 0), (0, 6000, 0))
    m.object("ceiling")
    m.quad((0, 0, HEIGHT), (0, 6000, HEIGHT), (9000, 6000, HEIGHT), (9000, 0, HEIGHT))
    m.object("outer walls")
    m.wall((0, 0), (9000, 0), 0, HEIGHT)
    m.wall((9000, 0), (9000, 6000), 0, HEIGHT)
    # Wound to face out, as a modeller's flipped normal leaves it.
    m.wall((9000, 6000), (0, 6000), 0, HEIGHT, facing_left=False)
    m.object("window wall")
    wall_with_opening(m, (0, 6000), (0, 0), 2000, 4000, 900, 2100)
    m.object("partition A-B")
    wall_with_opening(m, (5000, 0), (5000, 3500), 1500, 1500 + DOOR_W, 0, DOOR_H)
    m.object("partition A-corridor")
    m.wall((5000, 3500), (5000, 6000), 0, HEIGHT)
    m.object("partition B-corridor")
    wall_with_opening(m, (9000, 3500), (5000, 3500), 500, 1400, 0, DOOR_H)
    m.object("partition corridor-C")
    wall_with_opening(m, (7000, 3500), (7000, 6000), 800, 800 + DOOR_W, 0, DOOR_H)
    m.object("door")
    door(m, (5000, 1500 + DOOR_W), (0.0, -1.0), -DOOR_OPEN_DEG)
    m.object("table")
    table(m, 1200, 1200)
    m.object("column")
    m.box((2500, 4200, 0), (2800, 4500, HEIGHT))
    return m


CAMERAS = [
    # name, eye, target (mm, Z up)
    ("a-door", (600, 4800, 1600), (5000, 1900, 1100)),
    ("a-window", (4200, 2500, 1500), (0, 3200, 1400)),
    ("b-door", (8600, 400, 1600), (5000, 2000, 1000)),
    ("corridor", (6000, 3800, 1600), (8800, 5800, 1000)),
]

LIGHTS = {
    "a": '[[light]]\ntype = "point"\nposition = [2500, 2000, 2400]\nintensity = [15, 14.3, 13]\n',
    "c": '[[light]]\ntype = "point"\nposition = [8000, 4800, 2400]\nintensity = [15, 14.3, 13]\n',
    # Outside the window to the void, above it: most of its paths leave the level.
    "sun": '[[light]]\ntype = "point"\nposition = [-3000, 3000, 3500]\nintensity = [60, 57, 52]\n',
    "spot": (
        '[[light]]\ntype = "spot"\nposition = [8500, 3000, 2400]\ntarget = [5400, 1900, 0]\n'
        "cutoff_deg = 40\nbeam_deg = 30\nintensity = [40, 40, 40]\n"
    ),
}


def scene_text(light):
    cameras = "".join(
        f'\n[[camera]]\nname = "{name}"\neye = [{e[0]}, {e[1]}, {e[2]}]\n'
        f"target = [{t[0]}, {t[1]}, {t[2]}]\nfov_deg = 75\n"
        for name, e, t in CAMERAS
    )
    return (
        "# bench/apartment.py: a bare OBJ in millimetres, Z up, with one light and four cameras.\n"
        f'name = "apartment-{light}"\nup = "z"\nmetres_per_unit = 0.001\n\n'
        '[[mesh]]\npath = "apartment.obj"\n\n' + LIGHTS[light] + cameras
    )


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    apartment().write(out / "apartment.obj")
    for light in LIGHTS:
        (out / f"apartment-{light}.toml").write_text(scene_text(light))
    print(f"wrote {out / 'apartment.obj'} and apartment-{{{','.join(LIGHTS)}}}.toml beside it")


if __name__ == "__main__":
    main()
