"""Issue 19's error table (the gates paper's Table II, extended): every visibility mode against
the CPU reference with the same VPLs, on the built-ins that hold what real levels have (zero-
thickness walls, a door ajar, a table, columns, a window to the void, a floor with a stair hole)
and on the shared levels, two light configurations each, every camera.

Usage: python3 bench/error_table.py VISGATE OUT [SCENE...]

VISGATE: the visgate binary (a release build). OUT: a folder; it gets OUT/configs/ (the scene
TOMLs of each light configuration), OUT/LEVEL.vgate (the shared levels baked at 256), one
`visgate compare` folder per configuration (report.md/html/json, panels/, renders/: run again
after a stop, only what is missing is rendered) and OUT/table.md: indirect MSE, then indirect
energy / black where lit, then frame ms on this machine's adapter. SCENE: any of ajar-door,
pillared-hall, stairwell, sun-window, e2m3, sponza (default all). Needs ../shared/scenes beside
the repository for e2m3 and sponza.

The light configurations: a scene's two lights each alone (the pillared hall, e2m3, Sponza),
or the built-in's light and the same light moved to the other room or storey (the ajar door,
the stairwell); the sun window has one (its sun). Built-ins at their default bake (128),
320 x 240, 4 spp; the shared levels baked at 256, 320 x 180, 1 spp (the reference traces Sponza's
262,000 triangles); 1,024 light paths each."""
import json
import os
import re
import subprocess
import sys

MODES = ["none", "gates", "gates-fast", "gates-portal", "gates-disk", "val-hard", "val-cssm",
         "per-vpl-shadow-maps"]
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = {"e2m3": "scenes/shared/librequake-e2m3.toml",
          "sponza": "scenes/shared/crytek-sponza.toml"}
# Built-ins whose second configuration moves their one light: (name, position, where).
MOVED = {"ajar-door": ("1.2, 2.5, 0.8", "the near room"),
         "stairwell": ("6.5, 2.5, 4.5", "downstairs")}


def run(cmd):
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, cwd=REPO)


def split_lights(text):
    """The TOML before its first [[light]], each [[light]] block, and the rest (cameras)."""
    i, j = text.index("[[light]]"), text.index("[[camera]]")
    blocks = ["[[light]]" + b for b in text[i:j].split("[[light]]")[1:]]
    return text[:i], blocks, text[j:]


def light_of(block):
    """A light block's type and position, for the table's light column."""
    kind = re.search(r'type = "(\w+)"', block).group(1)
    pos = re.search(r"position = \[([^\]]*)\]", block).group(1)
    pos = ", ".join(f"{float(x):g}" for x in pos.replace("\n", " ").split(",") if x.strip())
    return f"{kind} at ({pos})"


def configs(visgate, out, scene):
    """[(label, toml, level or None, size args)] of a scene's light configurations."""
    cfg = os.path.join(out, "configs")
    os.makedirs(cfg, exist_ok=True)
    if scene in SHARED:
        src = os.path.join(REPO, SHARED[scene])
        shared = os.path.join(REPO, "..", "shared") + "/"
        text = open(src).read().replace("../../../shared/", shared)
        level = os.path.join(out, f"{scene}.vgate")
        if not os.path.exists(level):
            run([visgate, "bake", SHARED[scene], "--resolution", "256", "-o", level])
        size = ["--size", "320x180", "--spp", "1"]
    else:
        run([visgate, "scenes", "export", scene, cfg])
        text = open(os.path.join(cfg, f"{scene}.toml")).read()
        level, size = None, ["--size", "320x240"]
    head, lights, rest = split_lights(text)
    if len(lights) == 1 and scene in MOVED:
        pos, where = MOVED[scene]
        lights.append(re.sub(r"position = \[[^\]]*\]", f"position = [{pos}]", lights[0]))
    found = []
    for k, block in enumerate(lights):
        toml = os.path.join(cfg, f"{scene}-{'AB'[k]}.toml")
        with open(toml, "w") as f:
            f.write(head + block + "\n" + rest)
        found.append((light_of(block), toml, level, size))
    return found


def parse(report):
    """{camera: {mode: (frame ms, indirect MSE, energy, black where lit)}} of a compare
    report.json, black where lit as the report writes it (with the lit pixels where they are
    under 5 % of the frame)."""
    data = json.load(open(report))
    out = {cam: {} for cam in data["cameras"]}
    for r in data["rows"]:
        if r["mode"] not in MODES:
            continue
        black = f"{100 * r['black_where_lit']:.1f} %"
        if r["lit_pixels"] < 0.05 * r["pixels"]:
            black += f" of {r['lit_pixels']} px"
        out[r["camera"]][r["mode"]] = (r["total_ms"], r["indirect_mse"], r["energy_ratio"], black)
    return out


def tables(rows):
    """The three Markdown tables of `rows` [(scene, light, camera, {mode: figures})]."""
    head = ("| level | light | camera | " + " | ".join(MODES) + " |\n|---|---|---|"
            + "---|" * len(MODES))
    mse, eb, ms = [head], [head], [head]
    for scene, light, cam, r in rows:
        best = min(r[m][1] for m in MODES if m in r and m != "per-vpl-shadow-maps")

        def cells(show):
            return " | ".join(show(r[m]) if m in r else "–" for m in MODES)

        pre = f"| {scene} | {light} | {cam} | "
        bold = lambda v: f"**{v[1]:.2e}**" if v[1] == best else f"{v[1]:.2e}"  # noqa: E731
        mse.append(pre + cells(bold) + " |")
        eb.append(pre + cells(lambda v: f"{v[2]:.2f} / {v[3]}") + " |")
        ms.append(pre + cells(lambda v: f"{v[0]:.0f}") + " |")
    return ("Indirect MSE (bold: the lowest but per-VPL maps')\n\n" + "\n".join(mse)
            + "\n\nIndirect energy / black where lit\n\n" + "\n".join(eb)
            + "\n\nFrame ms\n\n" + "\n".join(ms) + "\n")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    visgate, out = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    scenes = sys.argv[3:] or ["ajar-door", "pillared-hall", "stairwell", "sun-window", "e2m3",
                              "sponza"]
    rows = []
    for scene in scenes:
        for light, toml, level, size in configs(visgate, out, scene):
            dest = os.path.join(out, os.path.basename(toml)[:-5])
            cmd = [visgate, "compare", toml, "--modes", ",".join(MODES), "--vpls", "1024", *size,
                   "--out", dest]
            run(cmd + (["--level", level] if level else []))
            for cam, r in parse(os.path.join(dest, "report.json")).items():
                rows.append((scene, light, cam, r))
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(tables(rows))
    print(f"wrote {os.path.join(out, 'table.md')}")


if __name__ == "__main__":
    main()
