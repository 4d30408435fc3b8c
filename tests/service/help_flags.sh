#!/usr/bin/env bash
# Every service's and tool's flags and defaults as users know them: each binary in LIST answers
# --help with every flag LIST records for it, with the same default (a flag may be added, none
# may go or change its default). LIST was made from main's binaries before the flags moved onto
# CLI11 (tests/service/help_flags.tsv: binary, flag, default; <src> for the source tree).
# usage: help_flags.sh BIN_DIR SOURCE_DIR LIST          check
#        help_flags.sh BIN_DIR SOURCE_DIR LIST --write  record what BIN_DIR's binaries say now
set -uo pipefail
bin=${1:?usage: help_flags.sh BIN_DIR SOURCE_DIR LIST [--write]}
src=${2:?usage: help_flags.sh BIN_DIR SOURCE_DIR LIST [--write]}
list=${3:?usage: help_flags.sh BIN_DIR SOURCE_DIR LIST [--write]}
src=$(cd "$src" && pwd)  # absolute, as the binaries were built with it

# "--flag<TAB>default" for each flag of a --help text on stdin. A flag whose name fills the
# column has its help (and default) on the next line.
flags_of() {
  awk '
    /^options:/ { in_options = 1; next }
    !in_options { next }
    /^  --/ { if (flag != "") print_flag(); flag = $1; line = $0; next }
    /^                          / && flag != "" { line = line $0; next }
    END { if (flag != "") print_flag() }
    function print_flag(   d) {
      d = ""
      if (match(line, /\[[^]]*\]$/)) d = substr(line, RSTART + 1, RLENGTH - 2)
      printf "%s\t%s\n", flag, d
      flag = ""
    }'
}

help_of() { timeout 10 "$bin/$1" --help </dev/null 2>/dev/null; }
# The source tree's path (a literal, not a pattern) written as <src>: the list is machine-independent.
without_src() { local text; text=$(cat); printf '%s\n' "${text//"$src"/<src>}"; }

if [ "${4:-}" = --write ]; then
  for b in "$bin"/nudge-*; do
    name=$(basename "$b")
    text=$(help_of "$name") || continue
    [[ $text == usage:* ]] || continue
    printf '%s\n' "$text" | flags_of | without_src | sed "s|^|$name\t|"
  done >"$list"
  echo "wrote $(wc -l <"$list") flags of $(cut -f1 "$list" | sort -u | wc -l) binaries to $list"
  exit 0
fi

failed=0 checked=0 skipped=()
for name in $(cut -f1 "$list" | sort -u); do
  if [ ! -x "$bin/$name" ]; then skipped+=("$name"); continue; fi
  now=$(help_of "$name" | flags_of | without_src)
  while IFS=$'\t' read -r binary flag default; do
    [ "$binary" = "$name" ] || continue
    checked=$((checked + 1))
    current=$(printf '%s\n' "$now" | awk -F'\t' -v f="$flag" '$1 == f { print "found\t" $2; exit }')
    if [ -z "$current" ]; then
      echo "FAILED: $name --help no longer lists $flag" >&2
      failed=1
    elif [ "${current#found	}" != "$default" ]; then
      echo "FAILED: $name $flag: default '${current#found	}', was '$default'" >&2
      failed=1
    fi
  done <"$list"
done
[ ${#skipped[@]} -eq 0 ] || echo "not built here (skipped): ${skipped[*]}"
[ $failed -eq 0 ] || exit 1
echo "PASSED: $checked flags of $(cut -f1 "$list" | sort -u | wc -l) binaries keep their names and defaults"
