#!/usr/bin/env bash
# Lists the functions longer than a limit (default 120 lines, from the line of the function's
# name, or its first decorator, to its end) in the library, program and module sources, longest
# first; exits 1 when there is one. C++ functions come from Universal Ctags (lambdas count
# within their enclosing function), Python functions from the ast module.
#
#   scripts/check-function-length.sh [LIMIT] [PATH..]    # default: mesh solver viewer app python
set -euo pipefail
cd "$(dirname "$0")/.."
limit=${1:-120}
[[ $# -gt 0 ]] && shift
paths=("$@")
[[ ${#paths[@]} -eq 0 ]] && paths=(mesh solver viewer app python)

command -v ctags >/dev/null || { echo "check-function-length: needs universal-ctags" >&2; exit 2; }

long=$({
    find "${paths[@]}" -name '*.cpp' -o -name '*.h' | sort |
        xargs ctags -f - --languages=C++ --kinds-C++=f --fields=+ne --output-format=u-ctags 2>/dev/null |
        awk -F'\t' '$1 !~ /^__anon/ {
            line = ""; end = "";
            for (i = 4; i <= NF; ++i) {
                if ($i ~ /^line:/) line = substr($i, 6);
                if ($i ~ /^end:/) end = substr($i, 5);
            }
            if (line != "" && end != "") print end - line + 1 "\t" $2 ":" line "\t" $1;
        }'
    find "${paths[@]}" -name '*.py' | sort | python3 -c '
import ast, sys
for path in sys.stdin.read().split():
    tree = ast.parse(open(path).read(), path)
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            print(f"{node.end_lineno - first + 1}\t{path}:{first}\t{node.name}")
'
} | awk -F'\t' -v limit="$limit" '$1 > limit' | sort -t$'\t' -k1,1nr)
[[ -z $long ]] && exit 0
echo "functions over $limit lines (lines, where, name):"
echo "$long"
exit 1
