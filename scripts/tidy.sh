#!/usr/bin/env bash
# clang-tidy-14 with the repository's .clang-tidy over the project's own sources (planner/,
# control/, vo/, harness/; their headers through HeaderFilterRegex). Prints the findings and exits 1
# when there is any. CI runs it.
#
#   scripts/tidy.sh            every source, as the unity build's batches: build-tidy-unity/ (Clang
#                              with the sanitizer build's flags, CMake joining each library's sources
#                              8 at a time; configured here when missing, nothing is built). The
#                              headers are parsed once per 8 sources, not per source: 3.6 minutes on
#                              2 cores where one file at a time took 10-12. The sources included by
#                              a batch are checked as its headers are (their findings name them).
#                              Every source still compiles on its own in the normal build (build/).
#   scripts/tidy.sh FILE...    the files named, one at a time: build-tidy/'s per-file commands
#                              (configured here when missing or without a file named), as before a
#                              commit; a file that is no source of the build is an error.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
configure() {  # configure DIR [cmake args...]
  local dir=$1
  shift
  [[ -f "$dir/compile_commands.json" ]] && return 0
  CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" \
    -DTGNAV_SANITIZE=address,undefined -DTGNAV_FUZZ=ON -DTGNAV_BUILD_TESTS=ON "$@" >/dev/null
}
args=()
if [[ $# -gt 0 ]]; then
  dir="$root/build-tidy"
  configure "$dir"
  files=()
  for f in "$@"; do files+=("$(realpath "$f")"); done
  # A file added since build-tidy/ was configured is not in its commands: configure again, and
  # name any file still missing (run-clang-tidy would skip it without a word).
  missing() { for f in "${files[@]}"; do grep -q -F "\"file\": \"$f\"" "$dir/compile_commands.json" || echo "$f"; done; }
  if [[ -n "$(missing)" ]]; then
    rm -f "$dir/compile_commands.json"
    configure "$dir"
  fi
  if [[ -n "$(missing)" ]]; then
    echo "tidy.sh: not a source of the build (no compile command in $dir): $(missing | paste -sd ' ')" >&2
    exit 2
  fi
  regex=$(printf '%s|' "${files[@]}")
  regex="^(${regex%|})$"
else
  dir="$root/build-tidy-unity"
  configure "$dir" -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8
  # The batches, and any source CMake left out of them.
  regex="^($dir/(planner|control|vo|harness)/.*/Unity/unity_[0-9]+_cxx\\.cxx|$root/(planner|control|vo|harness)/.*\\.cpp)$"
  # A batch includes its sources: they are checked like headers, and including a .cpp is the
  # point of a batch, not a finding.
  args=(-header-filter='(planner|control|vo|harness)/.*\.(h|cpp)$' -checks=-bugprone-suspicious-include)
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run-clang-tidy-14 -p "$dir" -j "$(nproc)" -quiet "${args[@]}" "$regex" 2>&1 | sed 's/\x1b\[[0-9;]*m//g' >"$log" || true
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
n=$(grep -c -E '^clang-tidy-14 ' "$log" || true)
echo "tidy.sh: no findings ($n files)"
