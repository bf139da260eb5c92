#!/usr/bin/env bash
# The README's run command: installs what is missing, builds the release preset and renders the
# default scene (scenes/room.glb, the Scene6-like room) with the cycle model at the prototype
# configuration. It prints where the image and the report are, and the Table 4 comparison.
# Extra arguments go to `saarcor render` (e.g. --res 128x96, --model fp24, --set threads=32).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target saarcor
exec build/bin/saarcor render scenes/room.glb --model cycle --out out/room \
  --report out/room.json "$@"
