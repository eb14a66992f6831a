"""Run counts of the two calibration methods on functions with known answers: diefillCalibrate's
GP surrogate with expected improvement (the same design, stopping rule and posterior as the tool)
and the GrainLearning-style iterative Bayesian filter (tools/diefillcal/bayesfilter.py).

    compareMethods.py ROOT [-seeds N]

For each function and seed: the runs until the method stops, whether a run agrees with every
target within sigma, and the posterior against the exact one (the true function's likelihood on a
fine Sobol sample): |mean - exact mean| / exact sd and sd / exact sd, per parameter (the worst).
The numbers are quoted in docs/calibration.md."""
import os
import sys

import numpy as np
from scipy import stats

ROOT = os.path.abspath(sys.argv[1])
sys.path.insert(0, os.path.join(ROOT, "tools"))
from diefillcal import bayesfilter, method  # noqa: E402

SEEDS = int(sys.argv[sys.argv.index("-seeds") + 1]) if "-seeds" in sys.argv else 5


def scatter(x, size):
    """A deterministic scatter of the response (a DEM result moves by a fraction of a degree
    under a small change of the inputs); the same point gives the same value."""
    if size == 0:
        return np.zeros(len(x))
    keys = np.round(x * 1e9).astype(np.int64)
    return np.array([size * (2 * np.random.default_rng(abs(hash(tuple(k))) % 2**32).random() - 1) for k in keys])


CASES = {
    "1 parameter, 1 target (plate angle vs wall friction)":
        (1, lambda x: (15 + 25 * x[:, 0] + 2 * x[:, 0] ** 2)[:, None], [0.37], [0.5]),
    "2 parameters, 2 targets":
        (2, lambda x: np.stack([12 + 22 * x[:, 0] + 6 * x[:, 1] + 3 * x[:, 0] * x[:, 1],
                                14 + 4 * x[:, 0] + 12 * x[:, 1] + 2 * x[:, 1] ** 2], 1), [0.37, 0.62], [0.3, 0.3]),
    "3 parameters, 3 targets":
        (3, lambda x: np.stack([12 + 20 * x[:, 0] + 5 * x[:, 1] + 2 * x[:, 2],
                                14 + 3 * x[:, 0] + 12 * x[:, 1] + 4 * x[:, 2] * x[:, 1],
                                20 + 2 * x[:, 0] + 3 * x[:, 1] + 10 * x[:, 2] + 3 * x[:, 2] ** 2], 1),
         [0.3, 0.55, 0.7], [0.3, 0.3, 0.3]),
    "2 parameters, 1 target (a ridge: the plate's friction and rolling friction)":
        (2, lambda x: (12 + 22 * x[:, 0] + 6 * x[:, 1])[:, None], [0.5, 0.4], [1.5]),
}


def exact_posterior(f, targets, sigmas, dim):
    xs = stats.qmc.Sobol(d=dim, seed=99).random(2 ** 16)
    logl = -0.5 * np.sum(((f(xs) - targets) / sigmas) ** 2, axis=1)
    w = np.exp(logl - logl.max())
    w /= w.sum()
    mean = w @ xs
    return mean, np.sqrt(w @ (xs - mean) ** 2)


def gp_calibrate(f, dim, targets, sigmas, seed, max_runs=60):
    """diefillCalibrate's loop (runner.StageRunner) without the runs."""
    n0 = max(4, 2 * dim + 2)
    x = method.initial_design(n0, dim, seed)
    y = f(x)
    while True:
        s = method.Surrogate(x, y, targets, sigmas, seed=seed)
        chi2 = np.sum(((y - targets) / sigmas) ** 2, axis=1)
        agrees = bool(np.all(np.abs(y[np.argmin(chi2)] - targets) <= sigmas))
        new, ei = method.propose(s, x, chi2.min(), 1, seed=seed + len(x))
        if (len(x) >= n0 + 1 and agrees and ei[0] < 0.01) or len(x) >= max_runs:
            post = method.posterior(s, seed=seed)
            return {"runs": len(x), "mean": post["mean"], "std": post["std"], "converged": agrees}
        x = np.vstack([x, new])
        y = f(x)


def main():
    print(f"{'function':<75} {'method':<28} {'runs (mean, min-max)':<22} {'agree':<6} "
          f"{'|mean err|/sd':<14} {'sd/exact sd':<12}")
    for name, (dim, g, truth, sigmas) in CASES.items():
        for noise in (0.0, 0.2):
            def f(x, g=g, noise=noise):
                y = g(x)
                return y + scatter(x, noise)[:, None]
            targets = g(np.atleast_2d(truth))[0]
            sigmas_a = np.asarray(sigmas, float)
            exact_mean, exact_sd = exact_posterior(g, targets, sigmas_a, dim)
            per_iteration = 8 if dim <= 2 else 16      # GrainLearning's tutorials (docs/calibration.md)
            for label, run in (("GP + expected improvement", lambda s: gp_calibrate(f, dim, targets, sigmas_a, s)),
                               (f"Bayesian filter, {per_iteration}/iteration",
                                lambda s: bayesfilter.calibrate(f, dim, targets, sigmas_a, per_iteration, seed=s))):
                results = [run(seed) for seed in range(1, SEEDS + 1)]
                runs = [r["runs"] for r in results]
                err = max(float(np.max(np.abs(r["mean"] - exact_mean) / exact_sd)) for r in results)
                ratio = [float(np.max(r["std"] / exact_sd)) for r in results] + \
                        [float(np.min(r["std"] / exact_sd)) for r in results]
                agree = sum(r["converged"] for r in results)
                print(f"{name + (f', scatter {noise}' if noise else ''):<75} {label:<28} "
                      f"{np.mean(runs):5.1f} ({min(runs)}-{max(runs)})        {agree}/{len(results):<4} "
                      f"{err:<14.2f} {min(ratio):.2f}-{max(ratio):.2f}", flush=True)


if __name__ == "__main__":
    main()
