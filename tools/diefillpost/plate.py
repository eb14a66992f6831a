"""A tilting plate: which particles are still on it, the slid fraction vs plate
angle and the angle at which a given fraction has slid."""
import numpy as np


def read_stl_bounds(path, scale=1.0):
    """Bounding box (lo, hi) of an STL file (ASCII or binary) in its own frame."""
    data = open(path, "rb").read()
    if len(data) >= 84:
        n = int.from_bytes(data[80:84], "little")
        if len(data) == 84 + 50 * n:
            tri = np.frombuffer(data[84:], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
            v = tri["v"].reshape(-1, 3).astype(float)
            return v.min(axis=0) * scale, v.max(axis=0) * scale
    v = np.array([line.split()[1:4] for line in data.decode().splitlines() if line.strip().startswith("vertex")],
                 float)
    return v.min(axis=0) * scale, v.max(axis=0) * scale


def on_plate(frame, pose, t, footprint_lo, footprint_hi, height=0.02):
    """Mask of particles still on the plate at time t: centre over the plate's top
    face (reference-frame x, y inside the footprint) and above it by at most `height`."""
    if frame.count == 0:
        return np.zeros(0, bool)
    x = pose.to_reference(frame.position, t)
    lo, hi = np.asarray(footprint_lo, float), np.asarray(footprint_hi, float)
    inside = (x[:, 0] >= lo[0]) & (x[:, 0] <= hi[0]) & (x[:, 1] >= lo[1]) & (x[:, 1] <= hi[1])
    return inside & (x[:, 2] > hi[2]) & (x[:, 2] < hi[2] + height)


def moved_along(frame, reference, pose, t, t_reference, direction=(-1, 0, 0)):
    """Displacement (plate frame, along `direction`) of each particle of `frame`
    since `reference` (matched by id); particles absent from the reference get 0."""
    xr = pose.to_reference(reference.position, t_reference)
    x = pose.to_reference(frame.position, t)
    where = {int(i): k for k, i in enumerate(reference.id)}
    idx = np.array([where.get(int(i), -1) for i in frame.id], int)
    d = np.zeros(frame.count)
    ok = idx >= 0
    d[ok] = (x[ok] - xr[idx[ok]]) @ np.asarray(direction, float)
    return d


def angle_at_fraction(angles, fractions, target=0.5):
    """First angle at which the (monotone) curve fraction(angle) reaches `target`,
    linearly interpolated between samples; None if never reached."""
    a, f = np.asarray(angles, float), np.asarray(fractions, float)
    above = np.where(f >= target)[0]
    if len(above) == 0:
        return None
    k = above[0]
    if k == 0:
        return float(a[0])
    return float(a[k - 1] + (target - f[k - 1]) * (a[k] - a[k - 1]) / (f[k] - f[k - 1]))


def is_monotone_non_decreasing(values, tolerance=0.0):
    v = np.asarray(values, float)
    return bool(np.all(np.diff(v) >= -tolerance))
