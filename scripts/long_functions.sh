#!/usr/bin/env bash
# Lists the functions longer than a limit (default 120 lines) in src/ and apps/, longest first;
# exits 1 when there is any. The count runs from the line that opens the function's body to the
# line that closes it, lambdas included. A heuristic for this code base's clang-format layout
# (bodies open at the end of the signature, namespaces and classes are not functions).
#   scripts/long_functions.sh [LIMIT] [PATHS...]
set -euo pipefail
cd "$(dirname "$0")/.."
limit="${1:-120}"
shift || true
paths=("$@")
[ ${#paths[@]} -gt 0 ] || paths=(src apps)
find "${paths[@]}" \( -name '*.cc' -o -name '*.h' \) ! -name '*_test.cc' -print0 | sort -z |
  xargs -0 awk -v limit="$limit" '
    FNR == 1 { depth = 0; open_fn = 0; in_comment = 0; sig = "" }
    {
      line = $0
      # Strip comments, strings and character literals, roughly.
      if (in_comment) { if (sub(/.*\*\//, "", line)) in_comment = 0; else next }
      gsub(/\/\*[^*]*\*\//, "", line)
      if (match(line, /\/\*/)) { line = substr(line, 1, RSTART - 1); in_comment = 1 }
      sub(/\/\/.*/, "", line)
      gsub(/\\./, "", line)
      gsub(/"[^"]*"/, "\"\"", line)
      gsub(/'"'"'[^'"'"']*'"'"'/, "0", line)
      if (line ~ /^[ \t]*#/) next
      if (line ~ /^[A-Za-z_].*\(/ || line ~ /^[A-Za-z_].*::/) sig = $0 " @" FNR
      n = length(line)
      for (i = 1; i <= n; i++) {
        c = substr(line, i, 1)
        if (c == "{") {
          depth++
          kind[depth] = "other"
          if (line ~ /^(namespace|extern)/ || line ~ /^[ \t]*(class|struct|union|enum)[ \t]/ ||
              line ~ /^(class|struct|union|enum)[ \t]/)
            kind[depth] = "scope"
          else if (open_fn == 0 && all_scopes(depth - 1) && line !~ /=[ \t]*\{/ && sig != "") {
            kind[depth] = "function"; start[depth] = FNR; name[depth] = sig; open_fn = 1
          }
        } else if (c == "}") {
          if (kind[depth] == "function") {
            len = FNR - start[depth] + 1
            if (len > limit) printf "%5d  %s:%s\n", len, FILENAME, name[depth]
            open_fn = 0
          }
          depth--
        }
      }
    }
    function all_scopes(d,   k) { for (k = 1; k <= d; k++) if (kind[k] != "scope") return 0; return 1 }
  ' | sort -rn | { out=$(cat); [ -z "$out" ] && exit 0; echo "$out"; exit 1; }
