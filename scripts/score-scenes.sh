#!/usr/bin/env bash
# Scores a setting on the scenes with path-traced references (issue 34's set): the Cornell box,
# the study, the corridor and the rooms of 20 and 150 boxes, at 192 class-balanced probes each.
# Prints, per scene and seed, point data RMS / worst probe, penumbra and contact RMS, cell
# values RMS, elements and compare's seconds; the CSVs stay in OUT/SCENE_sSEED/.
#
#   scripts/score-scenes.sh [--out DIR] [--seeds "1 2"] [--scenes "cornell study"] -- COMPARE FLAGS
#
# The compare flags choose the setting, e.g. `--methods patches --patch-counts 2000
# --display-tolerances 0.02` (the default) or `--methods adaptive --link-epsilons 0.1`.
# Without them, the default. Needs a built build/app/bounce (scripts/build.sh bounce).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bounce="${BOUNCE:-$here/build/app/bounce}"
out=score
seeds="1"
scenes="cornell study corridor r20"
while [[ $# -gt 0 ]]; do
    case "$1" in
    --out) out="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --) shift; break ;;
    *) echo "score-scenes.sh: unknown argument '$1' (flags for compare go after --)" >&2; exit 2 ;;
    esac
done
flags=("$@")
[[ ${#flags[@]} -gt 0 ]] || flags=(--methods patches --patch-counts 2000 --display-tolerances 0.02)
mkdir -p "$out"
rooms="$here/docs/measurements/data/open_parts"

scene_of() {
    case "$1" in
    cornell) echo cornell ;;
    study) echo "$here/examples/scenes/study.json" ;;
    corridor) echo "$here/examples/scenes/corridor.obj" ;;
    r20 | r150)
        local n=${1#r} seed=1
        [[ $1 == r150 ]] && seed=2
        [[ -f "$out/$1.json" ]] || /usr/bin/python3 "$rooms/random_boxes_room.py" "$n" "$seed" "$out/$1.json"
        echo "$out/$1.json" ;;
    *) echo "score-scenes.sh: unknown scene '$1'" >&2; exit 2 ;;
    esac
}
reference_of() {
    case "$1" in
    cornell | study | corridor) echo "$here/examples/reference/$1_classes_192.csv" ;;
    r20 | r150) echo "$rooms/$1_ref.csv" ;;
    esac
}

printf '%-9s %4s %-34s %8s %7s %7s %8s %8s %7s %7s\n' scene seed setting elements seconds "rms%" "worst%" \
    "penum%" "cont%" "cells%"
for scene in $scenes; do
    for seed in $seeds; do
        dir="$out/${scene}_s$seed"
        "$bounce" compare "$(scene_of "$scene")" --meshes "${flags[@]}" --reference-level 0 \
            --reference "$(reference_of "$scene")" --seed "$seed" --out "$dir" --quiet >"$dir.log" 2>&1 ||
            { echo "score-scenes.sh: compare failed on $scene (log: $dir.log)" >&2; exit 1; }
        /usr/bin/python3 - "$dir/meshes.csv" "$scene" "$seed" <<'EOF'
import csv, sys
path, scene, seed = sys.argv[1:]
pct = lambda v: f"{100 * float(v):.2f}" if v else "-"
for r in csv.DictReader(open(path)):
    print(f"{scene:<9} {seed:>4} {r['method'] + ' ' + r['setting']:<34.34} {r['elements']:>8} "
          f"{float(r['seconds']):7.2f} {pct(r['probe_rms_smooth']):>7} {pct(r['probe_max_smooth']):>8} "
          f"{pct(r['probe_rms_smooth_penumbra']):>8} {pct(r['probe_rms_smooth_contact']):>7} "
          f"{pct(r['probe_rms_patch']):>7}")
EOF
    done
done
