#!/usr/bin/env bash
# The README's bake table: each shared level baked at each resolution by one visgate binary,
# one run each, as a Markdown row: stage times (s; "partition grid" and "refine" only where the
# level's voxels are finer than the partition voxel), the whole bake's wall time, the process's
# peak resident memory (GNU time), the file's size and the headline counts.
#
#   bench/bake_table.sh VISGATE OUT [RESOLUTION...]
#
# VISGATE: the visgate binary (a release build). OUT: a folder for the levels and reports.
# RESOLUTION: voxels on the longest axis (default: 128 256 512). THREADS=N in the environment
# bakes on N threads (default: all cores). Needs ../shared/scenes beside the repository (see
# README) and GNU time (/usr/bin/time, Debian's package `time`).
set -euo pipefail
if [ $# -lt 2 ]; then
    sed -n '2,/^set /p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'
    exit 2
fi
bin=$1 out=$2
shift 2
resolutions=${*:-128 256 512}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
threads=()
[ -n "${THREADS:-}" ] && threads=(--threads "$THREADS")

echo "| level | res | grid | total s | voxelize | sight grid | empty | partition grid | distance | thin | graph | clusters + gates | flatten | refine | portals | topology | peak MiB | file MB | clusters / gates / portals |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for scene in crytek-sponza dabrovic-sponza-80-lights librequake-e2m3; do
    for res in $resolutions; do
        name=$scene-$res
        /usr/bin/time -f '%M' -o "$out/$name.rss" \
            "$bin" bake "$here/scenes/shared/$scene.toml" --resolution "$res" "${threads[@]}" \
            -o "$out/$name.vgate" --report "$out/$name.json" > "$out/$name.log" 2>&1
        python3 - "$out/$name.json" "$out/$name.rss" "$out/$name.vgate" "$scene" "$res" <<'EOF'
import json, os, sys
report, rss, level, scene, res = sys.argv[1:]
r = json.load(open(report))
t = {s["name"]: s["seconds"] for s in r["stages"]}
# Stages a bake on its own grid does not run: a dash.
cell = lambda k: f"{t[k]:.2f}" if k in t else "–"
g = r["grid"]["dims"]
s = r["summary"]
cells = [scene, res, "×".join(map(str, g)), f"{r['total_seconds']:.2f}"]
cells += [cell(k) for k in ("voxelize", "sight grid", "empty space")]
cells.append(cell("partition grid: voxelize, empty space"))
cells += [cell(k) for k in ("distance", "thin", "skeleton graph")]
cells.append(f"{t['clusters'] + t['gates']:.2f}")
cells += [cell(k) for k in ("flatten", "refine", "portals", "topology check")]
cells.append(f"{int(open(rss).read().split()[-1]) / 1024:.0f}")
cells.append(f"{os.path.getsize(level) / 1e6:.1f}")
cells.append(f"{s['clusters']} / {s['gates']} / {s['portals']}")
print("| " + " | ".join(cells) + " |")
EOF
    done
done
