#!/usr/bin/env python3
"""Two rooms as Blender's OBJ export writes them, n-gons kept, for trying visgate's polygon
triangulation: two 4 x 3 x 4 m rooms side by side along x, faces turned in, the wall between
them at x = 4 a concave 8-corner polygon on each side, its doorway (1 m wide, 2.1 m high) cut
from the floor edge. A fan from a polygon's first corner, as tobj triangulates, shuts the
doorway.

    bench/ngon_rooms.py OUT

writes OUT/ngon.obj and OUT/ngon.toml (a lamp in the first room, the camera `b` in the second
looking at the doorway): `visgate compare OUT/ngon.toml --modes gates,val-hard --vpls 1024
--size 320x240` (README, Scenes: "Concave polygons").
"""
import os
import sys

L, H, W = 4.0, 3.0, 4.0
# The dividing wall's outline round its doorway, as (z, y).
WALL = [(0, 0), (1.5, 0), (1.5, 2.1), (2.5, 2.1), (2.5, 0), (W, 0), (W, H), (0, H)]


def room(x0, x1, door_at_x1):
    """The faces of a room from x0 to x1 (each a list of corners), turned in; its wall at x1
    (door_at_x1) or at x0 the dividing wall."""
    faces = [
        [(x0, 0, 0), (x0, 0, W), (x1, 0, W), (x1, 0, 0)],  # floor
        [(x0, H, 0), (x1, H, 0), (x1, H, W), (x0, H, W)],  # ceiling
        [(x0, 0, 0), (x1, 0, 0), (x1, H, 0), (x0, H, 0)],  # z = 0
        [(x0, 0, W), (x0, H, W), (x1, H, W), (x1, 0, W)],  # z = W
    ]
    if door_at_x1:
        faces.append([(x0, 0, 0), (x0, H, 0), (x0, H, W), (x0, 0, W)])
        faces.append([(x1, y, z) for (z, y) in WALL])
    else:
        faces.append([(x1, 0, 0), (x1, 0, W), (x1, H, W), (x1, H, 0)])
        faces.append([(x0, y, z) for (z, y) in WALL][::-1])
    return faces


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    lines, count = ["# two rooms, the wall between them a concave n-gon round its doorway"], 0
    for k, faces in enumerate([room(0, L, True), room(L, 2 * L, False)]):
        lines.append(f"o room{k}")
        for face in faces:
            lines += [f"v {x:g} {y:g} {z:g}" for (x, y, z) in face]
            lines.append("f " + " ".join(str(count + i + 1) for i in range(len(face))))
            count += len(face)
    with open(os.path.join(out, "ngon.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(out, "ngon.toml"), "w") as f:
        f.write(
            '[[mesh]]\npath = "ngon.obj"\n\n'
            '[[light]]\ntype = "point"\nposition = [1.0, 2.0, 1.0]\nintensity = [10, 10, 10]\n\n'
            '[[camera]]\nname = "b"\neye = [7.5, 1.5, 3.5]\ntarget = [4.0, 1.0, 2.0]\n'
            "fov_deg = 70\n"
        )


if __name__ == "__main__":
    main()
