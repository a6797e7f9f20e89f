#!/usr/bin/env bash
# What ships beside the binaries stays true to them (issue 23, item 7): `--version` on cosmicd
# and cosmicctl prints the project's version; the bash completion offers exactly the commands
# `cosmicctl --help` lists and, per command, exactly the options `cosmicctl COMMAND --help` lists
# (run through the completion function itself, as bash would); the manual pages are clean troff
# (no groff warning) and describe every command and every option the binaries' --help lists.
#
# Usage: man_completion_test.sh COSMICCTL COSMICD SOURCE_DIR VERSION
set -u
CTL=${1:?cosmicctl} DAEMON=${2:?cosmicd} SRC=${3:?source dir} VERSION=${4:?project version}
COMPLETION=$SRC/daemon/cosmicctl/cosmicctl.bash
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
FAILURES=0
fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}
command -v groff >/dev/null || { echo "SKIP: no groff (scripts/setup installs groff-base)"; exit 77; }

# --- --version ---------------------------------------------------------------------------------
for binary in "$CTL" "$DAEMON"; do
  name=$(basename "$binary")
  out=$(timeout 10 "$binary" --version 2>"$WORK/version.err")
  code=$?
  [ "$code" -eq 0 ] || fail "$name --version exited $code: $(cat "$WORK/version.err")"
  [ "$out" = "$name $VERSION" ] || fail "$name --version printed '$out', expected '$name $VERSION'"
done

# --- what --help lists -------------------------------------------------------------------------
# long_options HELP_TEXT: the --options of the Options: section, one a line, sorted.
long_options() {
  sed -n '/^Options:/,/^[A-Z][a-z]*:/p' | sed -n 's/^  \(-[^ ]*\).*/\1/p' | tr ',' '\n' | grep '^--' | sort -u
}
"$CTL" --help >"$WORK/help" 2>&1 || fail "cosmicctl --help exited $?"
mapfile -t commands < <(sed -n '/^Subcommands:/,$p' "$WORK/help" | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p' | sort -u)
[ "${#commands[@]}" -ge 10 ] || fail "found only ${#commands[@]} commands in cosmicctl --help: ${commands[*]}"
long_options <"$WORK/help" >"$WORK/global.options"
grep -qx -- --version "$WORK/global.options" || fail "cosmicctl --help does not list --version"
for c in "${commands[@]}"; do
  "$CTL" "$c" --help >"$WORK/help.$c" 2>&1 || fail "cosmicctl $c --help exited $?"
  long_options <"$WORK/help.$c" >"$WORK/$c.options"
done
"$DAEMON" --help >"$WORK/help.cosmicd" 2>&1 || fail "cosmicd --help exited $?"
long_options <"$WORK/help.cosmicd" >"$WORK/cosmicd.options"
grep -qx -- --version "$WORK/cosmicd.options" || fail "cosmicd --help does not list --version"

# --- bash completion ---------------------------------------------------------------------------
# complete WORDS...: what the completion offers for the last word (one a line, sorted).
complete_words() {
  bash --norc --noprofile -c '
    source "$1" || exit 1
    shift
    COMP_WORDS=("$@")
    COMP_CWORD=$(($# - 1))
    COMP_LINE="$*"
    _cosmicctl cosmicctl "${COMP_WORDS[COMP_CWORD]}" "${COMP_WORDS[COMP_CWORD - 1]}"
    printf "%s\n" "${COMPREPLY[@]}"' complete "$COMPLETION" "$@" | sed '/^$/d' | sort -u
}
# same_set WHAT EXPECTED_FILE OFFERED_FILE
same_set() {
  local missing extra
  missing=$(comm -23 "$2" "$3" | tr '\n' ' ')
  extra=$(comm -13 "$2" "$3" | tr '\n' ' ')
  [ -z "$missing" ] || fail "$1: --help lists, the completion does not offer: $missing"
  [ -z "$extra" ] || fail "$1: the completion offers what --help does not list: $extra"
}
printf '%s\n' "${commands[@]}" >"$WORK/commands"
complete_words cosmicctl "" >"$WORK/offered.commands"
same_set "commands" "$WORK/commands" "$WORK/offered.commands"
complete_words cosmicctl -- >"$WORK/offered.global"
same_set "options before a command" "$WORK/global.options" "$WORK/offered.global"
for c in "${commands[@]}"; do
  # After a command: its own options and the global ones cosmicctl accepts there (fallthrough),
  # except --version, which only the bare cosmicctl takes.
  grep -vx -- --version "$WORK/global.options" | sort -u - "$WORK/$c.options" >"$WORK/$c.expected"
  complete_words cosmicctl "$c" -- >"$WORK/$c.offered"
  same_set "cosmicctl $c" "$WORK/$c.expected" "$WORK/$c.offered"
done
complete_words cosmicctl diagram f.yaml --format "" | tr '\n' ' ' | grep -qx "dot svg " || fail "diagram --format does not offer dot and svg"
complete_words cosmicctl gen "$SRC/config/robot.yaml" --component "" >"$WORK/components"
grep -qx speed_controller "$WORK/components" || fail "gen --component does not offer robot.yaml's speed_controller: $(tr '\n' ' ' <"$WORK/components")"
mkdir -p "$WORK/files/sub" && touch "$WORK/files/a.yaml" "$WORK/files/b.txt"
(cd "$WORK/files" && complete_words cosmicctl check "") | tr '\n' ' ' | grep -qx "a.yaml sub " ||
  fail "check FILE does not offer exactly the YAML files and directories"

# --- manual pages ------------------------------------------------------------------------------
# render PAGE: plain text, one paragraph a line (no hyphenation, no line breaks inside words).
render() { groff -man -Tascii -rLL=2000n -rHY=0 -P-cbou -ww "$1" 2>"$WORK/groff.err"; }
for page in "$SRC/docs/man/cosmicd.8" "$SRC/docs/man/cosmicctl.1"; do
  render "$page" >"$WORK/$(basename "$page").txt"
  [ -s "$WORK/groff.err" ] && fail "groff warns about $(basename "$page"): $(cat "$WORK/groff.err")"
done
for c in "${commands[@]}"; do
  grep -qE "^ {7}$c( |\$)" "$WORK/cosmicctl.1.txt" || fail "cosmicctl(1) describes no command $c"
  while read -r option; do
    grep -qF -- "$option" "$WORK/cosmicctl.1.txt" || fail "cosmicctl(1) does not mention $option of $c"
  done <"$WORK/$c.options"
done
while read -r option; do
  grep -qF -- "$option" "$WORK/cosmicctl.1.txt" || fail "cosmicctl(1) does not mention the global option $option"
done <"$WORK/global.options"
while read -r option; do
  grep -qE -- "^ {7}(-[a-z], )?$option( |\$)" "$WORK/cosmicd.8.txt" || fail "cosmicd(8) describes no option $option"
done <"$WORK/cosmicd.options"

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed (${#commands[@]} commands)"
