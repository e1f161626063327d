#!/usr/bin/env bash
# Create or update .venv from training/requirements.txt (only when the requirements changed).
set -euo pipefail
cd "$(dirname "$0")/.."
req=training/requirements.txt
stamp=.venv/.requirements.sha256
want=$(sha256sum "$req" | cut -d' ' -f1)
if [ -x .venv/bin/python ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  exit 0
fi
echo "Setting up the Python environment in .venv (from $req) ..."
python3 -m venv .venv
.venv/bin/pip install --quiet --upgrade pip
.venv/bin/pip install --quiet --progress-bar off -r "$req"
echo "$want" > "$stamp"
