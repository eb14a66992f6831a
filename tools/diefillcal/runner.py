"""Running a stage: case copies, the table of finished runs, restart, the loop that fills
the free slots with the design's points and then with the surrogate's proposals."""
import csv
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import time

import numpy as np
from scipy import stats

from . import casefile, method
from .config import InputError

TABLE = "runs.csv"
RECORD = "stage.json"
RUN_PARAMETERS = "calibrationRun.json"
RUN_LOG = "log.calibrationRun"
CALLS = "calls.csv"      # one row per call of the tool on the stage: when, how long, how it ended
# Results of an earlier run in the tutorial folder are not copied into a run's case.
_NOT_COPIED = {"dem", "postProcessing", "runRecord", "setting", ".diefill.lock"}


class StopCalibration(Exception):
    """A run failed and onFailure is 'stop', or the user stopped the tool."""


def _say(text):
    print(text, flush=True)


def _write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


class RunTable:
    """The finished runs of a stage, one row each, rewritten whole (atomically) after each."""

    def __init__(self, path):
        self.path = path
        self.rows = []
        if os.path.exists(path):
            with open(path, newline="") as f:
                self.rows = list(csv.DictReader(f))

    def add(self, row):
        self.rows.append({k: ("" if v is None else v) for k, v in row.items()})
        columns = []
        for r in self.rows:
            columns += [k for k in r if k not in columns]
        buffer = io.StringIO()
        w = csv.DictWriter(buffer, columns, restval="")
        w.writeheader()
        for r in self.rows:
            w.writerow(r)
        _write_atomically(self.path, buffer.getvalue())

    def ids(self):
        return {int(r["run"]) for r in self.rows}


def _copy_case(source, dest):
    def ignore(folder, names):
        return [n for n in names if n in _NOT_COPIED or n.startswith("log.") or n == "demProperties.orig"]
    shutil.copytree(source, dest, ignore=ignore, symlinks=True)
    orig = os.path.join(source, "constant", "demProperties.orig")
    if os.path.exists(orig):       # Allrun has run in the source: .orig is the input, not the generated file
        shutil.copy2(orig, os.path.join(dest, "constant", "demProperties"))


class StageRunner:
    def __init__(self, calibration, stage, carried):
        self.c = calibration
        self.s = stage
        self.carried = carried            # keyword -> value from earlier stages
        self.folder = os.path.join(calibration.work_dir, stage.name)
        self.table = None
        self.running = {}                 # run id -> (process, start time, parameters, log file)
        self.stopping = False
        self.finished_here = 0
        self._design = None
        self.agrees = False
        self.started = time.time()

    # ---- the record of what the runs mean, checked on restart -------------------------------
    def open(self):
        os.makedirs(os.path.join(self.folder, "runs"), exist_ok=True)
        record_path = os.path.join(self.folder, RECORD)
        record = self.s.record(self.carried)
        if os.path.exists(record_path):
            old = json.load(open(record_path))
            changed = [k for k in record if json.dumps(old.get(k), sort_keys=True) != json.dumps(record[k], sort_keys=True)]
            if changed:
                raise InputError(
                    f"{self.c.path}: stage '{self.s.name}': {', '.join(changed)} changed since the runs in "
                    f"{self.folder} were made (recorded in {record_path}: {', '.join(json.dumps(old.get(k)) for k in changed)}); "
                    f"their results would not belong to this calibration. Undo the change, or give another workDir "
                    f"(or -workDir) to start afresh" +
                    (" (the earlier stage's result changed: its values are kept fixed here)" if "fixed" in changed else ""))
        else:
            _write_atomically(record_path, json.dumps(record, indent=1))
        self.table = RunTable(os.path.join(self.folder, TABLE))

    # ---- the points ---------------------------------------------------------------------------
    def _points(self, rows):
        d = len(self.s.parameters)
        return np.array([[p.to_unit(float(r[p.keyword])) for p in self.s.parameters] for r in rows],
                        float).reshape(len(rows), d)

    def finished_ok(self):
        rows = [r for r in self.table.rows if r["status"] == "ok"]
        y = np.array([[float(r[t.key]) for t in self.s.targets] for r in rows], float).reshape(len(rows), len(self.s.targets))
        return rows, self._points(rows), y

    def start_values(self):
        """The case's own value of each parameter (an earlier stage's result when it tuned it)."""
        source = casefile.source_file(self.s.case)
        return [float(self.carried.get(p.keyword, casefile.read_value(source, p.keyword))) for p in self.s.parameters]

    def start_unit(self):
        """start_values() in the unit cube (not clipped)."""
        return np.array([p.to_unit(v) for p, v in zip(self.s.parameters, self.start_values())])

    def within_tolerance(self, values):
        """Whether one run's target values all lie within tolerance x sigma of the targets."""
        return all(abs(v - t.value) <= self.s.tolerance * t.sigma for v, t in zip(values, self.s.targets))

    def misfit(self, values):
        return float(sum(((v - t.value) / t.sigma) ** 2 for v, t in zip(values, self.s.targets)))

    def design(self):
        if self._design is None:
            self._design = method.initial_design(self.s.initial_runs, len(self.s.parameters), self.c.seed)
        return self._design

    def surrogate(self, x, y):
        return method.Surrogate(x, y, [t.value for t in self.s.targets], [t.sigma for t in self.s.targets],
                                seed=self.c.seed)

    def _failed_points(self):
        return self._points([r for r in self.table.rows if r["status"] != "ok"])

    def next_point(self, run_id):
        """Unit-cube point of run `run_id`: the design's for the first runs, then the
        surrogate's proposal with the running points believed."""
        d = len(self.s.parameters)
        if d == 0:
            return np.zeros(0), "check at the earlier stages' values"
        if self.s.start_run and run_id == 1:
            return np.clip(self.start_unit(), 0.0, 1.0), "the case's own values"
        if run_id <= self.s.first_runs:
            return self.design()[run_id - 1 - (self.s.first_runs - self.s.initial_runs)], "design"
        _, x, y = self.finished_ok()
        if len(x) < 2:
            # too few good runs for a surrogate (failures): more space-filling points
            return stats.qmc.Sobol(d=d, seed=self.c.seed + 1).random(64)[run_id % 64], "space-filling"
        s = self.surrogate(x, y)
        pending = np.array([r[2] for r in self.running.values()]).reshape(-1, d)
        if self.converged_apart_from_nearest(x, y, s):
            # Only the nearest-agreeing run is left to make (one at a time: its result decides
            # whether another is worth it).
            if any(self._marker_why(r) == self.NEAREST for r in self.running):
                return None, None
            q = self.nearest_point(x, y, s, pending)
            if q is not None:
                return q, self.NEAREST
            if len(pending):
                return None, None
        s = s.believe(pending)
        best = min(self.misfit(v) for v in y)
        done = np.vstack([x, pending, self._failed_points()]) if len(pending) else np.vstack([x, self._failed_points()])
        points, _ = method.propose(s, done, best, 1, avoid=self._failed_points(), seed=self.c.seed + run_id)
        return points[0], "expected improvement"

    # ---- one run ----------------------------------------------------------------------------
    def run_folder(self, run_id):
        return os.path.join(self.folder, "runs", f"run{run_id:04d}")

    def launch(self, run_id, unit_point, why):
        folder = self.run_folder(run_id)
        values = {p.keyword: float(p.from_unit(u)) for p, u in zip(self.s.parameters, unit_point)}
        marker = os.path.join(folder, RUN_PARAMETERS)
        if os.path.exists(marker):
            _say(f"{self.s.name}: run {run_id} was stopped before it finished; continuing it in {folder}")
        else:
            if os.path.exists(folder):
                shutil.rmtree(folder)         # a copy that was never started (stopped while copying)
            _copy_case(self.s.case, folder)
            props = os.path.join(folder, "constant", "demProperties")
            casefile.set_values(props, {**self.carried, **self.s.fixed, **values})
            _write_atomically(marker, json.dumps({"run": run_id, "unit": list(map(float, unit_point)),
                                                  "values": values, "why": why}, indent=1))
        command = ["./Allrun"] + (["-quick"] if self.s.setting == "quick" else []) + self.s.allrun_options \
            + ["-threads", str(self.c.threads_per_run)]
        log = open(os.path.join(folder, RUN_LOG), "a")
        env = dict(os.environ, DIEFILL_DIR=os.environ.get("DIEFILL_DIR", ""))
        process = subprocess.Popen(command, cwd=folder, stdout=log, stderr=subprocess.STDOUT, env=env,
                                   start_new_session=True)   # its own group: a stop reaches demRun too
        self.running[run_id] = (process, time.time(), np.asarray(unit_point, float), log)
        shown = ", ".join(f"{p.name} {v:.4g}" for p, v in zip(self.s.parameters, values.values()))
        _say(f"{self.s.name}: run {run_id} started ({why}): {shown}")

    def resume_points(self):
        """Runs with a case copy and parameters but no row in the table: stopped before they
        finished; they go on with their own parameters."""
        out = []
        runs = os.path.join(self.folder, "runs")
        done = self.table.ids()
        for name in sorted(os.listdir(runs)):
            marker = os.path.join(runs, name, RUN_PARAMETERS)
            if name.startswith("run") and os.path.exists(marker):
                m = json.load(open(marker))
                if m["run"] not in done:
                    out.append((m["run"], np.array(m["unit"]), m["why"]))
        return out

    def collect(self, run_id, process, start, unit_point, log):
        log.close()
        folder = self.run_folder(run_id)
        log_path = os.path.join(folder, RUN_LOG)
        # a run stopped and continued counts the time of its earlier calls too
        seconds = time.time() - start + _seconds_before(folder)
        row = {"run": run_id}
        for p, u in zip(self.s.parameters, unit_point):
            row[p.keyword] = f"{p.from_unit(u):.10g}"
        message = ""
        results = {}
        rc = process.returncode
        if rc != 0:
            tail = open(log_path, errors="replace").read().strip().splitlines()[-8:]
            if rc == 2 and any("is in use by process" in line for line in tail):
                # The case lock of the tutorials: a run of an earlier call, killed without its
                # simulations (SIGKILL), still goes on in this folder.  Not a result: not recorded.
                raise StopCalibration(f"stage '{self.s.name}': run {run_id}'s case {folder} is in use by another "
                                      f"process ({' '.join(tail[-1:])}): an earlier diefillCalibrate's simulation "
                                      f"still running? Wait for it or end it, then run again")
            message = f"Allrun exited with status {rc}; log: {log_path}; last lines: " + " | ".join(tail)
        else:
            path = os.path.join(folder, "postProcessing", "results.json")
            try:
                results = json.load(open(path))
            except (OSError, ValueError) as e:
                message = f"no readable {path} ({e}); log: {log_path}"
        scalars = {}
        for k, v in results.items():
            value = v.get("value") if isinstance(v, dict) else v
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                scalars[k] = value
        if not message:
            for t in self.s.targets:
                if t.key not in results:
                    raise InputError(f"{self.c.path}: stages/{self.s.name}/targets/{t.key}: the case does not report "
                                     f"'{t.key}' (run {run_id}'s {path} has: {', '.join(sorted(scalars))})")
                if t.key not in scalars or not math.isfinite(scalars[t.key]):
                    message = (f"results.json gives no number for '{t.key}' ({results[t.key]!r}): the test did not "
                               f"reach it at these parameters; log: {log_path}")
                    break
        status = "failed" if message else "ok"
        row["status"] = status
        for t in self.s.targets:
            row[t.key] = scalars.get(t.key)
        row["misfit"] = f"{self.misfit([scalars[t.key] for t in self.s.targets]):.6g}" if status == "ok" else ""
        row["seconds"] = f"{seconds:.1f}"
        for k, v in scalars.items():
            row.setdefault(k, v)
        row["folder"] = os.path.relpath(folder, self.folder)
        row["message"] = message
        self.table.add(row)
        return row

    # ---- the loop ---------------------------------------------------------------------------
    def converged(self):
        """(converged, agrees, largest expected improvement, the improvement the scatter alone
        explains).  Converged: a run agrees with every target within tolerance x sigma, and no
        point promises an improvement of the misfit above eiTolerance, or above what the
        simulations' own scatter makes of the misfit (sum of the fitted scatter^2 / sigma^2: a DEM
        result moves by a fraction of a degree under a small change of the inputs, and a smaller
        improvement could not be told from it); with 'choose nearest', also not while
        nearest_point() offers a run nearer the case's values than every run that agrees."""
        rows, x, y = self.finished_ok()
        if not rows:
            return False, False, None, None
        agrees = self.within_tolerance(y[int(np.argmin([self.misfit(v) for v in y]))])
        if not self.s.parameters:
            return agrees, agrees, None, None
        if len(rows) < 2 or len(self.table.rows) < self.s.min_runs:
            return False, agrees, None, None
        s = self.surrogate(x, y)
        settled, ei, scatter_floor = self._settling(x, y, s)
        if settled and self.nearest_point(x, y, s) is not None:
            settled = False             # a run nearer the case's values first (choose nearest)
        return settled, agrees, ei, scatter_floor

    def _settling(self, x, y, surrogate):
        """(settled, largest expected improvement, scatter floor): the best run agrees and no
        point promises more than eiTolerance or the scatter floor."""
        misfits = [self.misfit(v) for v in y]
        k = int(np.argmin(misfits))
        agrees = self.within_tolerance(y[k])
        _, ei = method.propose(surrogate, np.vstack([x, self._failed_points()]), misfits[k], 1,
                               avoid=self._failed_points(), seed=self.c.seed)
        floor = float(sum(m.noise_variance / t.sigma ** 2 for m, t in zip(surrogate.models, self.s.targets)))
        return agrees and ei[0] < max(self.s.ei_tolerance, floor), ei[0], floor

    NEAREST = "nearest agreeing point"

    def nearest_point(self, x, y, surrogate, pending=()):
        """With 'choose nearest': the unit point nearest the case's own values where the surrogate
        expects agreement, when it lies nearer than every run that agrees (by at least 0.05 of the
        ranges) and away from the runs made and running; None otherwise, or once nearestRuns such
        runs have been started.  On a ridge of agreeing values (fewer targets than parameters)
        the expected-improvement proposals may explore only one end of it; this run tries the
        ridge's point nearest the given values."""
        if self.s.choose != "nearest" or not self.s.parameters or len(self._runs_started_as(self.NEAREST)) >= self.s.nearest_runs:
            return None
        start = self.start_unit()
        agree = [i for i in range(len(y)) if self.within_tolerance(y[i])]
        nearest_run = min((float(np.sqrt(np.sum((x[i] - start) ** 2))) for i in agree), default=np.inf)
        q = method.nearest_agreeing(surrogate, start, self.s.tolerance, seed=self.c.seed)
        if q is None or float(np.sqrt(np.sum((q - start) ** 2))) > nearest_run - 0.05:
            return None
        made = np.vstack([x, self._failed_points()] + ([np.asarray(pending).reshape(-1, len(start))] if len(pending) else []))
        if len(made) and float(np.sqrt(((made - q) ** 2).sum(1)).min()) < 0.02:
            return None
        return q

    def converged_apart_from_nearest(self, x, y, surrogate):
        """converged()'s test without the nearest-agreeing run."""
        return len(self.table.rows) >= self.s.min_runs and self._settling(x, y, surrogate)[0]

    def _marker_why(self, run_id):
        try:
            return json.load(open(os.path.join(self.run_folder(run_id), RUN_PARAMETERS))).get("why")
        except (OSError, ValueError):
            return None

    def _runs_started_as(self, why):
        """Ids of the runs (finished or not) whose parameters file gives `why` as the reason."""
        runs = os.path.join(self.folder, "runs")
        ids = [int(n[3:]) for n in sorted(os.listdir(runs)) if re.fullmatch(r"run\d+", n)] if os.path.isdir(runs) else []
        return [i for i in ids if self._marker_why(i) == why]

    def _stop_children(self, signum):
        for process, *_ in self.running.values():
            try:
                os.killpg(process.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass

    def run(self, stop_after=None):
        """Runs the stage until it converges or maxRuns are finished.  Returns 'converged',
        'budget' or 'stopped' (stop_after runs finished in this call, or a signal)."""
        self.open()
        self.finished_here = 0
        call_started = time.time()
        resume = self.resume_points()
        previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}

        def on_signal(signum, frame):
            self.stopping = True
            _say(f"{self.s.name}: stopping (signal {signum}): the runs in progress write their restart files; "
                 f"run diefillCalibrate again to continue them")
            self._stop_children(signum)
        for s in previous:
            signal.signal(s, on_signal)
        outcome = None          # set once no more runs are to be started
        checked_at = -1
        try:
            while True:
                total = len(self.table.rows)
                if outcome is None and total != checked_at and not resume:
                    checked_at = total
                    if self.converged()[0]:
                        outcome = "converged"
                if outcome is None and total >= self.s.max_runs:
                    self.agrees = self.converged()[1]
                    outcome = "budget"
                if outcome is None and (self.stopping or (stop_after is not None and self.finished_here >= stop_after)):
                    outcome = "stopped"
                if outcome is None:
                    while len(self.running) < self.c.runs_in_parallel and total + len(self.running) < self.s.max_runs:
                        if resume:
                            run_id, point, why = resume.pop(0)
                        else:
                            used = self.table.ids() | set(self.running)
                            # the design's runs first, then the surrogate's
                            missing = [i for i in range(1, self.s.first_runs + 1) if i not in used]
                            run_id = missing[0] if missing else max(used | {0}) + 1
                            point, why = self.next_point(run_id)
                            if point is None:       # only a run that waits on a running one is left
                                break
                        if self.stopping:           # a signal came while the point was chosen
                            break
                        self.launch(run_id, point, why)
                if not self.running:
                    if outcome is None:
                        continue
                    return outcome
                for run_id in self._wait():
                    process, start, point, log = self.running.pop(run_id)
                    if self.stopping and process.returncode != 0:
                        log.close()
                        self._add_seconds_before(run_id, time.time() - start)
                        continue                       # stopped by us: continued next time, not recorded
                    row = self.collect(run_id, process, start, point, log)
                    self.finished_here += 1
                    self._progress(row)
                    if row["status"] != "ok":
                        _say(f"{self.s.name}: run {run_id} FAILED: {row['message']}")
                        if self.c.on_failure == "stop":
                            raise StopCalibration(f"stage '{self.s.name}': run {run_id} failed and onFailure is "
                                                  f"'stop': {row['message']}")
        except BaseException as e:
            self._stop_children(signal.SIGTERM)
            for run_id, (process, start, *_) in list(self.running.items()):
                process.wait()
                self._add_seconds_before(run_id, time.time() - start)
            outcome = f"error ({type(e).__name__})"
            raise
        finally:
            for s, h in previous.items():
                signal.signal(s, h)
            self._record_call(call_started, outcome or "stopped")

    def _add_seconds_before(self, run_id, seconds):
        """A run stopped before it finished: its time so far goes into its parameters file, so
        that the table's 'seconds' of the run, once it finishes, counts every call's share."""
        marker = os.path.join(self.run_folder(run_id), RUN_PARAMETERS)
        try:
            m = json.load(open(marker))
        except (OSError, ValueError):
            return
        m["secondsBefore"] = float(m.get("secondsBefore", 0.0)) + seconds
        _write_atomically(marker, json.dumps(m, indent=1))

    def _record_call(self, started, outcome):
        """Appends this call to calls.csv: the stage's wall time over interrupted calls."""
        path = os.path.join(self.folder, CALLS)
        ended = time.time()
        new = not os.path.exists(path)
        with open(path, "a", newline="") as f:
            w = csv.writer(f)
            if new:
                w.writerow(["started", "ended", "seconds", "outcome", "runsFinished"])
            w.writerow([_utc(started), _utc(ended), f"{ended - started:.1f}", outcome, self.finished_here])

    def wall_seconds(self):
        """The stage's wall time over every call recorded in calls.csv."""
        path = os.path.join(self.folder, CALLS)
        if not os.path.exists(path):
            return 0.0
        with open(path, newline="") as f:
            return float(sum(float(r["seconds"]) for r in csv.DictReader(f)))

    def _wait(self):
        while True:
            finished = [k for k, (p, *_) in self.running.items() if p.poll() is not None]
            if finished:
                return finished
            time.sleep(0.2)

    def _progress(self, row):
        rows, x, y = self.finished_ok()
        n = len(self.table.rows)
        best = min(rows, key=lambda r: float(r["misfit"])) if rows else None
        values = ", ".join(f"{t.key} {float(row[t.key]):.4g}" for t in self.s.targets) if row["status"] == "ok" else "failed"
        seconds = [float(r["seconds"]) for r in self.table.rows]
        left = self.s.max_runs - n
        eta = np.mean(seconds) * math.ceil(left / self.c.runs_in_parallel) if seconds else 0
        text = f"{self.s.name}: run {row['run']} done, {n} of at most {self.s.max_runs} finished: {values}"
        if row["status"] == "ok":
            text += f" (misfit {float(row['misfit']):.3g})"
        if best:
            text += f"; best so far run {best['run']} (misfit {float(best['misfit']):.3g})"
        text += f"; {float(row['seconds']):.0f} s; at most {_duration(eta)} left"
        _say(text)


def _utc(t):
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(t))


def _seconds_before(folder):
    try:
        return float(json.load(open(os.path.join(folder, RUN_PARAMETERS))).get("secondsBefore", 0.0))
    except (OSError, ValueError):
        return 0.0


def _duration(seconds):
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
