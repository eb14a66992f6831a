#!/usr/bin/env python3
"""diefillCalibrate: calibrates contact parameters of a case against measured bulk results
(the paper's section 4: the inclined plate, then the repose test with the plate's result
kept fixed), running the simulations itself.

    diefillCalibrate [DICT] [-workDir DIR] [-check] [-report] [-stopAfter N] [-help]

DICT (default ./calibrationDict) is an OpenFOAM-style dictionary:

    workDir        calibration;     // where the runs, the table and the results go (beside DICT)
    runsInParallel 1;               // simulations at once, each in its own case copy
    threadsPerRun  1;               // demRun threads per simulation (Allrun -threads)
    onFailure      continue;        // continue | stop, when a run fails
    seed           1;
    stages                          // run in this order; a stage keeps the earlier ones' results fixed;
                                    // a stage without parameters is a check: one run at those values
    {
        plate
        {
            case       "$DIEFILL_DIR/tutorials/calibration/inclinedPlate";
            setting    quick;                                  // quick | full
            allrunOptions ( -rolling cdt );                    // optional, passed to Allrun
            fixed      { interactions/sand-sand/friction 0.7; }   // optional
            parameters { interactions/sand-steel/friction (0.3 0.9); }
            targets    { angleAt50PercentSlid { value 29; sigma 1.5; } }   // keys of postProcessing/results.json
            initialRuns 4;  minRuns 5;  maxRuns 16;  tolerance 1;  eiTolerance 0.01;   // optional
            choose     nearest;   // of the runs that agree, the one nearest the case's values (or: best)
            nearestRuns 2;        // runs at the surrogate's agreeing point nearest the case's values
            startRun   yes;       // the first run at the case's own values (no: the design only)
        }
    }

Method: a run at the case's own values and a Latin-hypercube first sample, then one
Gaussian-process surrogate per target and expected improvement of chi2 = sum ((y - value)/sigma)^2.
It stops when a run agrees with every target within tolerance x sigma and no point promises an
improvement above eiTolerance (or above what the simulations' fitted scatter alone makes of chi2),
or at maxRuns (a success if a run agrees, exit 3 if none does).  Output per stage in
WORKDIR/STAGE/: runs.csv (every finished run), result.json (chosen run, posterior mean, sd and
95 % interval per parameter), demPropertiesFragment, response.png, samples.png, convergence.png.
Run again after an interruption: finished runs are kept, a run that was stopped continues from
its restart files.  docs/calibration.md has the details.

Options:
  -workDir DIR   the work folder (instead of the dictionary's workDir)
  -check         read and check the dictionary and its cases; run nothing
  -report        write the results and plots from the runs made so far; run nothing
  -stopAfter N   stop once N runs have finished in this call (run again to continue)
Exit status: 0 done (every stage converged), 1 bad input or a failed run with onFailure stop,
3 a stage used up maxRuns and no run agrees with its targets (the later stages are not run), or
the last stage is a check that does not agree (a check followed by further stages that does not
agree is reported and the later stages run: they may tune its case's parameters again),
4 stopped (-stopAfter or a signal) before the end."""
import datetime
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, positive_int  # noqa: E402
from diefillcal import config, report, runner  # noqa: E402


def main():
    ap = argument_parser(__doc__)
    ap.prog = "diefillCalibrate"
    ap.add_argument("dict", nargs="?", default="calibrationDict", help="the calibration dictionary")
    ap.add_argument("-workDir", default=None)
    ap.add_argument("-check", action="store_true")
    ap.add_argument("-report", action="store_true")
    ap.add_argument("-stopAfter", type=positive_int, default=None)
    a = ap.parse_args()
    if not os.environ.get("DIEFILL_DIR"):
        os.environ["DIEFILL_DIR"] = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    try:
        c = config.read(a.dict, a.workDir)
    except config.InputError as e:
        print(f"diefillCalibrate: error: {e}", file=sys.stderr)
        return 1
    if a.check:
        for s in c.stages:
            what = ("parameters " + ", ".join(f"{p.keyword} {p.low:g}-{p.high:g}" for p in s.parameters)
                    + f"; {s.first_runs} first-sample runs"
                    + (" (the case's own values first)" if s.start_run else "") + f", at most {s.max_runs}") if s.parameters \
                else "a check: one run at the earlier stages' values"
            print(f"{s.name}: {s.case} ({s.setting}); {what}; targets "
                  + ", ".join(f"{t.key} {t.value:g} +- {t.sigma:g}" for t in s.targets))
        print(f"diefillCalibrate: {a.dict} is fine; work folder {c.work_dir}")
        return 0
    carried = {}
    summaries = []
    stop_after = a.stopAfter
    for s in c.stages:
        started = time.time()
        r = runner.StageRunner(c, s, dict(carried))
        tuned = {p.keyword for p in s.parameters}
        kept = {k: v for k, v in carried.items() if k not in tuned}
        if kept:
            print(f"{s.name}: kept fixed from the earlier stage(s): "
                  + ", ".join(f"{k} {v:.4g}" for k, v in kept.items()), flush=True)
        if len(kept) < len(carried):
            print(f"{s.name}: tuned again, from the earlier stage(s)' values: "
                  + ", ".join(f"{k} {v:.4g}" for k, v in carried.items() if k in tuned), flush=True)
        try:
            if a.report:
                r.open()
                outcome = "report"
                if not r.table.rows:
                    print(f"{s.name}: no finished run yet in {r.folder}", flush=True)
                    return 0
            else:
                print(f"{s.name}: case {s.case} ({s.setting}), work folder {r.folder}", flush=True)
                outcome = r.run(stop_after=stop_after)
        except config.InputError as e:
            print(f"diefillCalibrate: error: {e}", file=sys.stderr)
            return 1
        except runner.StopCalibration as e:
            print(f"diefillCalibrate: stopped: {e}", file=sys.stderr)
            return 1
        if outcome == "stopped":
            print(f"{s.name}: stopped with {len(r.table.rows)} runs finished; run the same command again to continue",
                  flush=True)
            return 4
        if stop_after is not None:
            stop_after -= r.finished_here
        try:
            result = report.summarise(r, outcome, time.time() - started)
        except ValueError as e:
            print(f"diefillCalibrate: error: {e}", file=sys.stderr)
            return 1
        summaries.append(result)
        if not s.parameters:
            shown = ", ".join(f"{k} {v:.4g} (target {result['targets'][k]['value']:g} +- {result['targets'][k]['sigma']:g})"
                              for k, v in result["chosenTargets"].items())
            if not result["agrees"]:
                if s is not c.stages[-1]:
                    # The paper's order is one sweep of a fixed-point iteration: a later stage
                    # may tune this case's parameters again with the others kept.
                    print(f"{s.name}: check run at the earlier stages' values: {shown}: not within "
                          f"{s.tolerance:g} sigma; the later stages go on", flush=True)
                    continue
                write_summary(c, summaries, carried, a.report)
                print(f"diefillCalibrate: check stage '{s.name}': the case at the earlier stages' values gives {shown}: "
                      f"not within {s.tolerance:g} sigma (the later stage moved it; tune this case's parameters again "
                      f"in a further stage with the others kept)", file=sys.stderr)
                return 3
            print(f"{s.name}: check run at the earlier stages' values: {shown}: agrees", flush=True)
            continue
        print(f"{s.name}: {outcome} after {result['runs']} runs ({result['failedRuns']} failed, "
              f"{result['simulationSeconds'] / 60:.1f} min of simulation); chosen run {result['chosenRun']}: "
              + ", ".join(f"{t} {v:.4g}" for t, v in result["chosenTargets"].items()), flush=True)
        for keyword, p in result["posterior"].items():
            print(f"    {keyword} = {result['chosen'][keyword]:.4g}   (posterior {p['mean']:.4g} +- {p['std']:.2g}, "
                  f"95 %: {p['q2.5']:.4g} - {p['q97.5']:.4g}; range {p['range'][0]:g}-{p['range'][1]:g})", flush=True)
        print(f"    demProperties fragment: {os.path.join(r.folder, 'demPropertiesFragment')}; plots: "
              f"{os.path.join(r.folder, '{response,samples,convergence}.png')}", flush=True)
        if outcome == "budget" and not a.report:
            if not r.agrees:
                print(f"diefillCalibrate: stage '{s.name}' used its {s.max_runs} runs (maxRuns) and no run agrees with "
                      f"every target within {s.tolerance:g} sigma; the later stages are not run. Raise maxRuns (the runs "
                      f"made are kept), widen the ranges, or tune other parameters", file=sys.stderr)
                return 3
            print(f"{s.name}: maxRuns reached; run {result['chosenRun']} agrees with the targets within "
                  f"{s.tolerance:g} sigma, the surrogate still expected some improvement (raise maxRuns to refine "
                  f"the posterior)", flush=True)
        carried.update(result["chosen"])
    write_summary(c, summaries, carried, a.report)
    return 0


def write_summary(c, summaries, values, reporting):
    """WORKDIR/calibration.json (the values every stage leaves, and per stage its runs, times and
    whether it agrees) and WORKDIR/demPropertiesFragment (those values, to paste)."""
    whole = {
        "values": values,
        "runs": sum(r["runs"] for r in summaries),
        "simulationSeconds": sum(r["simulationSeconds"] for r in summaries),
        "wallSeconds": sum(r["wallSeconds"] for r in summaries),
        "agrees": all(r["agrees"] for r in summaries[-1:]),
        "stages": [{k: r[k] for k in ("stage", "setting", "outcome", "runs", "failedRuns", "simulationSeconds",
                                      "wallSeconds", "chosen", "chosenTargets", "targets", "agrees")}
                   for r in summaries],
    }
    runner._write_atomically(os.path.join(c.work_dir, "calibration.json"), json.dumps(whole, indent=1))
    tuned_in = {k: r["stage"] for r in summaries for k in r["chosen"]}     # the last stage that tuned each
    notes = {k: f"stage '{st}'" for k, st in tuned_in.items()}
    header = [f"// diefillCalibrate, stages {', '.join(r['stage'] for r in summaries)} ({whole['runs']} runs, "
              f"{datetime.date.today().isoformat()}): the values every stage leaves"]
    runner._write_atomically(os.path.join(c.work_dir, "demPropertiesFragment"),
                             report.values_text(values, notes, header))
    if not reporting:
        print(f"diefillCalibrate: {whole['runs']} runs, {whole['wallSeconds'] / 3600:.2f} h; the values of all "
              f"stages in {os.path.join(c.work_dir, 'calibration.json')} and "
              f"{os.path.join(c.work_dir, 'demPropertiesFragment')}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
