#!/usr/bin/env bash
# The README's run command: installs what is missing, builds the release preset and runs the main
# job on the default scene. Extra arguments go to `saarcor render`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target saarcor
exec build/bin/saarcor demo "$@"
