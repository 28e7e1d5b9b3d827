#!/usr/bin/env bash
# The house style (.clang-format: Google, 100 columns) on every C++ file of the tree. Exits 1 and
# names each file that is not formatted; `bash scripts/check_format.sh --fix` formats them.
# README command 2 (scripts/test.sh) runs it first.
set -euo pipefail
cd "$(dirname "$0")/.."
FORMAT=${CLANG_FORMAT:-clang-format}
command -v "$FORMAT" >/dev/null || { echo "check_format: $FORMAT not found (scripts/setup.sh --test)" >&2; exit 1; }
mapfile -d '' files < <(find src apps tests fuzz benchmarks \( -name '*.cc' -o -name '*.h' \) -print0 | sort -z)
if [ "${1:-}" = --fix ]; then
  "$FORMAT" -i "${files[@]}"
  echo "check_format: formatted ${#files[@]} files"
  exit 0
fi
# clang-format names each offending line "FILE:LINE:COL: error: code should be clang-formatted".
mapfile -t bad < <(printf '%s\0' "${files[@]}" |
  xargs -0 -P "$(nproc)" -n 16 "$FORMAT" --dry-run -Werror 2>&1 |
  sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
if [ ${#bad[@]} -gt 0 ]; then
  echo "check_format: ${#bad[@]} of ${#files[@]} files are not formatted (.clang-format); run" \
       "bash scripts/check_format.sh --fix:" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted as .clang-format says"
