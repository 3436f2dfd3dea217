# Sourced by the benchmark scripts: `record_results NAME TITLE "$@"` as a script's first step
# runs the rest of that script again with its standard output copied into
# docs/results/NAME.md, below a header that names the command, its environment variables, the
# commit and the machine, so that every table in docs/results/ says how to reproduce it.
# JETPIPE_RESULTS=0 prints the table without writing the file (e.g. for a quick subset).
# The header says when the tree had uncommitted changes in the code: such a table is not
# reproducible from its commit alone.
#
# The file holds the latest run only, and ends with a "## History" table that this function
# keeps: one row per run, newest first (date, commit, settings and arguments, totals), at most
# RESULTS_HISTORY_ROWS of them; older runs are in the file's git history. The totals come from
# the benchmark itself: the last line of its output that starts with `TOTALS: ` is taken out of
# the body and its text goes into the run's row. A file without a history (or no file) starts one.

RESULTS_HISTORY_ROWS=20

# The rows of the "## History" table of a results file (the last such section), newest first,
# without its header; nothing when the file or the section is missing.
results_history_rows() {
    [ -f "$1" ] || return 0
    awk '
        /^## History[[:space:]]*$/ { inside = 1; n = 0; delete rows; next }
        inside && /^## / { inside = 0; next }
        inside && /^\|/ {
            if ($0 ~ /^\|[-|: ]+\|[[:space:]]*$/) next      # the separator
            if ($0 ~ /^\| *date/) next                        # the header
            rows[++n] = $0
        }
        END { for (i = 1; i <= n; i++) print rows[i] }
    ' "$1"
}

# A table cell: pipes escaped, newlines joined.
results_cell() {
    printf '%s' "$1" | tr '\n' ' ' | sed 's/|/\\|/g'
}

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
    # The run's row of the history, then the earlier runs' rows (read before the file is
    # rewritten).
    local totals invocation commit_cell row
    totals="$(grep '^TOTALS: ' "$table" | tail -n 1 | sed 's/^TOTALS: *//')"
    if [ "$status" != 0 ]; then
        totals="${totals:+$totals; }exited with status $status"
    fi
    invocation="${settings}$*"
    invocation="${invocation% }"
    commit_cell="\`$commit\`${changes:+ (uncommitted changes)}"
    row="| ${started% UTC} | $commit_cell | $(results_cell "${invocation:+\`$invocation\`}") | $(results_cell "$totals") |"
    local written
    written="$(mktemp)"
    {
        echo "# $title"
        echo
        echo "Written by \`${settings}bash $script${*:+ $*}\` at commit \`$commit\`$changes, on $started,"
        echo "on $(nproc) cores (load average $load_before at the start, $(cut -d' ' -f1-3 /proc/loadavg) at the end)."
        echo "Running the same command at that commit writes the same table; wall and CPU times vary with"
        echo "the machine and its load."
        echo
        grep -v '^TOTALS: ' "$table"
        if [ "$status" != 0 ]; then
            echo
            echo "The command exited with status $status."
        fi
        echo
        echo "## History"
        echo
        echo "The runs of \`bash $script\`, newest first (at most $RESULTS_HISTORY_ROWS; the tables of earlier"
        echo "runs are in this file's git history)."
        echo
        echo "| date (UTC) | commit | settings and arguments | totals |"
        echo "|---|---|---|---|"
        echo "$row"
        results_history_rows "$file" | head -n $((RESULTS_HISTORY_ROWS - 1))
    } >"$written"
    cat "$written" >"$file"
    rm -f "$table" "$written"
    echo "wrote $file" >&2
    exit "$status"
}
