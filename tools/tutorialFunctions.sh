# Shared functions of the calibration tutorials (sourced by their Allrun/Allclean).
#
#   tutorial_parse_args "$@"    sets QUICK (0/1), ROLLING (cdt|epsd2|epsd|none or empty = as in the file),
#                               THREADS (default 1: on a shared 2-core machine one thread is several
#                               times faster than two); prints the usage from the caller's header on -help
#   tutorial_prepare            constant/demProperties from constant/demProperties.orig (saved on the
#                               first run) with the '// @quick ...' lines swapped in (-quick) and
#                               'rolling <model>' set (-rolling)
#   tutorial_run_demRun         demRun (or $DEMRUN) in the case (log.demRun), wall time in TUTORIAL_DEM_SECONDS
#   tutorial_clean              removes the results and restores constant/demProperties

tutorial_usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }

tutorial_parse_args() {
    QUICK=0; ROLLING=""; THREADS=1
    while [ $# -gt 0 ]; do
        case "$1" in
            -quick) QUICK=1 ;;
            -rolling)
                ROLLING=${2:?-rolling needs a model: cdt, epsd2, epsd or none}; shift
                case "$ROLLING" in cdt|epsd|epsd2|none) ;; *)
                    echo "$(basename "$0"): unknown rolling model '$ROLLING'; expected cdt, epsd2, epsd or none" >&2
                    exit 2 ;;
                esac ;;
            -threads) THREADS=${2:?-threads needs a number}; shift ;;
            -h|-help|--help) tutorial_usage; exit 0 ;;
            *) echo "$(basename "$0"): unknown option '$1'" >&2; tutorial_usage >&2; exit 2 ;;
        esac
        shift
    done
}

tutorial_prepare() {
    local props=constant/demProperties
    [ -f "$props.orig" ] || cp "$props" "$props.orig"
    if [ "$QUICK" = 1 ]; then
        # '<full text>   // @quick <quick text>'  ->  '<quick text>   // quick setting; full: <full text>'
        sed -E 's#^([[:space:]]*)([^/[:space:]].*[^[:space:]])[[:space:]]*// @quick (.*)$#\1\3   // quick setting; full: \2#' \
            "$props.orig" > "$props"
    else
        cp "$props.orig" "$props"
    fi
    if [ -n "$ROLLING" ]; then
        sed -i -E "s#(contactModel[^}]*rolling )[a-z0-9]+;#\1$ROLLING;#" "$props"
    fi
    ROLLING=$(sed -n -E 's#.*contactModel[^}]*rolling ([a-z0-9]+);.*#\1#p' "$props" | head -1)
    SETTING=$([ "$QUICK" = 1 ] && echo quick || echo full)
    echo "$SETTING" > constant/setting
    echo "    setting: $SETTING, rolling model: $ROLLING, $THREADS thread(s)"
}

tutorial_run_demRun() {
    local start=$SECONDS status=0
    rm -rf dem log.demRun
    OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive} "${DEMRUN:-demRun}" -case "$PWD" -threads "$THREADS" > /dev/null 2>&1 || status=$?
    TUTORIAL_DEM_SECONDS=$((SECONDS - start))
    if [ "$status" -ne 0 ]; then
        echo "$(basename "$PWD"): demRun failed (exit $status); last lines of log.demRun:" >&2
        tail -n 20 log.demRun >&2
        exit "$status"
    fi
    echo "    demRun: ok (${TUTORIAL_DEM_SECONDS} s, log.demRun)"
}

tutorial_clean() {
    rm -rf dem postProcessing log.* constant/setting
    [ -f constant/demProperties.orig ] && mv constant/demProperties.orig constant/demProperties
    return 0
}
