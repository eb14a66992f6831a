"""PNG pictures (matplotlib with the Agg backend; no display needed)."""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402

from .geometry import unit  # noqa: E402
from .output import replacing  # noqa: E402


def save(fig, path, dpi=130):
    """Writes the figure to `path` (its format from the extension), replacing an
    earlier picture only once the new one is complete, and closes it."""
    fig.tight_layout()
    try:
        with replacing(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format=os.path.splitext(path)[1][1:] or "png")
    finally:
        plt.close(fig)
    return path


def profile_with_fit(path, x, h, fit=None, title="", xlabel="distance [mm]"):
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(np.asarray(x) * 1e3, np.asarray(h) * 1e3, "o-", ms=3, label="surface profile")
    if fit is not None:
        xs = np.linspace(*fit["window"], 20)
        ax.plot(xs * 1e3, (fit["intercept"] + fit["slope"] * xs) * 1e3, "r-", lw=2,
                label=f"fit {fit['angle']:.1f}° on [{fit['window'][0]*1e3:.1f}, {fit['window'][1]*1e3:.1f}] mm")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("height [mm]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    return save(fig, path)


def curve(path, x, ys, labels, xlabel, ylabel, title="", hlines=(), vlines=(), points=()):
    """Several curves y(x); hlines/vlines: (value, label); points: (x, y, label) markers."""
    fig, ax = plt.subplots(figsize=(6, 3.5))
    for y, lab in zip(ys, labels):
        ax.plot(x, y, "-o", ms=2.5, label=lab)
    for v, lab in hlines:
        ax.axhline(v, color="gray", ls="--", lw=1, label=lab)
    for v, lab in vlines:
        ax.axvline(v, color="k", ls=":", lw=1, label=lab)
    for px, py, lab in points:
        ax.plot(px, py, "s", ms=7, mfc="none", label=lab)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    return save(fig, path)


def side_view(path, frame, horizontal=(1, 0, 0), up=(0, 0, 1), color_by="height", title="", vmax=None):
    """The bed seen from the side: each particle a circle of its true radius,
    projected on the plane (horizontal, up); the nearest particles drawn last.
    color_by: 'height' (along up), 'speed' or 'omega' (|angular velocity|, as the paper's Fig. 2)."""
    e1, e2 = unit(horizontal), unit(up)
    depth_dir = np.cross(e2, e1)  # towards the viewer
    x = frame.position
    u, v, depth = x @ e1, x @ e2, x @ depth_dir
    order = np.argsort(depth)
    if color_by == "speed":
        c, label = np.linalg.norm(frame.velocity, axis=1), "speed [m/s]"
    elif color_by == "omega":
        c, label = np.linalg.norm(frame.omega, axis=1), "angular velocity [rad/s]"
    else:
        c, label = v * 1e3, "height [mm]"
    fig, ax = plt.subplots(figsize=(7, 3.5))
    d = 2e3 * frame.radius[order]
    coll = EllipseCollection(d, d, np.zeros_like(d), units="xy", offsets=np.column_stack([u[order], v[order]]) * 1e3,
                             offset_transform=ax.transData, cmap="viridis", edgecolors="k", linewidths=0.1)
    coll.set_array(c[order])
    if vmax is not None:
        coll.set_clim(0, vmax)
    ax.add_collection(coll)
    ax.set_xlim(u.min() * 1e3 - 2, u.max() * 1e3 + 2)
    ax.set_ylim(min(v.min() * 1e3 - 2, 0), v.max() * 1e3 + 2)
    ax.set_aspect("equal")
    ax.set_xlabel("horizontal [mm]")
    ax.set_ylabel("height [mm]")
    fig.colorbar(coll, ax=ax, label=label, shrink=0.8)
    ax.set_title(title or f"t = {frame.time:.3f} s, {frame.count} particles", fontsize=9)
    return save(fig, path)
