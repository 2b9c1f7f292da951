#!/usr/bin/env bash
# Fails when a folder includes from a folder further along the data flow
# (mesh -> solver -> viewer -> app and python, the two front ends, which never include each
# other), when a mesh room includes from a room further along (scene -> geometry -> readers,
# meshing), when a solver room includes from a room further along
# (optics -> visibility -> form_factors -> linear -> refinement -> gather -> reference -> two_pass
# -> pipeline), or when solver/ or mesh/ mention VTK.
set -u
root="$1"
bad=0
check() {  # folder, forbidden include pattern
  if grep -rnE "#include [<\"]($2)" "$root/$1" --include='*.h' --include='*.cpp'; then
    echo "layering: $1/ must not include $2"; bad=1
  fi
}
check mesh   'solver/|viewer/|app/|python/|vtk'
check solver 'viewer/|app/|python/|vtk'
check viewer 'app/|python/'
check app    'python/'
check python 'app/'

# The mesh rooms, lowest first; readers and meshing never include each other.
mesh_rooms=(scene geometry readers meshing)
for ((i = 0; i < ${#mesh_rooms[@]}; i++)); do
  higher=("${mesh_rooms[@]:i+1}")
  ((${#higher[@]})) || continue
  check "mesh/${mesh_rooms[i]}" "mesh/($(IFS='|'; echo "${higher[*]}"))/"
done
check mesh/meshing 'mesh/readers/'
loose_mesh=$(find "$root/mesh" -maxdepth 1 -name '*.h' -o -maxdepth 1 -name '*.cpp')
if [ -n "$loose_mesh" ]; then
  echo "$loose_mesh"; echo "layering: mesh/ sources belong in a room (mesh/<room>/)"; bad=1
fi

# The solver's rooms, lowest first; a new room goes into this list at its place in the flow.
rooms=(optics visibility form_factors linear refinement gather reference two_pass pipeline)
for ((i = 0; i < ${#rooms[@]}; i++)); do
  higher=("${rooms[@]:i+1}")
  ((${#higher[@]})) || continue
  pattern="solver/($(IFS='|'; echo "${higher[*]}"))/"
  check "solver/${rooms[i]}" "$pattern"
done
# Every solver source sits in a room, never loose in solver/ itself.
loose=$(find "$root/solver" -maxdepth 1 -name '*.h' -o -maxdepth 1 -name '*.cpp')
if [ -n "$loose" ]; then
  echo "$loose"; echo "layering: solver/ sources belong in a room (solver/<room>/)"; bad=1
fi
[ $bad -eq 0 ] && echo "layering ok"
exit $bad
