#!/usr/bin/env bash
# What ships beside the binaries stays true to them (issue 23, item 7; cosmic-fmu: issue 38):
# `--version` on cosmicd, cosmicctl and cosmic-fmu prints the project's version; the bash
# completion offers exactly the commands `cosmicctl --help` lists and, per command, exactly the
# options `cosmicctl COMMAND --help` lists, and exactly the options `cosmic-fmu --help` lists, with
# its choices and the fmus: names of the --config file (run through the completion functions
# themselves, as bash would); the manual pages are clean troff (no groff warning) and describe
# every command and every option the binaries' --help lists, and cosmic-fmu(1) gives each option
# the default and the choices its --help shows.
#
# Usage: man_completion_test.sh COSMICCTL COSMICD SOURCE_DIR VERSION COSMIC_FMU
set -u
CTL=${1:?cosmicctl} DAEMON=${2:?cosmicd} SRC=${3:?source dir} VERSION=${4:?project version} FMU=${5:?cosmic-fmu}
COMPLETION=$SRC/daemon/cosmicctl/cosmicctl.bash
FMU_COMPLETION=$SRC/daemon/cosmic-fmu/cosmic-fmu.bash
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
FAILURES=0
fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}
command -v groff >/dev/null || { echo "SKIP: no groff (scripts/setup installs groff-base)"; exit 77; }

# --- --version ---------------------------------------------------------------------------------
for binary in "$CTL" "$DAEMON" "$FMU"; do
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
"$FMU" --help >"$WORK/help.cosmic-fmu" 2>&1 || fail "cosmic-fmu --help exited $?"
long_options <"$WORK/help.cosmic-fmu" >"$WORK/cosmic-fmu.options"
[ "$(wc -l <"$WORK/cosmic-fmu.options")" -ge 10 ] || fail "found only $(wc -l <"$WORK/cosmic-fmu.options") options in cosmic-fmu --help"

# --- bash completion ---------------------------------------------------------------------------
# complete_with FILE FUNCTION WORDS...: what FILE's completion function offers for the last word
# (one a line, sorted); complete_words WORDS... for cosmicctl, complete_fmu WORDS... for cosmic-fmu.
complete_with() {
  bash --norc --noprofile -c '
    source "$1" || exit 1
    function=$2
    shift 2
    COMP_WORDS=("$@")
    COMP_CWORD=$(($# - 1))
    COMP_LINE="$*"
    "$function" "${COMP_WORDS[0]}" "${COMP_WORDS[COMP_CWORD]}" "${COMP_WORDS[COMP_CWORD - 1]}"
    printf "%s\n" "${COMPREPLY[@]}"' complete "$@" | sed '/^$/d' | sort -u
}
complete_words() { complete_with "$COMPLETION" _cosmicctl "$@"; }
complete_fmu() { complete_with "$FMU_COMPLETION" _cosmic_fmu "$@"; }
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

complete_fmu cosmic-fmu -- >"$WORK/offered.cosmic-fmu"
same_set "cosmic-fmu" "$WORK/cosmic-fmu.options" "$WORK/offered.cosmic-fmu"
complete_fmu cosmic-fmu --config f.yaml "" >"$WORK/offered.cosmic-fmu.empty"
same_set "cosmic-fmu (an empty word)" "$WORK/cosmic-fmu.options" "$WORK/offered.cosmic-fmu.empty"
# Choices: those --help shows as {a,b,...} after the option.
for option in --pace --log-level; do
  sed -n "s/^  \(-[a-z],\)\{0,1\}$option [A-Z]*:{\([^}]*\)}.*/\2/p" "$WORK/help.cosmic-fmu" | tr ',' '\n' | sort -u >"$WORK/choices$option"
  [ -s "$WORK/choices$option" ] || fail "cosmic-fmu --help shows no choices of $option"
  complete_fmu cosmic-fmu "$option" "" >"$WORK/offered$option"
  same_set "cosmic-fmu $option" "$WORK/choices$option" "$WORK/offered$option"
done
complete_fmu cosmic-fmu -l "" | tr '\n' ' ' | grep -qx "debug error info notice warning " || fail "cosmic-fmu -l does not offer the log levels"
# --name: the fmus: entries of the --config file, in either YAML style, and nothing of other sections.
cat >"$WORK/fmus.yaml" <<'YAML'
components:
  - name: not_an_fmu
    segment: lan
fmus:
  - name: plant
    fmu: Plant.fmu
    inputs: {drive: drive.value}
  # a comment between entries
  - {name: controller, fmu: SpeedController.fmu, segment: lan}
channels:
  - name: drive
YAML
complete_fmu cosmic-fmu --config "$WORK/fmus.yaml" --name "" | tr '\n' ' ' | grep -qx "controller plant " ||
  fail "cosmic-fmu --name does not offer exactly the fmus: of --config: $(complete_fmu cosmic-fmu --config "$WORK/fmus.yaml" --name "" | tr '\n' ' ')"
complete_fmu cosmic-fmu --pace free -c "$WORK/fmus.yaml" -n c | tr '\n' ' ' | grep -qx "controller " ||
  fail "cosmic-fmu -c FILE -n c does not offer controller"
[ -z "$(complete_fmu cosmic-fmu --name "")" ] || fail "cosmic-fmu --name offers names without a --config"
(cd "$WORK/files" && complete_fmu cosmic-fmu --config "") | tr '\n' ' ' | grep -qx "a.yaml sub " ||
  fail "cosmic-fmu --config does not offer exactly the YAML files and directories"
(cd "$WORK/files" && complete_fmu cosmic-fmu --work-dir "") | tr '\n' ' ' | grep -qx "sub " ||
  fail "cosmic-fmu --work-dir does not offer exactly the directories"

# --- manual pages ------------------------------------------------------------------------------
# render PAGE: plain text, one paragraph a line (no hyphenation, no line breaks inside words).
render() { groff -man -Tascii -rLL=2000n -rHY=0 -P-cbou -ww "$1" 2>"$WORK/groff.err"; }
for page in "$SRC/docs/man/cosmicd.8" "$SRC/docs/man/cosmicctl.1" "$SRC/docs/man/cosmic-fmu.1"; do
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
# cosmic-fmu(1): each option described, with the default (`--option TYPE=DEFAULT` in --help) and
# the choices (`TYPE:{a,b}`) its --help shows, in the option's paragraph (the line after its tag).
while read -r option; do
  paragraph=$(grep -A1 -E -- "^ {7}(-[a-z], )?$option( |\$)" "$WORK/cosmic-fmu.1.txt" | sed -n 2p)
  if [ -z "$paragraph" ]; then
    fail "cosmic-fmu(1) describes no option $option"
    continue
  fi
  spec=$(sed -n "s/^  \(-[a-z],\)\{0,1\}$option \([^ ]*\).*/\2/p" "$WORK/help.cosmic-fmu")
  default=$(sed -n 's/^[^=]*=\(.*\)$/\1/p' <<<"$spec")
  [ -z "$default" ] || grep -qw -- "$default" <<<"$paragraph" ||
    fail "cosmic-fmu(1) does not give $option's default $default: $paragraph"
  for choice in $(sed -n 's/^[^{]*{\([^}]*\)}.*/\1/p' <<<"$spec" | tr ',' ' '); do
    grep -qw -- "$choice" <<<"$paragraph" || fail "cosmic-fmu(1) does not name $option's choice $choice: $paragraph"
  done
done <"$WORK/cosmic-fmu.options"

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed (${#commands[@]} commands)"
