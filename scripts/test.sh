#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs every test with CTest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
echo "test: running the tests (ctest -j$(nproc))" >&2
ctest --test-dir "$root/build" --output-on-failure -j"$(nproc)" "$@"
