#!/usr/bin/env bash
# The README's test command: installs what is missing, then builds and runs every test in the
# release preset and in the ASan+UBSan preset (warnings are errors in both).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
for preset in release asan; do
  echo "== preset ${preset}"
  cmake --preset "${preset}" >/dev/null
  cmake --build --preset "${preset}"
  ctest --preset "${preset}"
done
# The libFuzzer harnesses (clang, docs/fuzzing.md): built alone in build-fuzz, each run 30 s on
# its seeds (label fuzz; `ctest --preset fuzz-deep` runs a million executions each).
echo "== preset fuzz"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
ctest --preset fuzz
