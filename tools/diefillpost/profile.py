"""Bed surface profiles (top-surface height per bin) and fitted slope angles."""
import numpy as np

from .geometry import unit


def _positive(name, value):
    """A ValueError unless `value` is a finite number above zero."""
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number above zero, got {value}")


def _sectors(sectors):
    if int(sectors) != sectors or sectors < 1:
        raise ValueError(f"sectors must be a whole number of at least 1, got {sectors}")
    return int(sectors)


def _binned_max(coord, top, edges, groups=None, n_groups=1):
    """Max of `top` per (group, bin); NaN where a bin is empty."""
    nb = len(edges) - 1
    k = np.searchsorted(edges, coord, side="right") - 1
    ok = (k >= 0) & (k < nb)
    g = np.zeros(len(coord), int) if groups is None else groups
    out = np.full((n_groups, nb), -np.inf)
    np.maximum.at(out, (g[ok], k[ok]), top[ok])
    out[np.isinf(out)] = np.nan
    return out


def _sector_of(rvec, e, sectors):
    """Azimuthal sector (0 .. sectors-1) of radial vectors `rvec` around the unit axis `e`."""
    # an in-plane basis for the azimuth
    u = unit(np.cross(e, [1, 0, 0]) if abs(e[0]) < 0.9 else np.cross(e, [0, 1, 0]))
    v = np.cross(e, u)
    phi = np.arctan2(rvec @ v, rvec @ u)
    return np.minimum(((phi + np.pi) / (2 * np.pi) * sectors).astype(int), sectors - 1)


def radial_profile(position, radius, axis_point=(0, 0, 0), axis=(0, 0, 1), bin_width=1e-3,
                   r_max=None, sectors=8, base=0.0):
    """Surface height vs distance from an axis, averaged around it.

    In each of `sectors` azimuthal sectors and each radial bin the surface is the
    highest particle top (axial coordinate + radius); the profile is the mean over
    the sectors that hold particles in that bin.  Heights are measured from `base`
    along `axis`.  Returns (bin centres, height, number of sectors with data)."""
    _positive("bin_width", bin_width)
    sectors = _sectors(sectors)
    x = np.asarray(position, float) - np.asarray(axis_point, float)
    e = unit(axis)
    z = x @ e
    rvec = x - np.outer(z, e)
    rho = np.linalg.norm(rvec, axis=1)
    sector = _sector_of(rvec, e, sectors)
    r_max = float(np.max(rho)) + bin_width if r_max is None else r_max
    edges = np.arange(0.0, r_max + 0.5 * bin_width, bin_width)
    per_sector = _binned_max(rho, z + np.asarray(radius, float) - base, edges, sector, sectors)
    n = np.sum(np.isfinite(per_sector), axis=0)
    with np.errstate(invalid="ignore"):
        h = np.where(n > 0, np.nansum(np.nan_to_num(per_sector, nan=0.0), axis=0) / np.maximum(n, 1), np.nan)
    return 0.5 * (edges[1:] + edges[:-1]), h, n


def sector_angles(position, radius, axis_point, axis, bin_width, window, sectors=8):
    """The pile's angle sector by sector: in each of `sectors` azimuthal sectors the
    profile of that sector's particles alone (radial_profile with one sector) fitted
    over `window` (fit_line); sectors with fewer than 3 points in the window are left
    out.  Returns the list of angles (deg), whose spread shows how round the pile is."""
    _positive("bin_width", bin_width)
    sectors = _sectors(sectors)
    position, radius = np.asarray(position, float), np.asarray(radius, float)
    x = position - np.asarray(axis_point, float)
    e = unit(axis)
    sector = _sector_of(x - np.outer(x @ e, e), e, sectors)
    angles = []
    for k in range(sectors):
        sel = sector == k
        r, h, _ = radial_profile(position[sel], radius[sel], axis_point, axis, bin_width, sectors=1)
        try:
            angles.append(fit_line(r, h, window)["angle"])
        except ValueError:
            pass
    return angles


def line_profile(position, radius, origin=(0, 0, 0), direction=(1, 0, 0), up=(0, 0, 1), bin_width=1e-3,
                 extent=None, band=None):
    """Surface height vs position along a line: the highest particle top (height along
    `up` + radius) per bin of the coordinate along `direction`, for particles within
    `band` of the vertical plane through the line (all particles when None).
    Returns (bin centres, height) with NaN in empty bins."""
    _positive("bin_width", bin_width)
    x = np.asarray(position, float) - np.asarray(origin, float)
    d, n = unit(direction), unit(up)
    s, h = x @ d, x @ n + np.asarray(radius, float)
    keep = np.ones(len(x), bool)
    if band is not None:
        _positive("band", band)
        across = np.cross(n, d)
        keep = np.abs(x @ across) <= band
    if extent is None and not keep.any():
        raise ValueError(f"no particle within the band of {band:g} m around the line" if band is not None
                         else "no particles")
    lo, hi = (np.min(s[keep]), np.max(s[keep]) + 1e-12) if extent is None else extent
    edges = np.arange(lo, hi + 0.5 * bin_width, bin_width)
    return 0.5 * (edges[1:] + edges[:-1]), _binned_max(s[keep], h[keep], edges)[0]


def fit_line(x, h, window):
    """Least-squares line h = a + b x over the bins with window[0] <= x <= window[1]
    (NaN bins skipped).  Returns dict(slope, intercept, angle (deg, of |slope|),
    window, points, rms)."""
    x, h = np.asarray(x, float), np.asarray(h, float)
    sel = (x >= window[0]) & (x <= window[1]) & np.isfinite(h)
    if np.count_nonzero(sel) < 3:
        raise ValueError(f"fit window {window} holds fewer than 3 profile points")
    b, a = np.polyfit(x[sel], h[sel], 1)
    rms = float(np.sqrt(np.mean((a + b * x[sel] - h[sel]) ** 2)))
    return {"slope": float(b), "intercept": float(a), "angle": float(np.degrees(np.arctan(abs(b)))),
            "window": [float(window[0]), float(window[1])], "points": int(np.count_nonzero(sel)), "rms": rms}


def flank_window(x, h, low=0.2, high=0.8):
    """The part of a pile's flank where the profile falls from `high` to `low` times
    its peak height (the toe and the rounded top are left out).  Returns (x_a, x_b):
    x_a the first bin beyond the peak with h <= high*peak, x_b the last bin with
    h >= low*peak."""
    x, h = np.asarray(x, float), np.asarray(h, float)
    finite = np.isfinite(h)
    ipeak = int(np.nanargmax(h))
    peak = h[ipeak]
    after = np.arange(len(h)) >= ipeak
    a = np.where(after & finite & (h <= high * peak))[0]
    b = np.where(after & finite & (h >= low * peak))[0]
    if len(a) == 0 or len(b) == 0 or x[b[-1]] <= x[a[0]]:
        raise ValueError("profile has no flank between the requested height fractions")
    return float(x[a[0]]), float(x[b[-1]])


def edge_angle(position, radius, origin=(0, 0, 0), direction=(1, 0, 0), up=(0, 0, 1), band=None,
               bin_height=1e-3, low=0.2, high=0.8):
    """Angle of a bed's edge on the `direction` side, measured from the edge position
    versus height (a height profile cannot resolve an edge close to vertical).
    Particles within `band` of the vertical plane through the line are binned by
    height; per bin the edge is the outermost extent s + radius along `direction`.
    A line s_edge = a + b h is fitted over the bins between `low` and `high` times
    the height of the bed's top near the edge (particles in its outer half), and the
    angle above the horizontal is atan(1/|b|): 90 deg for a vertical edge.
    Returns dict(angle, slope_ds_dh, window (heights), points)."""
    _positive("bin_height", bin_height)
    x = np.asarray(position, float) - np.asarray(origin, float)
    d, n = unit(direction), unit(up)
    r = np.asarray(radius, float) * np.ones(len(x))
    s, h = x @ d, x @ n
    keep = np.ones(len(x), bool)
    if band is not None:
        keep = np.abs(x @ np.cross(n, d)) <= band
    s, h, r = s[keep], h[keep], r[keep]
    outer = s > 0.5 * np.max(s + r)
    top = float(np.max(h[outer] + r[outer]))
    edges = np.arange(0.0, top + bin_height, bin_height)
    centres, extent = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (h >= lo) & (h < hi)
        if np.any(sel):
            centres.append(0.5 * (lo + hi))
            extent.append(float(np.max(s[sel] + r[sel])))
    centres, extent = np.array(centres), np.array(extent)
    window = (low * top, high * top)
    sel = (centres >= window[0]) & (centres <= window[1])
    if np.count_nonzero(sel) < 3:
        raise ValueError(f"edge fit window {window} holds fewer than 3 height bins")
    b, _ = np.polyfit(centres[sel], extent[sel], 1)
    return {"angle": float(np.degrees(np.arctan2(1.0, abs(b)))), "slope_ds_dh": float(b),
            "window": [float(window[0]), float(window[1])], "points": int(np.count_nonzero(sel))}
