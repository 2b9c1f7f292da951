#!/usr/bin/env bash
# Reproduces form_factor_accuracy.csv and form_factor_accuracy.png beside this script.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/../.."
"$root/scripts/build.sh" >&2
"$root/build/examples/form_factor_accuracy" "$here/form_factor_accuracy.csv"
/usr/bin/python3 "$here/plot.py" "$here/form_factor_accuracy.csv" "$here/form_factor_accuracy.png"
echo "wrote $here/form_factor_accuracy.csv and .png"
