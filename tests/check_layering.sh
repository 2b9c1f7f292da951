#!/usr/bin/env bash
# Fails when a folder includes from a folder further along the data flow
# (mesh -> solver -> viewer -> app), or when solver/ or mesh/ mention VTK.
set -u
root="$1"
bad=0
check() {  # folder, forbidden include pattern
  if grep -rnE "#include [<\"]($2)" "$root/$1" --include='*.h' --include='*.cpp'; then
    echo "layering: $1/ must not include $2"; bad=1
  fi
}
check mesh   'solver/|viewer/|app/|vtk'
check solver 'viewer/|app/|vtk'
check viewer 'app/'
[ $bad -eq 0 ] && echo "layering ok"
exit $bad
