#!/usr/bin/env bash
# The README's main command: installs what is missing, builds the `bounce` program (only it: not
# the tests, benchmarks or examples), runs it with the given arguments.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/build.sh" bounce >&2
exec "$here/build/app/bounce" "$@"
