#!/usr/bin/env bash
# The timing table of issue 19 (the gates paper's Table I, extended): GPU ms of the frame after
# one warm-up for every visibility mode, at several VPL counts and sizes, on the shared levels
# baked at 256, and a table of them.
#
#   bench/gpu_sweep.sh VISGATE OUT [LEVEL...]
#
# VISGATE: the visgate binary (a release build). OUT: a folder; it gets OUT/LEVEL.vgate,
# OUT/log.txt (every render's report) and OUT/table.md (level, camera, size, VPLs, mode, GPU ms
# of the frame, of its indirect pass; wall ms where the adapter's timestamps are not used).
# LEVEL: e2m3, sponza (default both), pillared (builtin:pillared-hall, camera side-room), ajar
# (builtin:ajar-door, camera main). Modes: none, direct-only, gates (the default: the balanced
# setting, the voxel walk with the closed voxels' triangles, the tent blur, the dark pixels'
# walks, the near field and the ratio estimator; the walks' roulette auto), gates-one-pass (the
# default with its tent in one pass, as before its two), gates-no-ratio (the default without
# the ratio estimator), gates-accurate (--accurate), gates-fast (--fast: closed
# voxels passed on their planes, the box blur; the default before the balanced setting), and on
# the fast setting, as they were measured before it: gates-blocking (--no-closed-voxel-planes:
# every closed voxel blocks), gates-rr0, gates-rr05 and gates-rr10 (the roulette off, S = 0.05
# and 0.1), gates-triangles, gates-portal, gates-disk, gates-i4, gates-i4-rr0 and val-hard-i4
# (4 × 4 interleaving; rr0: every VPL walked), gates-starved48, gates-starved64 (--starved-taps
# 48, 64), gates-filled (--blur-fill), gates-tri-starved64 (the triangles and 64 starved taps);
# val-hard, val-cssm, per-vpl-shadow-maps. In the
# environment: RUNS="SIZE:COUNTS ..." (default "512x512:4096,1024,16384 1280x720:4096"), MODES
# (of those, default all but the 4 × 4 and roulette ones), LIMIT (seconds a render may take,
# default 60). A render that fails or runs past LIMIT is written as such in the table. Needs
# ../shared/scenes beside the repository.
set -uo pipefail
if [ $# -lt 2 ]; then
    sed -n '2,/^set /p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'
    exit 2
fi
bin=$1 out=$2
shift 2
levels=${*:-e2m3 sponza}
runs=${RUNS:-512x512:4096,1024,16384 1280x720:4096}
modes=${MODES:-none direct-only gates gates-fast gates-triangles gates-portal gates-disk val-hard val-cssm per-vpl-shadow-maps}
limit=${LIMIT:-60}
mkdir -p "$out"
log="$out/log.txt" table="$out/table.md"
[ -f "$table" ] || printf '| level | camera | size | VPLs | mode | frame (GPU ms) | indirect (GPU ms) |\n|---|---|---|---|---|---|---|\n' >"$table"

args_of() { # LABEL -> render arguments
    case $1 in
    gates-fast) echo "--mode gates --fast" ;;
    gates-accurate) echo "--mode gates --accurate" ;;
    gates-no-ratio) echo "--mode gates --no-ratio" ;;
    gates-one-pass) echo "--mode gates --blur-tent-one-pass" ;;
    gates-triangles) echo "--mode gates --fast --closed-voxel-triangles" ;;
    gates-blocking) echo "--mode gates --fast --no-closed-voxel-planes" ;;
    gates-portal) echo "--mode gates --fast --gate-shape portal" ;;
    gates-disk) echo "--mode gates --fast --gate-shape disk" ;;
    gates-i4) echo "--mode gates --fast --interleave 4" ;;
    gates-i4-rr0) echo "--mode gates --fast --interleave 4 --walk-roulette 0" ;;
    gates-rr0) echo "--mode gates --fast --walk-roulette 0" ;;
    gates-rr05) echo "--mode gates --fast --walk-roulette 0.05" ;;
    gates-rr10) echo "--mode gates --fast --walk-roulette 0.1" ;;
    val-hard-i4) echo "--mode val-hard --interleave 4" ;;
    gates-starved48) echo "--mode gates --fast --starved-taps 48" ;;
    gates-starved64) echo "--mode gates --fast --starved-taps 64" ;;
    gates-filled) echo "--mode gates --fast --blur-fill" ;;
    gates-tri-starved64) echo "--mode gates --fast --closed-voxel-triangles --starved-taps 64" ;;
    *) echo "--mode $1" ;;
    esac
}

scene_of() { # LEVEL -> scene camera
    case $1 in
    e2m3) echo "scenes/shared/librequake-e2m3.toml hall" ;;
    sponza) echo "scenes/shared/crytek-sponza.toml gallery" ;;
    pillared) echo "builtin:pillared-hall side-room" ;;
    ajar) echo "builtin:ajar-door main" ;;
    *) echo "unknown level $1" >&2 && exit 2 ;;
    esac
}

for level in $levels; do
    read -r scene _ <<<"$(scene_of "$level")" || exit 2
    [ -f "$out/$level.vgate" ] ||
        "$bin" bake "$scene" --resolution 256 -o "$out/$level.vgate" >>"$log" 2>&1 || exit 1
done
# The first run's first count on every level before the rest, so that a stopped sweep has it.
for run in $runs; do
    size=${run%%:*} counts=${run#*:}
    for n in ${counts//,/ }; do
        for level in $levels; do
            read -r scene camera <<<"$(scene_of "$level")"
            for mode in $modes; do
                echo "== $level $camera $size $n $mode" >>"$log"
                # shellcheck disable=SC2046
                res=$(timeout "$limit" "$bin" render "$scene" --camera "$camera" \
                    --level "$out/$level.vgate" --size "$size" --vpls "$n" --warmup 1 \
                    --out "$out/frame.exr" $(args_of "$mode") 2>&1)
                rc=$?
                echo "$res" >>"$log"
                # GPU ms, or the pass's wall ms where the report has no GPU time (lavapipe).
                frame=$(echo "$res" | awk '$1 == "frame" { print ($2 == "-" ? $3 " (wall)" : $2) }')
                # The indirect pass alone (not the starved pixels' second pass, in the frame's).
                ind=$(echo "$res" | awk '$1 == "indirect" && $2 == "lighting" { print ($(NF - 1) == "-" ? $NF : $(NF - 1)) }')
                [ $rc -eq 124 ] && frame="over ${limit} s"
                [ $rc -ne 0 ] && [ $rc -ne 124 ] && frame="failed ($rc)"
                echo "| $level | $camera | $size | $n | $mode | ${frame:-?} | ${ind:--} |" |
                    tee -a "$table"
            done
        done
    done
done
rm -f "$out/frame.exr"
