# Sourced by the benchmark scripts: `record_results NAME TITLE "$@"` as a script's first step
# runs the rest of that script again with its standard output copied into
# docs/results/NAME.md, below a header that names the command, its environment variables, the
# commit and the machine, so that every table in docs/results/ says how to reproduce it.
# JETPIPE_RESULTS=0 prints the table without writing the file (e.g. for a quick subset).
# The header says when the tree had uncommitted changes in the code: such a table is not
# reproducible from its commit alone.

record_results() {
    local name="$1" title="$2"
    shift 2
    if [ -n "${JETPIPE_RECORDING_RESULTS:-}" ] || [ "${JETPIPE_RESULTS:-1}" = 0 ]; then
        return 0
    fi
    local script="scripts/$(basename "$0")" file="docs/results/$name.md"
    mkdir -p docs/results
    local commit changes=""
    commit="$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown)"
    # What the diagnosis's figures depend on (the FMI layer and the FMUs do not change them).
    if ! git diff --quiet HEAD -- Cargo.lock crates/model crates/diagnosis crates/cli tools scripts 2>/dev/null; then
        changes=" with uncommitted changes to the code"
    fi
    # The variables that choose what a benchmark runs, as they were given.
    local settings=""
    local variable
    for variable in $(compgen -e | grep -E '^(JETPIPE|BENCH)_' | grep -v '^JETPIPE_RECORDING_RESULTS$' | sort); do
        local value="${!variable}"
        # A folder outside the project is named by its last component only.
        case "$value" in /*|../*) value=".../$(basename "$value")" ;; esac
        case "$value" in *" "*) value="\"$value\"" ;; esac
        settings+="$variable=$value "
    done
    local started load_before
    started="$(date -u '+%Y-%m-%d %H:%M UTC')"
    load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
    local table
    table="$(mktemp)"
    set +e
    JETPIPE_RECORDING_RESULTS=1 bash "$script" "$@" | tee "$table"
    local status="${PIPESTATUS[0]}"
    set -e
    {
        echo "# $title"
        echo
        echo "Written by \`${settings}bash $script${*:+ $*}\` at commit \`$commit\`$changes, on $started,"
        echo "on $(nproc) cores (load average $load_before at the start, $(cut -d' ' -f1-3 /proc/loadavg) at the end)."
        echo "Running the same command at that commit writes the same table; wall and CPU times vary with"
        echo "the machine and its load."
        echo
        cat "$table"
        if [ "$status" != 0 ]; then
            echo
            echo "The command exited with status $status."
        fi
    } >"$file"
    rm -f "$table"
    echo "wrote $file" >&2
    exit "$status"
}
