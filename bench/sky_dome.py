#!/usr/bin/env python3
"""A level's OBJ wrapped in a sky dome, as some exports bring one: a UV sphere round it as an
object of its own, for trying how visgate reads a bare mesh with one.

    bench/sky_dome.py LEVEL.obj OUT.obj [RADIUS] [SEGMENTS] [CENTRE]

copies LEVEL.obj (in its own units) to OUT.obj and appends the object `SkyDome`: a sphere of
RADIUS units (default 2000) round CENTRE (default "30,0,40", x,y,z) of SEGMENTS x SEGMENTS/2
quads (default 48: 2,208 triangles), facing in. With LibreQuake e2m3's OBJ (copy its MTL and
textures beside OUT.obj), `visgate inspect OUT.obj` shows the dome left out; at RADIUS 500 it
is kept and named by `visgate bake OUT.obj` (README, The bake: "A sky dome").
"""
import math
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    radius = float(sys.argv[3]) if len(sys.argv) > 3 else 2000.0
    nu = int(sys.argv[4]) if len(sys.argv) > 4 else 48
    centre = [float(c) for c in (sys.argv[5] if len(sys.argv) > 5 else "30,0,40").split(",")]
    nv = nu // 2
    lines = open(src).read().splitlines()
    first = 1 + sum(1 for line in lines if line.startswith("v "))
    lines += ["o SkyDome", "usemtl sky_dome"]
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu):
            ph = 2 * math.pi * i / nu
            p = [math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)]
            lines.append("v %.4f %.4f %.4f" % tuple(c + radius * d for c, d in zip(centre, p)))

    def at(j, i):
        return first + j * nu + i % nu

    for j in range(nv):
        for i in range(nu):
            a, b, c, d = at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i)
            if j > 0:
                lines.append("f %d %d %d" % (a, c, b))
            if j < nv - 1:
                lines.append("f %d %d %d" % (a, d, c))
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
