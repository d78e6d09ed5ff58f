#!/usr/bin/env bash
# clang-tidy-14 with the repository's .clang-tidy over the project's own sources (planner/,
# control/, vo/, harness/; their headers through HeaderFilterRegex), using the compile commands of
# build-tidy/ (Clang with the sanitizer build's flags, but one command per source file, where
# build-sanitize/ is a unity build; configured here when missing, nothing is built). Prints the
# findings and exits 1 when there is any. CI runs it (about 10 minutes on 2 cores).
#
#   scripts/tidy.sh [FILE...]     all sources, or the files named
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dir="$root/build-tidy"
if [[ ! -f "$dir/compile_commands.json" ]]; then
  CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" \
    -DTGNAV_SANITIZE=address,undefined -DTGNAV_FUZZ=ON -DTGNAV_BUILD_TESTS=ON >/dev/null
fi
if [[ $# -gt 0 ]]; then
  files=()
  for f in "$@"; do files+=("$(realpath "$f")"); done
  regex=$(printf '%s|' "${files[@]}")
  regex="^(${regex%|})$"
else
  regex="^$root/(planner|control|vo|harness)/.*\\.cpp$"
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run-clang-tidy-14 -p "$dir" -j "$(nproc)" -quiet "$regex" 2>&1 | sed 's/\x1b\[[0-9;]*m//g' >"$log" || true
# One line per finding (a header's finding is reported once, however many files include it).
findings=$(grep -E "^$root/.*: (warning|error): " "$log" | sort -u || true)
if [[ -n "$findings" ]]; then
  echo "$findings"
  echo "tidy.sh: $(echo "$findings" | wc -l) findings" >&2
  exit 1
fi
if grep -q -E "error: |Error while processing" "$log"; then
  grep -E "error: |Error while processing" "$log" | head -20 >&2
  echo "tidy.sh: clang-tidy failed on some files" >&2
  exit 1
fi
echo "tidy.sh: no findings"
