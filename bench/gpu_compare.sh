#!/usr/bin/env bash
# The README's GPU figures: `visgate compare` at a user's size (1280×720, 1,024 and 4,096 light
# paths, the reference at 1 sample a pixel) on the shared levels and on the built-in scenes that
# reproduce real levels' failures, and a frame-time sweep of every mode up to 16,384 paths.
#
#   bench/gpu_compare.sh VISGATE OUT SET...
#
# VISGATE: the visgate binary (a release build). OUT: a folder; each set writes OUT/NAME/ (a
# compare report; its renders in OUT/NAME/renders, kept so that a stopped run resumes) or
# OUT/sweep-NAME.txt. SET: sponza, e2m3, ajar-door, pillared-hall, sweep-sponza, sweep-e2m3,
# walk-check. SIZE=WxH in the environment sets another size. Needs ../shared/scenes beside
# the repository (see README), as the tests do.
set -euo pipefail
if [ $# -lt 3 ]; then
    sed -n '2,/^set /p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'
    exit 2
fi
bin=$1 out=$2
shift 2
mkdir -p "$out"
size=${SIZE:-1280x720}

compare() { # NAME SCENE BUDGET_MS EXTRA...
    local name=$1 scene=$2 budget=$3
    shift 3
    "$bin" compare "$scene" --vpls 1024,4096 --size $size --spp 1 --budget-ms "$budget" \
        --out "$out/$name" "$@"
}

# Every mode at 1,024 / 4,096 / 16,384 paths, the frame after one warm-up, GPU pass times.
sweep() { # NAME SCENE CAMERA LEVEL
    local name=$1 scene=$2 camera=$3 level=$4 log="$out/sweep-$1.txt"
    : >"$log"
    for n in 1024 4096 16384; do
        for mode in none direct-only gates gates-per-pixel val-hard val-cssm per-vpl-shadow-maps; do
            [ "$mode" = gates-per-pixel ] && [ "$n" -gt 4096 ] && continue
            echo "== $name $camera $mode $n" | tee -a "$log"
            "$bin" render "$scene" --camera "$camera" --mode "$mode" --vpls "$n" --size $size \
                --level "$level" --warmup 1 --out "$out/sweep.exr" 2>&1 | tee -a "$log"
        done
    done
    rm -f "$out/sweep.exr"
}

for set in "$@"; do
    case $set in
    sponza) compare crytek-sponza scenes/shared/crytek-sponza.toml 33 --bake-resolution 256 ;;
    e2m3) compare librequake-e2m3 scenes/shared/librequake-e2m3.toml 16.7 --bake-resolution 256 ;;
    ajar-door) compare ajar-door builtin:ajar-door 16.7 --bake-resolution 128 ;;
    pillared-hall) compare pillared-hall builtin:pillared-hall 16.7 --bake-resolution 128 ;;
    sweep-sponza | sweep-e2m3)
        scene=scenes/shared/crytek-sponza.toml camera=gallery
        [ "$set" = sweep-e2m3 ] && scene=scenes/shared/librequake-e2m3.toml camera=hall
        "$bin" bake "$scene" --resolution 256 -o "$out/$set.vgate"
        sweep "${set#sweep-}" "$scene" "$camera" "$out/$set.vgate"
        rm -f "$out/$set.vgate"
        ;;
    walk-check)
        # The portal walk per pixel against its CPU twin (issue 19): the indirect energy of
        # gates-per-pixel over gates --cpu's at growing VPL counts, ajar-door's door camera.
        lv="$out/ajar.vgate" w="$out/w"
        "$bin" bake builtin:ajar-door --resolution 128 -o "$lv" >/dev/null
        r() { "$bin" render builtin:ajar-door --camera door --size 32x24 --level "$lv" "$@" >/dev/null; }
        r --mode direct-only --out "$w-d.exr"
        # The CPU twins at the pixel centre, as the GPU (their default is 4 jittered samples,
        # which differ at thin features, where portals cut the light sharply).
        r --mode direct-only --cpu --spp 1 --out "$w-dc.exr"
        for n in 128 512 1024 2048 4096; do
            # The CPU twin of the gates walks every VPL at every pixel, as gates-per-pixel.
            r --mode gates-per-pixel --vpls $n --out "$w-g.exr"
            r --mode gates --vpls $n --cpu --spp 1 --out "$w-c.exr"
            echo "$n: $("$bin" diff "$w-g.exr" "$w-c.exr" --direct "$w-dc.exr" \
                --image-direct "$w-d.exr" | grep 'indirect energy')"
        done
        rm -f "$lv" "$w"-*.exr
        ;;
    *)
        echo "unknown set $set" >&2
        exit 2
        ;;
    esac
done
