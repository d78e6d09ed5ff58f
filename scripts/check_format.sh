#!/usr/bin/env bash
# Checks that every C++ source of the project is formatted as .clang-format says (clang-format-14,
# Debian 12's). Prints the files that are not and exits 1; `scripts/check_format.sh --fix` formats
# them in place.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
tool=$(command -v clang-format-14 || command -v clang-format || true)
if [ -z "$tool" ]; then
  echo "check_format.sh: clang-format-14 is not installed (scripts/setup.sh installs it)" >&2
  exit 1
fi
mapfile -t files < <(find planner control vo harness tests -name '*.cpp' -o -name '*.h' | sort)
if [ "${1:-}" = "--fix" ]; then
  "$tool" -i "${files[@]}"
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  "$tool" --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]})); then
  printf 'not formatted (scripts/check_format.sh --fix): %s\n' "${bad[@]}"
  exit 1
fi
echo "check_format.sh: ${#files[@]} files formatted"
