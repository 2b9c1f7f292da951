#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, runs `bounce` with the given arguments.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/build.sh" >&2
exec "$here/build/app/bounce" "$@"
