"""The iterative Bayesian filter (tools/diefillcal/bayesfilter.py, GrainLearning's manner) on the
quick inclined plate, for the run count beside diefillCalibrate's on the same problem (the
end-to-end test of tests/calibration: sand-steel friction in 0.25-0.85, the target made by the
case at 0.45, sigma 0.5 deg).  Runs one simulation at a time in WORKDIR.

    compareOnPlate.py ROOT WORKDIR [-target ANGLE] [-perIteration N]

Prints each iteration (runs, tempering, mean and sd) and the result; docs/calibration.md and
tutorials/calibration/README.md quote it."""
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

ROOT, WORK = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
sys.path.insert(0, os.path.join(ROOT, "tools"))
from diefillcal import bayesfilter, casefile  # noqa: E402

TARGET = float(sys.argv[sys.argv.index("-target") + 1]) if "-target" in sys.argv else 25.59
PER_ITERATION = int(sys.argv[sys.argv.index("-perIteration") + 1]) if "-perIteration" in sys.argv else 8
LOW, HIGH, TRUTH, SIGMA = 0.25, 0.85, 0.45, 0.5
count = 0


def plate_angle(friction):
    global count
    count += 1
    case = os.path.join(WORK, f"run{count:03d}")
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "tutorials", "calibration", "inclinedPlate"), case,
                    ignore=shutil.ignore_patterns("dem", "postProcessing", "log.*", "runRecord", "setting", "*.orig"))
    casefile.set_values(os.path.join(case, "constant", "demProperties"), {"interactions/sand-steel/friction": friction})
    subprocess.run(["./Allrun", "-quick"], cwd=case, capture_output=True, env=dict(os.environ, DIEFILL_DIR=ROOT))
    value = json.load(open(os.path.join(case, "postProcessing", "results.json")))["angleAt50PercentSlid"]["value"]
    print(f"  run {count}: friction {friction:.4f} -> {value}", flush=True)
    return 45.0 if value is None else value       # not 50 % slid by the end of the tilt (45 deg)


def simulate(unit_points):
    return np.array([[plate_angle(LOW + (HIGH - LOW) * u[0])] for u in unit_points])


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    start = time.time()
    r = bayesfilter.calibrate(simulate, 1, [TARGET], [SIGMA], per_iteration=PER_ITERATION, max_runs=48)
    for h in r["history"]:
        print(f"iteration: {h['runs']} runs, beta {h['beta']:.3g}, mean {LOW + (HIGH - LOW) * h['mean'][0]:.4f}, "
              f"sd {(HIGH - LOW) * h['std'][0]:.4f}")
    print(f"Bayesian filter, {PER_ITERATION} per iteration: {r['runs']} runs ({r['iterations']} iterations), "
          f"{'settled' if r['converged'] else 'not settled'}; friction {LOW + (HIGH - LOW) * r['mean'][0]:.4f} +- "
          f"{(HIGH - LOW) * r['std'][0]:.4f} (truth {TRUTH}); {time.time() - start:.0f} s")
