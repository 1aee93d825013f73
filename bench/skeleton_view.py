#!/usr/bin/env python3
"""Draws a bake's skeleton (`visgate bake … --debug-dir DIR`, its skeleton.ply) seen from above
or from the side, each edge coloured by the smaller max ball of its ends: red under 0.2 m,
yellow under 0.5 m, blue wider. Needs numpy and Pillow.

    bench/skeleton_view.py DIR/skeleton.ply OUT.png [top|side] [WIDTH]
"""
import sys

import numpy as np
from PIL import Image, ImageDraw


def load(path):
    lines = open(path).read().split("\n")
    h = lines.index("end_header")
    count = lambda what: int(next(l for l in lines[:h] if l.startswith(what)).split()[2])
    nv, ne = count("element vertex"), count("element edge")
    v = np.array([[float(x) for x in l.split()] for l in lines[h + 1 : h + 1 + nv]])
    e = np.array([[int(x) for x in l.split()] for l in lines[h + 1 + nv : h + 1 + nv + ne]])
    return v, e


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        sys.exit(2)
    v, e = load(sys.argv[1])
    view = sys.argv[3] if len(sys.argv) > 3 else "top"
    width = int(sys.argv[4]) if len(sys.argv) > 4 else 1400
    a, b = (0, 2) if view == "top" else (0, 1)
    lo, hi = v[:, [a, b]].min(0), v[:, [a, b]].max(0)
    scale = (width - 20) / (hi - lo).max()
    im = Image.new("RGB", (width, int((hi - lo)[1] * scale) + 20), "black")
    draw = ImageDraw.Draw(im)
    p = (v[:, [a, b]] - lo) * scale + 10
    if view == "side":
        p[:, 1] = im.height - p[:, 1]  # up is up
    for i, j in e:
        r = min(v[i, 3], v[j, 3])
        colour = (255, 60, 60) if r < 0.2 else (255, 200, 0) if r < 0.5 else (80, 160, 255)
        draw.line([tuple(p[i]), tuple(p[j])], fill=colour, width=1)
    im.save(sys.argv[2])


main()
