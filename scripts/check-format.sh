#!/usr/bin/env bash
# Checks that the C++ files under the folders listed in .clang-format-files follow .clang-format
# (clang-format --dry-run --Werror); exits 1 and shows the first differences when one does not.
#   scripts/check-format.sh             check the listed folders
#   scripts/check-format.sh --fix [P..] reformat the listed folders (or just the paths P) in place
set -euo pipefail
cd "$(dirname "$0")/.."
fix=0
if [ "${1:-}" = "--fix" ]; then fix=1; shift; fi
if (($#)); then
  paths=("$@")
else
  mapfile -t paths < <(sed -e 's/#.*//' -e 's/[[:space:]]*$//' .clang-format-files | grep -v '^$')
fi
mapfile -t files < <(find "${paths[@]}" -type f \( -name '*.h' -o -name '*.cpp' \) | sort)
((${#files[@]})) || { echo "check-format: no C++ files under ${paths[*]}" >&2; exit 1; }
command -v clang-format >/dev/null || { echo "check-format: clang-format is missing (scripts/install-deps.sh)" >&2; exit 1; }
if ((fix)); then
  clang-format -i "${files[@]}"
  echo "formatted ${#files[@]} files"
  exit 0
fi
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
if clang-format --dry-run --Werror "${files[@]}" 2>"$log"; then
  echo "format ok (${#files[@]} files under ${paths[*]})"
else
  head -n 60 "$log" >&2
  echo "check-format: run scripts/check-format.sh --fix to reformat" >&2
  exit 1
fi
