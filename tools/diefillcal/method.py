"""The calibration method: a space-filling first sample, one Gaussian-process surrogate
per target (Matern 5/2, one length scale per parameter, hyperparameters by the marginal
likelihood), expected improvement of the misfit to propose the next runs, and a posterior
over the parameter box from the surrogates.

Everything works on the unit cube [0, 1]^d; the caller maps it to the parameter ranges.
The misfit of a run is chi2 = sum_j ((y_j - target_j) / sigma_j)^2."""
import numpy as np
from scipy import optimize, stats
from scipy.linalg import cho_factor, cho_solve, solve_triangular

SQRT5 = np.sqrt(5.0)


def initial_design(n, dim, seed):
    """n points of a Latin hypercube in [0, 1]^dim, spread by scipy's centred-discrepancy
    optimisation; the same n, dim and seed give the same points (a restart depends on it)."""
    sampler = stats.qmc.LatinHypercube(d=dim, seed=seed, optimization="random-cd")
    return sampler.random(n)


def _matern52(a, b, lengths):
    r = np.sqrt(np.maximum(((a[:, None, :] - b[None, :, :]) / lengths) ** 2, 0.0).sum(-1))
    return (1.0 + SQRT5 * r + 5.0 / 3.0 * r * r) * np.exp(-SQRT5 * r)


class GaussianProcess:
    """A GP regression of one scalar response on the unit cube.  The response is centred
    and scaled; hyperparameters (length scales, signal and noise variance) maximise the log
    marginal likelihood from a few starts.  The noise term stands for the scatter of a DEM
    result under a small change of the inputs (a different packing, another contact first)."""

    LENGTH_BOUNDS = (0.05, 20.0)
    SIGNAL_BOUNDS = (0.05, 20.0)
    NOISE_BOUNDS = (1e-6, 0.3)

    def __init__(self, x, y, seed=0):
        self.x = np.asarray(x, float)
        y = np.asarray(y, float)
        self.offset = float(np.mean(y))
        self.scale = float(np.std(y)) or 1.0
        self.y = (y - self.offset) / self.scale
        self.dim = self.x.shape[1]
        self._fit(seed)

    def _unpack(self, theta):
        return np.exp(theta[:self.dim]), np.exp(theta[self.dim]), np.exp(theta[self.dim + 1])

    def _negative_log_likelihood(self, theta):
        lengths, signal, noise = self._unpack(theta)
        k = signal * _matern52(self.x, self.x, lengths) + (noise + 1e-10) * np.eye(len(self.x))
        try:
            c = cho_factor(k, lower=True)
        except np.linalg.LinAlgError:
            return 1e10
        alpha = cho_solve(c, self.y)
        return 0.5 * self.y @ alpha + np.sum(np.log(np.diag(c[0]))) + 0.5 * len(self.y) * np.log(2 * np.pi)

    def _fit(self, seed):
        bounds = ([np.log(self.LENGTH_BOUNDS)] * self.dim + [np.log(self.SIGNAL_BOUNDS), np.log(self.NOISE_BOUNDS)])
        rng = np.random.default_rng(seed)
        starts = [np.array([np.log(0.5)] * self.dim + [0.0, np.log(1e-3)])]
        starts += [np.array([rng.uniform(*b) for b in bounds]) for _ in range(4)]
        best = None
        for start in starts:
            r = optimize.minimize(self._negative_log_likelihood, start, method="L-BFGS-B", bounds=bounds)
            if best is None or r.fun < best.fun:
                best = r
        self.theta = best.x
        self.lengths, self.signal, self.noise = self._unpack(best.x)
        self._condition(self.x, self.y)

    def _condition(self, x, y):
        k = self.signal * _matern52(x, x, self.lengths) + (self.noise + 1e-10) * np.eye(len(x))
        self._chol = np.linalg.cholesky(k)
        self._alpha = cho_solve((self._chol, True), y)
        self._x_train = x
        self._y_train = y

    def with_believed(self, x_new):
        """A copy conditioned also on its own mean at x_new (the 'kriging believer' for
        points that are being run): the next proposal keeps away from them."""
        other = object.__new__(GaussianProcess)
        other.__dict__.update(self.__dict__)
        x_new = np.atleast_2d(x_new)
        mean, _ = self.predict(x_new)
        y_all = np.concatenate([self._y_train, (mean - self.offset) / self.scale])
        other._condition(np.vstack([self._x_train, x_new]), y_all)
        return other

    def predict(self, xs):
        """Mean and variance of the response (without the noise) at the points xs."""
        xs = np.atleast_2d(xs)
        ks = self.signal * _matern52(xs, self._x_train, self.lengths)
        mean = ks @ self._alpha
        v = solve_triangular(self._chol, ks.T, lower=True)
        var = np.maximum(self.signal - np.sum(v * v, axis=0), 1e-12)
        return self.offset + self.scale * mean, var * self.scale ** 2

    @property
    def noise_variance(self):
        """The fitted scatter of the response, in its own units squared."""
        return self.noise * self.scale ** 2


class Surrogate:
    """One GP per target and the misfit they predict."""

    def __init__(self, x, responses, targets, sigmas, seed=0):
        self.targets = np.asarray(targets, float)
        self.sigmas = np.asarray(sigmas, float)
        self.models = [GaussianProcess(x, responses[:, j], seed + j) for j in range(responses.shape[1])]
        self.dim = np.asarray(x).shape[1]

    def believe(self, x_pending):
        if len(x_pending) == 0:
            return self
        other = object.__new__(Surrogate)
        other.__dict__.update(self.__dict__)
        other.models = [m.with_believed(x_pending) for m in self.models]
        return other

    def predict(self, xs):
        """Means and variances, shape (n points, n targets)."""
        out = [m.predict(xs) for m in self.models]
        return np.stack([o[0] for o in out], 1), np.stack([o[1] for o in out], 1)

    def expected_improvement(self, xs, best_misfit, draws=256, seed=0):
        """E[max(0, best - chi2)] over the surrogates' uncertainty, by fixed normal draws
        (the same for every point, so that the comparison between points is smooth)."""
        mean, var = self.predict(xs)
        z = np.random.default_rng(seed).standard_normal((draws, 1, len(self.targets)))
        y = mean[None] + np.sqrt(var)[None] * z
        chi2 = np.sum(((y - self.targets) / self.sigmas) ** 2, axis=2)
        return np.mean(np.maximum(best_misfit - chi2, 0.0), axis=0)

    def log_likelihood(self, xs):
        """log p(measured targets | parameters): the measurement's sigma, the surrogate's
        uncertainty and the simulation's fitted scatter added as variances."""
        mean, var = self.predict(xs)
        scatter = np.array([m.noise_variance for m in self.models])
        total = self.sigmas ** 2 + var + scatter
        return -0.5 * np.sum((mean - self.targets) ** 2 / total + np.log(total), axis=1)


def propose(surrogate, x_done, best_misfit, count, avoid=(), seed=0, candidates=4096):
    """`count` new points in the unit cube with the largest expected improvement, each
    chosen with the ones before it (and x_done's pending runs, already in the surrogate)
    believed.  Candidates: a Sobol sample plus small steps around the best points so far;
    none within `too_close` of a run made or of a failed one (`avoid`)."""
    dim = surrogate.dim
    rng = np.random.default_rng(seed)
    pool = stats.qmc.Sobol(d=dim, seed=seed).random(candidates)
    x_done = np.atleast_2d(np.asarray(x_done, float)) if len(x_done) else np.zeros((0, dim))
    if len(x_done):
        mean, _ = surrogate.predict(x_done)
        order = np.argsort(np.sum(((mean - surrogate.targets) / surrogate.sigmas) ** 2, axis=1))[:3]
        for k in order:
            pool = np.vstack([pool, np.clip(x_done[k] + rng.normal(0, 0.05, (256, dim)), 0, 1)])
    chosen = []
    eis = []
    current = surrogate
    too_close = 1e-3
    avoid = np.atleast_2d(np.asarray(avoid, float)) if len(avoid) else np.zeros((0, dim))
    for _ in range(count):
        ei = current.expected_improvement(pool, best_misfit, seed=seed)
        blocked = np.zeros(len(pool), bool)
        for ref, radius in ((x_done, too_close), (np.array(chosen).reshape(-1, dim), too_close),
                            (avoid, 0.05 * np.sqrt(dim))):
            if len(ref):
                d = np.sqrt(((pool[:, None, :] - ref[None]) ** 2).sum(-1)).min(1)
                blocked |= d < radius
        ei[blocked] = -1.0
        k = int(np.argmax(ei))
        chosen.append(pool[k])
        eis.append(float(ei[k]))
        current = current.believe(pool[k][None])
    return np.array(chosen), eis


def nearest_agreeing(surrogate, start, tolerance, seed=0, candidates=8192):
    """The unit point nearest `start` where the surrogate is sure enough of agreement: every
    target's predicted mean within half of tolerance x sigma of its value, and its predictive
    sd (the simulations' scatter included) under half of tolerance x sigma, so that a run there
    is likely to agree.  Candidates: a Sobol sample and points spread around `start`.  Returns
    the point, or None when no candidate qualifies."""
    dim = surrogate.dim
    start = np.asarray(start, float)
    rng = np.random.default_rng(seed)
    pool = np.vstack([stats.qmc.Sobol(d=dim, seed=seed).random(candidates),
                      np.clip(start + rng.normal(0.0, 0.15, (candidates // 2, dim)), 0.0, 1.0)])
    mean, var = surrogate.predict(pool)
    scatter = np.array([m.noise_variance for m in surrogate.models])
    half = 0.5 * tolerance * surrogate.sigmas
    sure = np.all((np.abs(mean - surrogate.targets) <= half) & (np.sqrt(var + scatter) <= half), axis=1)
    if not np.any(sure):
        return None
    distance = np.sum((pool - start) ** 2, axis=1)
    distance[~sure] = np.inf
    return pool[int(np.argmin(distance))]


def posterior(surrogate, rounds=3, n=8192, seed=0):
    """Weighted samples of the posterior over the unit cube (uniform prior), from the
    surrogate's likelihood: mean, standard deviation and 2.5/97.5 % quantiles per parameter,
    the effective sample size, and the samples with their weights.  When the likelihood is
    narrow, later rounds sample a box around where the weight lies (the prior is uniform, so
    a sub-box needs no correction as long as it holds the weight)."""
    dim = surrogate.dim
    low, high = np.zeros(dim), np.ones(dim)
    for r in range(rounds):
        xs = low + (high - low) * stats.qmc.Sobol(d=dim, seed=seed + r).random(n)
        logl = surrogate.log_likelihood(xs)
        w = np.exp(logl - logl.max())
        w /= w.sum()
        ess = 1.0 / np.sum(w * w)
        mean = w @ xs
        std = np.sqrt(np.maximum(w @ (xs - mean) ** 2, 0.0))
        if ess > 400 or r == rounds - 1:
            break
        # a box that holds the weight (6 standard deviations each way, at least one grid cell)
        span = np.maximum(6 * std, 4.0 / n ** (1.0 / dim))
        low, high = np.clip(mean - span, 0, 1), np.clip(mean + span, 0, 1)
    quantiles = []
    for k in range(dim):
        order = np.argsort(xs[:, k])
        cw = np.cumsum(w[order])
        quantiles.append((float(xs[order, k][np.searchsorted(cw, 0.025)]),
                          float(xs[order, k][min(np.searchsorted(cw, 0.975), len(cw) - 1)])))
    return {"mean": mean, "std": std, "quantiles": quantiles, "ess": float(ess), "samples": xs, "weights": w}
