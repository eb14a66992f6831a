"""An iterative Bayesian filter in the manner of GrainLearning (Cheng et al. 2019; the
'Calibration' notes in ../shared/notes), kept here to compare run counts with the GP surrogate
(tests/calibration/compareMethods.py, docs/calibration.md): not used by diefillCalibrate.

Each iteration runs N simulations.  The first N come from a Sobol sample of the box; the
likelihood of each is Gaussian in the targets with the measurement's sigma, tempered (raised to
beta <= 1) so that the effective sample size is ess_target x N, as GrainLearning scales its
observation covariance to reach a target ESS.  The next N are drawn from the weighted samples
smoothed by a Gaussian kernel (GrainLearning fits a variational Gaussian mixture with scikit-learn,
which is not a Debian package here; one kernel per sample is the mixture's limit).  It ends when
the untempered likelihood (beta = 1) keeps the target ESS, i.e. the last iteration's samples
represent the posterior, and one run agrees with every target within tolerance x sigma."""
import numpy as np
from scipy import stats


def _ess(w):
    return 1.0 / np.sum(w * w)


def _weights(logl, beta):
    a = beta * logl
    w = np.exp(a - a.max())
    return w / w.sum()


def _temper(logl, ess_wanted):
    """The largest beta in (0, 1] whose weights keep ess_wanted samples."""
    if _ess(_weights(logl, 1.0)) >= ess_wanted:
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _ess(_weights(logl, mid)) >= ess_wanted:
            lo = mid
        else:
            hi = mid
    return max(lo, 1e-12)


def calibrate(simulate, dim, targets, sigmas, per_iteration=8, ess_target=0.3, max_runs=80, tolerance=1.0, seed=1):
    """simulate(points in the unit cube, shape (n, dim)) -> responses (n, n targets).
    Returns the dictionary: runs, iterations, mean, std (unit cube), converged, history."""
    targets, sigmas = np.asarray(targets, float), np.asarray(sigmas, float)
    rng = np.random.default_rng(seed)
    x = stats.qmc.Sobol(d=dim, seed=seed).random(per_iteration)
    runs, history = 0, []
    best_agrees = False
    while True:
        y = simulate(x)
        runs += len(x)
        logl = -0.5 * np.sum(((y - targets) / sigmas) ** 2, axis=1)
        best_agrees |= bool(np.any(np.all(np.abs(y - targets) <= tolerance * sigmas, axis=1)))
        beta = _temper(logl, ess_target * len(x))
        w = _weights(logl, beta)
        mean = w @ x
        std = np.sqrt(np.maximum(w @ (x - mean) ** 2, 1e-18))
        history.append({"runs": runs, "beta": beta, "mean": mean, "std": std})
        if (beta >= 1.0 and best_agrees) or runs + per_iteration > max_runs:
            return {"runs": runs, "iterations": len(history), "mean": mean, "std": std,
                    "converged": beta >= 1.0 and best_agrees, "history": history}
        # resample from the weighted samples, smoothed by a Gaussian kernel (Silverman's width)
        cov = np.cov(x.T, aweights=w).reshape(dim, dim) + 1e-10 * np.eye(dim)
        factor = (4.0 / ((dim + 2) * len(x))) ** (2.0 / (dim + 4))
        picks = rng.choice(len(x), size=per_iteration, p=w)
        new = x[picks] + rng.multivariate_normal(np.zeros(dim), factor * cov, size=per_iteration)
        x = np.abs(new) % 2.0                 # reflected into [0, 1]
        x = np.where(x > 1.0, 2.0 - x, x)
