"""What a stage gives back: the calibrated parameters with their posterior, a demProperties
fragment, plots (response per parameter, samples and the chosen point, convergence)."""
import datetime
import json
import os

import numpy as np

from . import method
from .runner import _write_atomically


def summarise(runner, outcome, wall_seconds):
    """result.json, demPropertiesFragment and the plots of a stage; returns the result dict."""
    s = runner.s
    rows, x, y = runner.finished_ok()
    needed = 2 if s.parameters else 1
    if len(rows) < needed:
        raise ValueError(f"stage '{s.name}': {len(rows)} successful run(s) in {runner.folder}; "
                         + ("the posterior needs at least 2" if s.parameters else "the check run failed")
                         + f" (see the failed runs' messages in {os.path.join(runner.folder, 'runs.csv')})")
    misfits = np.array([runner.misfit(v) for v in y])
    k = choose(runner, x, y)
    if s.parameters:
        surrogate = runner.surrogate(x, y)
        post = method.posterior(surrogate, seed=runner.c.seed)
    else:
        surrogate, post = None, {"mean": [], "std": [], "quantiles": [], "ess": 0.0}
    chosen = {p.keyword: float(p.from_unit(x[k, i])) for i, p in enumerate(s.parameters)}
    width = np.array([p.high - p.low for p in s.parameters])
    result = {
        "stage": s.name,
        "case": s.case,
        "setting": s.setting,
        "outcome": outcome,
        "runs": len(runner.table.rows),
        "failedRuns": sum(r["status"] != "ok" for r in runner.table.rows),
        "simulationSeconds": float(sum(float(r["seconds"]) for r in runner.table.rows)),
        "wallSecondsThisCall": wall_seconds,
        "wallSeconds": runner.wall_seconds(),       # every call on this stage (calls.csv)
        "chosenRun": int(rows[k]["run"]),
        "choose": s.choose,
        "start": {p.keyword: runner.start_values()[i] for i, p in enumerate(s.parameters)},
        "chosen": chosen,
        "chosenTargets": {t.key: float(y[k, j]) for j, t in enumerate(s.targets)},
        "targets": {t.key: {"value": t.value, "sigma": t.sigma} for t in s.targets},
        "chosenMisfit": float(misfits[k]),
        "posterior": {p.keyword: {"mean": float(p.from_unit(post["mean"][i])), "std": float(post["std"][i] * width[i]),
                                  "q2.5": float(p.from_unit(post["quantiles"][i][0])),
                                  "q97.5": float(p.from_unit(post["quantiles"][i][1])),
                                  "range": [p.low, p.high]} for i, p in enumerate(s.parameters)},
        "posteriorEffectiveSamples": post["ess"],
        "fixed": {**runner.carried, **s.fixed},
        "surrogateScatter": {t.key: float(np.sqrt(m.noise_variance)) for t, m in zip(s.targets, surrogate.models)}
        if surrogate else {},
        "agrees": bool(runner.within_tolerance(y[k])),
    }
    _write_atomically(os.path.join(runner.folder, "result.json"), json.dumps(result, indent=1))
    if not s.parameters:
        return result
    _write_atomically(os.path.join(runner.folder, "demPropertiesFragment"), fragment(result))
    try:
        plots(runner, surrogate, post, x, y, k)
    except Exception as e:  # a plot must not lose a calibration that took hours
        print(f"{s.name}: plots not written ({e})", flush=True)
    return result


def choose(runner, x, y):
    """Index of the chosen run among the good ones: 'best' the smallest chi2; 'nearest' (the
    default) of the runs that agree with every target within tolerance x sigma the one nearest
    to the case's own values (distance in range units; with fewer targets than parameters the
    agreeing runs lie along a ridge, and this keeps the calibrated set as close to the given one
    as the data allow), the smallest chi2 when none agrees."""
    s = runner.s
    misfits = np.array([runner.misfit(v) for v in y])
    best = int(np.argmin(misfits))
    if s.choose == "best" or not s.parameters:
        return best
    agree = [i for i in range(len(y)) if runner.within_tolerance(y[i])]
    if not agree:
        return best
    start = runner.start_unit()
    return min(agree, key=lambda i: float(np.sum((x[i] - start) ** 2)))


def fragment(result):
    """A stage's calibrated values as demProperties text, nested as their keyword paths."""
    notes = {k: f"posterior {p['mean']:.4g} +- {p['std']:.2g}" for k, p in result["posterior"].items()}
    header = (f"// diefillCalibrate, stage '{result['stage']}' ({result['setting']} setting, "
              f"{result['runs']} runs, {datetime.date.today().isoformat()}): run {result['chosenRun']}, "
              + ", ".join(f"{k} {v:.4g}" for k, v in result["chosenTargets"].items())
              + " (targets: " + ", ".join(f"{k} {t['value']:g} +- {t['sigma']:g}" for k, t in result["targets"].items()) + ")")
    return values_text(result["chosen"], notes, [header])


def values_text(values, notes, header):
    """Keyword-path values as nested demProperties text, each with its note as a comment."""
    tree = {}
    for keyword, value in values.items():
        node = tree
        names = keyword.split("/")
        for n in names[:-1]:
            node = node.setdefault(n, {})
        node[names[-1]] = (value, notes.get(keyword, ""))
    lines = list(header) + ["// Paste into constant/demProperties (the entries replace the ones of the same names)."]

    def write(node, indent):
        for name, value in node.items():
            if isinstance(value, dict):
                if all(not isinstance(v, dict) for v in value.values()):
                    inner = " ".join(f"{n} {v[0]:.4g};" for n, v in value.items())
                    notes = "; ".join(f"{n}: {v[1]}" for n, v in value.items())
                    lines.append(f"{' ' * indent}{name} {{ {inner} }}   // {notes}")
                else:
                    lines.append(f"{' ' * indent}{name}")
                    lines.append(f"{' ' * indent}{{")
                    write(value, indent + 4)
                    lines.append(f"{' ' * indent}}}")
            else:
                lines.append(f"{' ' * indent}{name} {value[0]:.4g};   // {value[1]}")
    write(tree, 0)
    return "\n".join(lines) + "\n"


def history(runner, x_all_rows):
    """Posterior mean and std per parameter after each finished run from the end of the
    design on (refitted from the table: nothing is stored during the loop)."""
    s = runner.s
    out = []
    ok_rows, x, y = runner.finished_ok()
    order = [int(r["run"]) for r in ok_rows]
    for n in range(max(2, min(s.first_runs, len(order))), len(order) + 1):
        sur = runner.surrogate(x[:n], y[:n])
        post = method.posterior(sur, rounds=2, n=2048, seed=runner.c.seed)
        out.append((n, post["mean"], post["std"]))
    return out


def plots(runner, surrogate, post, x, y, k):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    s = runner.s
    d, m = len(s.parameters), len(s.targets)
    phys = np.array([[p.from_unit(u) for p, u in zip(s.parameters, row)] for row in x])
    start = runner.start_values()

    # response of each target to each parameter (the others at the chosen run's values)
    fig, axes = plt.subplots(m, d, figsize=(4.2 * d, 3.4 * m), squeeze=False)
    for j, t in enumerate(s.targets):
        for i, p in enumerate(s.parameters):
            ax = axes[j][i]
            line = np.repeat(x[k][None], 200, 0)
            line[:, i] = np.linspace(0, 1, 200)
            mean, var = surrogate.predict(line)
            u = p.from_unit(line[:, i])
            ax.fill_between(u, mean[:, j] - 2 * np.sqrt(var[:, j]), mean[:, j] + 2 * np.sqrt(var[:, j]),
                            color="C0", alpha=0.2, label="surrogate ± 2 sd" + (" (others at chosen)" if d > 1 else ""))
            ax.plot(u, mean[:, j], color="C0")
            ax.axhspan(t.value - t.sigma, t.value + t.sigma, color="C2", alpha=0.2, label="target ± sigma")
            ax.scatter(phys[:, i], y[:, j], color="k", s=14, label="runs" + (" (other parameters as they were)" if d > 1 else ""))
            ax.scatter([phys[k, i]], [y[k, j]], color="C3", marker="*", s=120, label="chosen", zorder=5)
            ax.set_xlabel(p.keyword)
            ax.set_ylabel(t.key)
            if i == 0 and j == 0:
                ax.legend(fontsize=7)
    fig.suptitle(f"{s.name}: response of each target to each parameter")
    fig.tight_layout()
    fig.savefig(os.path.join(runner.folder, "response.png"), dpi=110)
    plt.close(fig)

    # samples, posterior and the chosen point
    samples = np.array([[p.from_unit(u) for p, u in zip(s.parameters, row)] for row in post["samples"]])
    w = post["weights"]
    if d == 1:
        fig, ax = plt.subplots(figsize=(6, 4))
        order = np.argsort(samples[:, 0])
        density = w[order] / max(w.max(), 1e-300)
        ax.plot(samples[order, 0], density, color="C0", label="posterior (scaled)")
        ax.scatter(phys[:, 0], np.zeros(len(phys)), color="k", label="runs")
        for n, v in enumerate(phys[:, 0]):
            ax.annotate(str(n + 1), (v, 0.02), fontsize=7)
        ax.axvline(phys[k, 0], color="C3", label="chosen")
        ax.axvline(start[0], color="C1", ls="--", label="the case's own value")
        ax.set_xlabel(s.parameters[0].keyword)
        ax.legend(fontsize=8)
    else:
        fig, axes = plt.subplots(d - 1, d - 1, figsize=(4.2 * (d - 1), 4.0 * (d - 1)), squeeze=False)
        top = np.argsort(w)[-2000:]
        misfit = np.array([runner.misfit(v) for v in y])
        for a in range(1, d):
            for b in range(d - 1):
                ax = axes[a - 1][b]
                if b >= a:
                    ax.axis("off")
                    continue
                ax.scatter(samples[top, b], samples[top, a], c=w[top], cmap="Blues", s=4, label="posterior samples")
                sc = ax.scatter(phys[:, b], phys[:, a], c=np.log10(misfit + 1e-3), cmap="viridis_r", edgecolor="k",
                                s=30, label="runs (colour: log10 misfit)")
                ax.scatter([phys[k, b]], [phys[k, a]], color="C3", marker="*", s=160, label="chosen")
                ax.scatter([start[b]], [start[a]], color="C1", marker="x", s=80, label="the case's own values")
                ax.set_xlim(s.parameters[b].low, s.parameters[b].high)
                ax.set_ylim(s.parameters[a].low, s.parameters[a].high)
                ax.set_xlabel(s.parameters[b].keyword)
                ax.set_ylabel(s.parameters[a].keyword)
                if a == 1 and b == 0:
                    ax.legend(fontsize=7)
                    fig.colorbar(sc, ax=ax)
    fig.suptitle(f"{s.name}: runs, posterior and the chosen point")
    fig.tight_layout()
    fig.savefig(os.path.join(runner.folder, "samples.png"), dpi=110)
    plt.close(fig)

    # convergence: best misfit, posterior mean +- sd per parameter
    misfit_all = [float(r["misfit"]) if r["status"] == "ok" else np.nan for r in runner.table.rows]
    best = np.fmin.accumulate(np.nan_to_num(misfit_all, nan=np.inf))
    hist = history(runner, None)
    fig, axes = plt.subplots(1, d + 1, figsize=(4.2 * (d + 1), 3.4), squeeze=False)
    ax = axes[0][0]
    ax.semilogy(range(1, len(misfit_all) + 1), np.maximum(misfit_all, 1e-4), "o", color="k", ms=3, label="run")
    ax.semilogy(range(1, len(best) + 1), np.maximum(best, 1e-4), color="C3", label="best so far")
    ax.axhline(len(s.targets) * s.tolerance ** 2, color="C2", ls="--", label="tolerance")
    ax.axvline(s.first_runs + 0.5, color="0.6", ls=":", label="end of the first sample")
    ax.set_xlabel("run")
    ax.set_ylabel("misfit chi2")
    ax.legend(fontsize=7)
    for i, p in enumerate(s.parameters):
        ax = axes[0][i + 1]
        n = np.array([h[0] for h in hist])
        mean = np.array([p.from_unit(h[1][i]) for h in hist])
        sd = np.array([h[2][i] * (p.high - p.low) for h in hist])
        ax.fill_between(n, mean - sd, mean + sd, color="C0", alpha=0.3, label="posterior mean ± sd")
        ax.plot(n, mean, color="C0")
        ax.set_ylim(p.low, p.high)
        ax.set_xlabel("successful runs")
        ax.set_ylabel(p.keyword)
        ax.legend(fontsize=7)
    fig.suptitle(f"{s.name}: convergence")
    fig.tight_layout()
    fig.savefig(os.path.join(runner.folder, "convergence.png"), dpi=110)
    plt.close(fig)
