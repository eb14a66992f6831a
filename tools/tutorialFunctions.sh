# Shared functions of the calibration tutorials (sourced by their Allrun/Allclean).
#
#   tutorial_parse_args "$@"    sets QUICK (0/1), ROLLING (cdt|epsd2|epsd|none or empty = as in the file),
#                               THREADS (default 1: on a shared 2-core machine one thread is several
#                               times faster than two; with -np, per rank), NP (MPI ranks of demRun or
#                               diefillFoam, default 1: serial); prints the usage from the caller's
#                               header on -help.  -np N is taken only where the caller set
#                               TUTORIAL_NP_OPTION=1 before: elsewhere it is an unknown option
#                               A case's own flags: the caller's tutorial_case_option FLAG [WORDS...]
#                               returns 0 when it took FLAG (and sets TUTORIAL_CASE_VALUES to the
#                               number of words after it that it took as FLAG's value).  A missing or bad value (an option given as the
#                               value: -rolling -dry) stops it with one line, exit 2, nothing written
#   tutorial_prepare [EXTRA]    constant/demProperties from constant/demProperties.orig (saved on the
#                               first run) with the '// @quick ...' lines swapped in (-quick) and
#                               'rolling <model>' set (-rolling); first checks the case with
#                               tutorial_guard (VARIANT: "quick|full, rolling MODEL" + EXTRA)
#   tutorial_lock               one run at a time in the case: locks <case>/.diefill.lock (the lock demRun and
#                               diefillFoam take) for as long as Allrun runs; a second Allrun (or demRun,
#                               diefillFoam) in the case stops with exit 2 naming the holder, nothing written.
#                               The solvers Allrun starts run under its lock (DIEFILL_CASE_LOCK=<file>:<pid>)
#   tutorial_guard              stops Allrun (exit 2) before it writes anything when the case holds
#                               results of another variant or of other inputs (a file of tutorial_inputs
#                               changed, added or removed since the run), or when the generated
#                               constant/demProperties or system/controlDict was edited by hand (Allrun
#                               would overwrite it)
#   tutorial_inputs             the case's inputs, one a line: every file in constant/, system/ and 0.orig/
#                               and the case's geometry writers, less the files Allrun generates
#                               (TUTORIAL_GENERATED; the generated demProperties and controlDict are
#                               checked against their sources, constant/demProperties.orig and
#                               system/controlDict.orig, which are inputs)
#   tutorial_record             writes constant/runRecord (variant, checksums of the inputs and of the
#                               generated demProperties and system/controlDict) just before the solver runs
#   tutorial_run_demRun         demRun (or $DEMRUN) in the case (log.demRun), with -np N > 1 as
#                               diefill_mpirun -np N demRun ... -parallel; continues from the newest
#                               restart file when there is one (same variant and inputs: tutorial_guard);
#                               wall time in TUTORIAL_DEM_SECONDS, and TUTORIAL_RUNTIME_ARGS = (-runTime S)
#                               for the post-processing when the run went from its start in one piece
#   tutorial_clean_args "$@"    Allclean's arguments: the usage from the caller's header on -help;
#                               anything else stops it before a file is removed (exit 2)
#   tutorial_clean              removes the results and restores constant/demProperties
# Cases with air (diefillFoam; dieFilling):
#   tutorial_swap_quick SRC DST  DST from SRC with the '// @quick ...' lines swapped in (-quick)
#   tutorial_prepare_air SCALE  the air mesh (writeAirMesh -scale SCALE, blockMesh, topoSet,
#                               subsetMesh, createPatch) and 0/ from 0.orig/; when time folders
#                               and the mesh exist already, keeps them: the run continues
#   tutorial_run_diefillFoam    diefillFoam in the case (log.diefillFoam), wall time in
#                               TUTORIAL_DEM_SECONDS (and TUTORIAL_RUNTIME_ARGS, as for demRun)
#   tutorial_clean_air          removes the mesh, 0/, the time folders and the air's outputs

# The Allrun scripts cd to their own folder first, so a relative $0 given from elsewhere
# (./tutorials/dieFilling/Allrun -help) is found by its base name.
tutorial_usage() {
    local script=$0
    [ -f "$script" ] || script=$(basename "$0")
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$script"
}

# _tutorial_value OPTION WHAT "$@": stops (one line, exit 2) when OPTION has no value: none
# follows it, or the next word is an option (-dry, -quick: not a value; -1 is one, refused later).
_tutorial_value() {
    local option=$1 what=$2
    shift 2
    if [ $# -lt 2 ] || [[ "$2" =~ ^-[a-zA-Z] ]]; then
        echo "$(basename "$0"): $option needs $what${2+ (got the option '$2')}" >&2
        exit 2
    fi
}

# The most MPI ranks -np takes: the tutorials' cases hold 700-49 000 particles, and a rank needs a
# few thousand for its ghost layer to stay below its own particles (docs/parallel.md).
TUTORIAL_NP_MAX=64

tutorial_parse_args() {
    QUICK=0; ROLLING=""; THREADS=1; NP=1
    while [ $# -gt 0 ]; do
        case "$1" in
            -quick) QUICK=1 ;;
            -rolling)
                _tutorial_value -rolling "a model: cdt, epsd2, epsd or none" "$@"
                ROLLING=$2; shift
                case "$ROLLING" in cdt|epsd|epsd2|none) ;; *)
                    echo "$(basename "$0"): unknown rolling model '$ROLLING'; expected cdt, epsd2, epsd or none" >&2
                    exit 2 ;;
                esac ;;
            -threads)
                _tutorial_value -threads "a positive whole number" "$@"
                THREADS=$2; shift
                # Checked here, before anything is written into the case.
                case "$THREADS" in ''|*[!0-9]*|0*)
                    echo "$(basename "$0"): -threads expects a positive whole number, got '$THREADS'" >&2
                    exit 2 ;;
                esac ;;
            -np)
                if [ "${TUTORIAL_NP_OPTION:-0}" != 1 ]; then
                    echo "$(basename "$0"): unknown option '$1' (this case does not run on MPI ranks)" >&2
                    tutorial_usage >&2; exit 2
                fi
                _tutorial_value -np "a number of MPI ranks from 1 to $TUTORIAL_NP_MAX" "$@"
                NP=$2; shift
                # Checked here, before anything is written into the case (-np 1: serial, as without it).
                if ! [[ "$NP" =~ ^[1-9][0-9]{0,5}$ ]] || [ "$NP" -gt "$TUTORIAL_NP_MAX" ]; then
                    echo "$(basename "$0"): -np expects a number of MPI ranks from 1 to $TUTORIAL_NP_MAX (1: serial), got '$NP'" >&2
                    exit 2
                fi
                if [ "$NP" -gt 1 ] && ! command -v mpirun > /dev/null; then
                    echo "$(basename "$0"): -np $NP needs mpirun (Open MPI), which is not on PATH" >&2
                    exit 2
                fi ;;
            -h|-help|--help) tutorial_usage; exit 0 ;;
            *)
                # A case option with a value sets TUTORIAL_CASE_VALUES=1 (the words it took after the flag).
                TUTORIAL_CASE_VALUES=0
                if declare -F tutorial_case_option > /dev/null && tutorial_case_option "$@"; then
                    shift "$TUTORIAL_CASE_VALUES"
                else
                    echo "$(basename "$0"): unknown option '$1'" >&2; tutorial_usage >&2; exit 2
                fi ;;
        esac
        shift
    done
}

tutorial_swap_quick() {
    local src=$1 dst=$2
    if [ "$QUICK" = 1 ]; then
        # '<full text>   // @quick <quick text>'  ->  '<quick text>   // quick setting; full: <full text>'
        sed -E 's#^([[:space:]]*)([^/[:space:]].*[^[:space:]])[[:space:]]*// @quick (.*)$#\1\3   // quick setting; full: \2#' \
            "$src" > "$dst"
    else
        cp "$src" "$dst"
    fi
}

# The variant a run is: setting, rolling model (as given, or the file's) and the caller's extra.
tutorial_variant() {
    local src=constant/demProperties rolling=$ROLLING
    [ -f "$src.orig" ] && src=$src.orig
    [ -n "$rolling" ] || rolling=$(sed -n -E 's#.*contactModel[^}]*rolling ([a-z0-9]+);.*#\1#p' "$src" | head -1)
    echo "$([ "$QUICK" = 1 ] && echo quick || echo full), rolling $rolling${1-}"
}

_tutorial_md5() { md5sum < "$1" | cut -d' ' -f1; }
_tutorial_recorded() { sed -n "s/^$1 //p" constant/runRecord 2> /dev/null; }

# Files Allrun (or what it runs: writeAirMesh, the solver's start) writes into constant/ and system/.
TUTORIAL_AIR_DICTS=(system/blockMeshDict system/topoSetDict system/topoSetDict.aeration system/createPatchDict
                    system/decomposeParDict)
TUTORIAL_GENERATED=(constant/demProperties system/controlDict constant/setting constant/air constant/runRecord
                    "${TUTORIAL_AIR_DICTS[@]}")

# The inputs a run reads, or makes what it reads from (the geometry and the air mesh): a continued
# run would read a changed one differently, so the guard refuses it (one list for all the cases).
tutorial_inputs() {
    local f
    for f in constant/* system/* 0.orig/* writeGeometry writeAirMesh; do
        [ -f "$f" ] || continue
        case " ${TUTORIAL_GENERATED[*]} " in *" $f "*) continue ;; esac
        echo "$f"
    done
}

# The inputs changed since constant/runRecord was written, as 'FILE was changed|added|removed, ...'.
# A record without inputs (written before they were recorded) has demProperties.orig's only.
_tutorial_changed_inputs() {
    local f md5 changes=() recorded
    recorded=$(sed -n 's/^input //p' constant/runRecord)
    if [ -z "$recorded" ]; then
        if [ -f constant/demProperties.orig ] && [ "$(_tutorial_md5 constant/demProperties.orig)" != "$(_tutorial_recorded source)" ]; then
            changes+=("constant/demProperties.orig was changed")
        fi
    else
        while read -r md5 f; do
            if [ ! -f "$f" ]; then changes+=("$f was removed")
            elif [ "$(_tutorial_md5 "$f")" != "$md5" ]; then changes+=("$f was changed"); fi
        done <<< "$recorded"
        while read -r f; do
            [ -z "$f" ] || grep -qxF -- "$f" <<< "$(cut -d' ' -f2- <<< "$recorded")" || changes+=("$f was added")
        done <<< "$(tutorial_inputs)"
    fi
    [ ${#changes[@]} = 0 ] || { local IFS=,; echo "${changes[*]}" | sed 's/,/, /g'; }
}

# Results of a run: DEM output or air time folders.
tutorial_has_results() { [ -f dem/summary.csv ] || [ -f dem/restart/latest ] || [ -n "$(tutorial_air_times)" ]; }

tutorial_guard() {
    local props=constant/demProperties me recorded changed
    me=$(basename "$0")
    [ -f constant/runRecord ] || return 0     # never run, or cleaned, or run before the record existed
    if [ -f "$props.orig" ] && [ "$(_tutorial_md5 "$props")" != "$(_tutorial_recorded generated)" ]; then
        echo "$me: constant/demProperties was changed after Allrun wrote it from constant/demProperties.orig," \
             "and Allrun would overwrite the change; nothing done. Make the change in constant/demProperties.orig" \
             "(Allrun's source, with the '// @quick' lines), or run ./Allclean to drop it." >&2
        exit 2
    fi
    if [ -f system/controlDict.orig ] && [ -n "$(_tutorial_recorded controlDict)" ] \
        && [ "$(_tutorial_md5 system/controlDict)" != "$(_tutorial_recorded controlDict)" ]; then
        echo "$me: system/controlDict was changed after Allrun wrote it from system/controlDict.orig, and" \
             "Allrun would overwrite the change; nothing done. Make the change in system/controlDict.orig," \
             "or run ./Allclean to drop it." >&2
        exit 2
    fi
    tutorial_has_results || return 0
    recorded=$(_tutorial_recorded variant)
    if [ "$recorded" != "$VARIANT" ]; then
        echo "$me: this case holds the results of a '$recorded' run, and this is a '$VARIANT' run: Allrun would" \
             "mix or delete them; nothing done. Run ./Allclean first, or run in a fresh copy of the tutorial." >&2
        exit 2
    fi
    changed=$(_tutorial_changed_inputs)
    if [ -n "$changed" ]; then
        echo "$me: $changed after this case's results were computed: Allrun would continue them with other" \
             "inputs; nothing done. Undo the change, or run ./Allclean first (the results go), or run in a" \
             "fresh copy of the case." >&2
        exit 2
    fi
}

tutorial_record() {
    printf 'variant %s\nsource %s\ngenerated %s\n' "$VARIANT" "$(_tutorial_md5 constant/demProperties.orig)" \
        "$(_tutorial_md5 constant/demProperties)" > constant/runRecord
    [ ! -f system/controlDict.orig ] || printf 'controlDict %s\n' "$(_tutorial_md5 system/controlDict)" >> constant/runRecord
    local f
    while read -r f; do
        [ -z "$f" ] || printf 'input %s %s\n' "$(_tutorial_md5 "$f")" "$f" >> constant/runRecord
    done <<< "$(tutorial_inputs)"
}

# The lock is the kernel's (flock): released when this shell ends, however it ends.
tutorial_lock() {
    local lock=$PWD/.diefill.lock me
    me=$(basename "$0")
    if ! exec {TUTORIAL_LOCK_FD}<>"$lock"; then
        echo "$me: cannot create the case lock $lock (a case folder must be writable to run in it); nothing done" >&2
        exit 2
    fi
    if ! flock -n "$TUTORIAL_LOCK_FD"; then
        echo "$me: case $PWD is in use by process $(sed -n 's/^pid //p' "$lock") ($(sed -n 's/^command //p' "$lock"))," \
             "started $(sed -n 's/^started //p' "$lock") (lock $lock); a second run in it would cut the first one's" \
             "results; nothing done. Wait for it to end, or run in a copy of the case." >&2
        exit 2
    fi
    printf 'pid %s\ncommand %s\nstarted %s\n' "$$" "$me" "$(date -u '+%Y-%m-%d %H:%M:%S UTC')" > "$lock"
    export DIEFILL_CASE_LOCK="$lock:$$"
}

tutorial_prepare() {
    local props=constant/demProperties
    VARIANT=$(tutorial_variant "${1-}")
    tutorial_guard     # reads only: a run it refuses leaves even the lock file as it was
    tutorial_lock
    [ -f "$props.orig" ] || cp "$props" "$props.orig"
    tutorial_swap_quick "$props.orig" "$props"
    if [ -n "$ROLLING" ]; then
        sed -i -E "s#(contactModel[^}]*rolling )[a-z0-9]+;#\1$ROLLING;#" "$props"
    fi
    ROLLING=$(sed -n -E 's#.*contactModel[^}]*rolling ([a-z0-9]+);.*#\1#p' "$props" | head -1)
    SETTING=$([ "$QUICK" = 1 ] && echo quick || echo full)
    echo "$SETTING" > constant/setting
    if [ "${NP:-1}" -gt 1 ]; then
        echo "    setting: $SETTING, rolling model: $ROLLING, $NP MPI ranks x $THREADS thread(s)"
    else
        echo "    setting: $SETTING, rolling model: $ROLLING, $THREADS thread(s)"
    fi
}

# tutorial_timed_run NAME LOG COMMAND...: runs COMMAND, wall time in TUTORIAL_DEM_SECONDS;
# on failure prints the end of LOG and exits with the command's status.
tutorial_timed_run() {
    local name=$1 log=$2 start=$SECONDS status=0
    shift 2
    "$@" || status=$?
    TUTORIAL_DEM_SECONDS=$((SECONDS - start))
    if [ "$status" -ne 0 ]; then
        # A run refused before it started (a locked case, a damaged restart file) has not
        # written its log: its console output says why.
        if [ -s "${TUTORIAL_CONSOLE-}" ] && ! grep -qF -- "$(tail -n 1 "$TUTORIAL_CONSOLE")" "$log" 2> /dev/null; then
            echo "$(basename "$PWD"): $name failed (exit $status):" >&2
            tail -n 30 "$TUTORIAL_CONSOLE" >&2
        else
            echo "$(basename "$PWD"): $name failed (exit $status); last lines of $log:" >&2
            tail -n 30 "$log" >&2
        fi
        rm -f "${TUTORIAL_CONSOLE-}"
        exit "$status"
    fi
    rm -f "${TUTORIAL_CONSOLE-}"
    echo "    $name: ok (${TUTORIAL_DEM_SECONDS} s, $log)"
}

# demRun writes log.demRun itself (with its progress lines and ETA).  With -np N > 1 on N MPI
# ranks (-threads per rank); rank 0 takes the case lock under Allrun's (DIEFILL_CASE_LOCK passed
# on with -x), writes the log and the results; stdin is not handed to rank 0.
_tutorial_demRun() {
    if [ "${NP:-1}" -gt 1 ]; then
        diefill_mpirun -x DIEFILL_CASE_LOCK -np "$NP" "${DEMRUN:-demRun}" -case "$PWD" -parallel -threads "$THREADS" \
            ${TUTORIAL_RESTART_ARGS[@]+"${TUTORIAL_RESTART_ARGS[@]}"} < /dev/null > "$TUTORIAL_CONSOLE" 2>&1
    else
        "${DEMRUN:-demRun}" -case "$PWD" -threads "$THREADS" ${TUTORIAL_RESTART_ARGS[@]+"${TUTORIAL_RESTART_ARGS[@]}"} > "$TUTORIAL_CONSOLE" 2>&1
    fi
}
# With -np N > 1: the air decomposed by decomposePar and the DEM by demLib, on N MPI ranks
# (docs/coupling.md, "Parallel"); rank 0 takes the case lock under Allrun's.
_tutorial_diefillFoam() {
    if [ "${NP:-1}" -gt 1 ]; then
        diefill_mpirun -x DIEFILL_CASE_LOCK -x OMP_NUM_THREADS -np "$NP" diefillFoam -parallel < /dev/null \
            >> log.diefillFoam 2>&1
    else
        diefillFoam >> log.diefillFoam 2>&1
    fi
}

# The air of a run on -np N ranks: N slabs along x (the shoe's motion; the DEM cuts its own, by
# particle count), decomposed at the start or, continuing a serial run, at its newest time.  A run
# decomposed on another count continues on that one (the processor folders hold its air).
_tutorial_decompose() {
    local continued=$1 have=0 dir
    for dir in processor[0-9]*; do [ ! -d "$dir" ] || have=$((have + 1)); done
    if [ "$have" -gt 0 ]; then
        [ "$have" = "$NP" ] && return 0
        echo "$(basename "$0"): this run's air is decomposed on $have ranks (processor*/): continue it with" \
             "-np $have (or reconstructPar, remove processor*, and continue with -np $NP); nothing done" >&2
        exit 2
    fi
    cat > system/decomposeParDict <<EOF_DICT
FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }
// Written by Allrun -np $NP: the air in $NP slabs along x.
numberOfSubdomains $NP;
method          simple;
coeffs          { n ($NP 1 1); }
EOF_DICT
    if ! decomposePar -force $([ "$continued" = 1 ] && echo -latestTime) > log.decomposePar 2>&1; then
        echo "$(basename "$PWD"): decomposePar failed; last lines of log.decomposePar:" >&2
        tail -n 20 log.decomposePar >&2
        exit 1
    fi
}

# A stopped run (or a finished one: then only the post-processing runs again) goes on from its
# newest restart file; tutorial_guard has made sure it is this variant's, with these inputs.
tutorial_run_demRun() {
    TUTORIAL_RESTART_ARGS=()
    if [ -f dem/restart/latest ]; then
        echo "    continuing from the newest restart file, dem/restart/$(cat dem/restart/latest) (./Allclean to start afresh)"
        TUTORIAL_RESTART_ARGS=(-restart latest)
    else
        rm -rf dem log.demRun
    fi
    tutorial_record
    TUTORIAL_CONSOLE=$(mktemp)      # outside the case: the console output, shown if demRun is refused
    tutorial_timed_run "demRun$([ "${NP:-1}" -gt 1 ] && echo " on $NP MPI ranks")" log.demRun _tutorial_demRun
    TUTORIAL_RUNTIME_ARGS=()
    [ -n "${TUTORIAL_RESTART_ARGS[*]}" ] || TUTORIAL_RUNTIME_ARGS=(-runTime "$TUTORIAL_DEM_SECONDS")
}

# Time folders of the air after 0, in order (a decomposed run's in processor0/)
tutorial_air_times() {
    { ls -d [0-9]* 2>/dev/null; [ ! -d processor0 ] || (cd processor0 && ls -d [0-9]* 2>/dev/null); } \
        | grep -E '^[0-9]+(\.[0-9]+)?(e[+-]?[0-9]+)?$' | grep -v '^0$' | sort -gu
}

tutorial_prepare_air() {
    local scale=$1 tool
    [ -f system/controlDict.orig ] || cp system/controlDict system/controlDict.orig
    tutorial_swap_quick system/controlDict.orig system/controlDict
    if [ -d constant/polyMesh ] && [ -d 0 ] && [ -n "$(tutorial_air_times)" ]; then
        echo "    air: continuing from t = $(tutorial_air_times | tail -1) s (mesh and fields kept)"
        return 0
    fi
    rm -rf 0 constant/polyMesh
    "$DIEFILL_PYTHON" ./writeAirMesh -scale "$scale" > log.writeAirMesh
    local steps=("blockMesh:blockMesh" "topoSet:topoSet" "subsetMesh:subsetMesh air -patch walls -overwrite"
                 "topoSet.aeration:topoSet -dict system/topoSetDict.aeration" "createPatch:createPatch -overwrite")
    for tool in "${steps[@]}"; do
        # shellcheck disable=SC2086
        if ! ${tool#*:} > "log.${tool%%:*}" 2>&1; then
            echo "$(basename "$PWD"): '${tool#*:}' failed; last lines of log.${tool%%:*}:" >&2
            tail -n 20 "log.${tool%%:*}" >&2
            exit 1
        fi
    done
    touch case.foam     # for ParaView's OpenFOAM reader
    mkdir -p 0
    for f in 0.orig/*; do tutorial_swap_quick "$f" "0/$(basename "$f")"; done
    echo "    air mesh: $(sed -n 's/^writeAirMesh: //p' log.writeAirMesh)"
}

tutorial_run_diefillFoam() {
    local continued=0
    if [ -d dem/restart ] && [ -n "$(tutorial_air_times)" ]; then continued=1; else rm -rf dem processor[0-9]*; fi
    [ "${NP:-1}" -le 1 ] || _tutorial_decompose "$continued"
    tutorial_record
    OMP_NUM_THREADS=$THREADS tutorial_timed_run "diefillFoam$([ "${NP:-1}" -gt 1 ] && echo " on $NP MPI ranks")" \
        log.diefillFoam _tutorial_diefillFoam
    # The air fields of every written time in the case folder too (ParaView, a serial continuation)
    if [ "${NP:-1}" -gt 1 ] && ! reconstructPar -newTimes > log.reconstructPar 2>&1; then
        echo "$(basename "$PWD"): reconstructPar failed; last lines of log.reconstructPar:" >&2
        tail -n 20 log.reconstructPar >&2
        exit 1
    fi
    TUTORIAL_RUNTIME_ARGS=()
    [ "$continued" = 1 ] || TUTORIAL_RUNTIME_ARGS=(-runTime "$TUTORIAL_DEM_SECONDS")
}

# Allclean deletes a case's results, so an option it does not know (a typo, or an
# Allrun option given to it by mistake) must stop it before anything is removed.
tutorial_clean_args() {
    case "${1-}" in
        '') ;;
        -h|-help|--help) tutorial_usage; exit 0 ;;
        *) echo "$(basename "$0"): unknown option '$1'; nothing removed" >&2; tutorial_usage >&2; exit 2 ;;
    esac
}

tutorial_clean_air() {
    rm -rf 0 constant/polyMesh [1-9]* 0.[0-9]* processor* postProcessing log.* case.foam "${TUTORIAL_AIR_DICTS[@]}"
    [ -f system/controlDict.orig ] && mv system/controlDict.orig system/controlDict
    return 0
}

tutorial_clean() {
    rm -rf dem postProcessing log.* constant/setting constant/runRecord
    [ -f constant/demProperties.orig ] && mv constant/demProperties.orig constant/demProperties
    return 0
}
