# bash completion for cosmic-fmu (installed as /usr/share/bash-completion/completions/cosmic-fmu).
# The options are those `cosmic-fmu --help` lists: tests/cli/man_completion_test.sh fails when one is
# missing here or no longer exists. Values: --config to YAML files, --name to the names of the
# fmus: section of the --config file on the line (read with sed, as cosmicctl's completion reads
# components:), --pace and --log-level to their choices, --work-dir to directories, --socket and
# --trace to files. Needs nothing from the bash-completion package.

_cosmic_fmu_options="--can-node --config --cpus --help --log-level --name --no-report --pace --priority --ready-timeout --report-interval --socket --steps --trace --version --work-dir"

# The names of the fmus: section of a YAML file (both `- name: x` and `- {name: x, ...}`).
_cosmic_fmu_names() {
  [ -r "$1" ] || return
  sed -n '/^fmus:/,/^[^[:space:]#-]/p' "$1" 2>/dev/null |
    sed -n 's/^[[:space:]]*-[[:space:]]*{\{0,1\}[[:space:]]*name:[[:space:]]*\([^,}[:space:]]*\).*/\1/p'
}

_cosmic_fmu() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
  local config="" i
  for ((i = 1; i < COMP_CWORD; i++)); do
    case ${COMP_WORDS[i]} in
      -c | --config) config=${COMP_WORDS[i + 1]} ;;
    esac
  done
  config=${config/#\~/$HOME}

  case $prev in
    -c | --config)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -X '!*.yaml' -- "$cur"; compgen -f -X '!*.yml' -- "$cur"; compgen -d -- "$cur")
      return ;;
    -n | --name)
      mapfile -t COMPREPLY < <(compgen -W "$(_cosmic_fmu_names "$config")" -- "$cur")
      return ;;
    --pace)
      mapfile -t COMPREPLY < <(compgen -W "realtime free" -- "$cur")
      return ;;
    -l | --log-level)
      mapfile -t COMPREPLY < <(compgen -W "debug info notice warning error" -- "$cur")
      return ;;
    --work-dir)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -d -- "$cur")
      return ;;
    -s | --socket | --trace)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -- "$cur")
      return ;;
    --steps | --report-interval | --ready-timeout | --can-node | --priority | --cpus)
      return ;;
  esac
  mapfile -t COMPREPLY < <(compgen -W "$_cosmic_fmu_options" -- "$cur")
}

complete -F _cosmic_fmu cosmic-fmu
