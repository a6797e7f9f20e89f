# bash completion for cosmicctl (installed as /usr/share/bash-completion/completions/cosmicctl).
# Commands and options are those `cosmicctl --help` and `cosmicctl COMMAND --help` list:
# tests/cli/man_completion_test.sh fails when a command or option is missing here or no longer
# exists (`security` has the subcommand `permissions`, whose options follow it; `record` has start,
# stop, status and info FILE, an MCAP file; `replay` takes FILE, an MCAP file, or stop NAME). Values: FILE
# arguments complete to YAML files, --output to directories, --format and --protection to their
# choices, --sign-with to two files, --component to the components: of the FILE on the line, channel NAMEs (channel,
# unbind, echo) to the channels of the running gateway (`cosmicctl --json channels`, silent when it
# cannot be reached). Needs nothing from the bash-completion package.

_cosmicctl_commands="bind calibrate channel channels check diagram echo fmus gen peers record reload replay security segments status top types unbind"
_cosmicctl_global_options="--help --json --socket --version"

# The options of one command (besides the global ones, which may follow it too).
_cosmicctl_command_options() {
  case $1 in
    bind) echo "--replace --match-timeout" ;;
    calibrate) echo "--seconds --rate --dds-samples" ;;
    diagram) echo "--format --detail" ;;
    echo) echo "--count --interval --timeout" ;;
    gen) echo "--component --output" ;;
    replay) [ "$2" != stop ] && echo "--channel --speed --loop --start-offset --name --realtime --latency-bound --alongside --match-timeout" ;;
    security) [ "$2" = permissions ] && echo "--sign-with --protection --valid-days" ;;
    top) echo "--interval --iterations" ;;
    types) echo "--type-path --name" ;;
  esac
}

# The names of the components: section of a YAML file (both `- name: x` and `- {name: x, ...}`).
_cosmicctl_components() {
  [ -r "$1" ] || return
  sed -n '/^components:/,/^[^[:space:]#-]/p' "$1" 2>/dev/null |
    sed -n 's/^[[:space:]]*-[[:space:]]*{\{0,1\}[[:space:]]*name:[[:space:]]*\([^,}[:space:]]*\).*/\1/p'
}

_cosmicctl() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
  local command="" socket=() file="" more="" i word
  for ((i = 1; i < COMP_CWORD; i++)); do
    word=${COMP_WORDS[i]}
    case $word in
      --socket) socket=(--socket "${COMP_WORDS[i + 1]}"); ((i++)) ;;
      --format | --component | --output | --interval | --iterations | --seconds | --rate | --match-timeout | \
        --protection | --valid-days) ((i++)) ;;
      --sign-with) ((i += 2)) ;;
      -*) ;;
      *)
        if [ -z "$command" ]; then
          command=$word
        elif [ -z "$file" ]; then
          file=$word
        else
          more=$word
        fi
        ;;
    esac
  done

  case $prev in
    --socket)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -- "$cur")
      return ;;
    --output)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -d -- "$cur")
      return ;;
    --format)
      mapfile -t COMPREPLY < <(compgen -W "svg dot" -- "$cur")
      return ;;
    --protection)
      mapfile -t COMPREPLY < <(compgen -W "encrypt sign none" -- "$cur")
      return ;;
    --component)
      mapfile -t COMPREPLY < <(compgen -W "$(_cosmicctl_components "$file")" -- "$cur")
      return ;;
    --interval | --iterations | --seconds | --rate | --valid-days)
      return ;;
  esac
  # --sign-with CA_CERT CA_KEY: both are PEM files.
  if [ "$prev" = --sign-with ] || [ "${COMP_WORDS[COMP_CWORD - 2]:-}" = --sign-with ]; then
    compopt -o filenames 2>/dev/null
    mapfile -t COMPREPLY < <(compgen -f -- "$cur")
    return
  fi

  if [ -z "$command" ]; then
    if [[ $cur == -* ]]; then
      mapfile -t COMPREPLY < <(compgen -W "$_cosmicctl_global_options" -- "$cur")
    else
      mapfile -t COMPREPLY < <(compgen -W "$_cosmicctl_commands" -- "$cur")
    fi
    return
  fi
  if [[ $cur == -* ]]; then
    mapfile -t COMPREPLY < <(compgen -W "$(_cosmicctl_command_options "$command" "$file") --help --json --socket" -- "$cur")
    return
  fi
  case $command in
    check | diagram | gen | bind | calibrate)
      [ -n "$file" ] && return
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -X '!*.yaml' -- "$cur"; compgen -f -X '!*.yml' -- "$cur"; compgen -d -- "$cur")
      ;;
    types)
      [ -n "$file" ] && return
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -X '!*.dbc' -- "$cur"; compgen -f -X '!*.DBC' -- "$cur"; compgen -f -X '!*.lcm' -- "$cur"
        compgen -f -X '!*.idl' -- "$cur"; compgen -f -X '!*.msg' -- "$cur"; compgen -d -- "$cur")
      ;;
    security)
      # security permissions FILE
      if [ -z "$file" ]; then
        mapfile -t COMPREPLY < <(compgen -W "permissions" -- "$cur")
      elif [ "$file" = permissions ] && [ -z "$more" ]; then
        compopt -o filenames 2>/dev/null
        mapfile -t COMPREPLY < <(compgen -f -X '!*.yaml' -- "$cur"; compgen -f -X '!*.yml' -- "$cur"; compgen -d -- "$cur")
      fi
      ;;
    record)
      # record start|stop|status|info FILE.mcap
      if [ -z "$file" ]; then
        mapfile -t COMPREPLY < <(compgen -W "start stop status info" -- "$cur")
      elif [ "$file" = info ] && [ -z "$more" ]; then
        compopt -o filenames 2>/dev/null
        mapfile -t COMPREPLY < <(compgen -f -X '!*.mcap' -- "$cur"; compgen -d -- "$cur")
      fi
      ;;
    replay)
      # replay FILE.mcap [options] | replay stop NAME
      if [ -z "$file" ]; then
        compopt -o filenames 2>/dev/null
        mapfile -t COMPREPLY < <(compgen -W "stop" -- "$cur"; compgen -f -X '!*.mcap' -- "$cur"; compgen -d -- "$cur")
      fi
      ;;
    channel | unbind | echo)
      [ -n "$file" ] && return
      local names
      names=$(cosmicctl "${socket[@]}" --json channels 2>/dev/null | grep -o '"name": *"[^"]*"' | sed 's/.*"\([^"]*\)"$/\1/')
      mapfile -t COMPREPLY < <(compgen -W "$names" -- "$cur")
      ;;
  esac
}

complete -F _cosmicctl cosmicctl
