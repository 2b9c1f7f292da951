#!/usr/bin/env bash
# Regenerates the README's pictures of the default Cornell box: the rendered box
# (cornell.png) and the same .vtu coloured by luminance with patch edges (cornell_luminance.png).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bounce="$here/../../scripts/bounce.sh"
"$bounce" solve -q -o "$here/cornell.vtu"
"$bounce" render "$here/cornell.vtu" -o "$here/cornell.png" --smooth --size 600x600
"$bounce" render "$here/cornell.vtu" -o "$here/cornell_luminance.png" --luminance --edges --size 600x600
rm -f "$here/cornell.vtu"
echo "wrote $here/cornell.png and cornell_luminance.png"
# Issue 16 before and after, smooth point data with the patch edges: every surface meshed whole
# and the point data averaged from the patches (--no-contact-cuts --gather none), against the
# default run (contact cuts, point data gathered at the vertices).
"$bounce" solve -q --no-contact-cuts --gather none -o "$here/cornell_before_16.vtu"
"$bounce" render "$here/cornell_before_16.vtu" -o "$here/cornell_before_16.png" --smooth --edges --size 600x600
"$bounce" solve -q -o "$here/cornell_after_16.vtu"
"$bounce" render "$here/cornell_after_16.vtu" -o "$here/cornell_after_16.png" --smooth --edges --size 600x600
rm -f "$here/cornell_before_16.vtu" "$here/cornell_after_16.vtu"
echo "wrote $here/cornell_before_16.png and cornell_after_16.png"
# Adaptive subdivision with the element edges drawn: fine at shadow edges, coarse on open walls.
"$bounce" solve -q --adaptive -o "$here/cornell_adaptive.vtu" --png "$here/cornell_adaptive.png" --edges --size 600x600
rm -f "$here/cornell_adaptive.vtu"
echo "wrote $here/cornell_adaptive.png"
# ParaView's own screenshot of the file, through the script solve --paraview writes
# (PVBATCH: a pvbatch command, e.g. ../shared/tools/paraview.sh; skipped when unset).
if [[ -n ${PVBATCH:-} ]]; then
  "$bounce" solve -q --paraview -o "$here/cornell.vtu"
  "$PVBATCH" "$here/cornell_paraview.py" --screenshot "$here/cornell_paraview.png"
  rm -f "$here/cornell.vtu" "$here/cornell_paraview.py"
  echo "wrote $here/cornell_paraview.png"
fi
# The two-pass picture of cornell-spheres, the path tracer's at the same time and the 2048-path
# reference, side by side (compare --picture at 512 x 512; about 10 minutes on 2 cores, most of it
# the reference), and the picture alone.
"$bounce" compare --picture -q --reference-paths 2048 --out "$here/compare_picture"
cp "$here/compare_picture/picture_side_by_side.png" "$here/cornell_spheres_compare.png"
rm -rf "$here/compare_picture"
"$bounce" render cornell-spheres -q -o "$here/cornell_spheres.png" --size 512x512
echo "wrote $here/cornell_spheres_compare.png and cornell_spheres.png"
