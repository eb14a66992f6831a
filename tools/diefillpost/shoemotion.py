"""A shoe's motion from a measured table of time against position (docs/own-die.md): rows
of time [s], x and optionally y, linear between rows, turned into demLib's translation
segments (constant velocity between two rows; rows where it stands still add none)."""
import math

import numpy as np


def read_table(path):
    """Rows [t, x, y] of a CSV or whitespace table; '#' starts a comment, one header line of
    words is allowed.  A ValueError names the file and the line."""
    rows, seen_line = [], False
    with open(path) as f:
        for number, line in enumerate(f, 1):
            words = line.split("#")[0].replace(",", " ").split()
            if not words:
                continue
            first, seen_line = not seen_line, True
            try:
                values = [float(w) for w in words]
            except ValueError:
                if first:
                    continue   # a header line
                raise ValueError(f"{path}, line {number}: expected numbers (time [s], x, y), got {line.strip()!r}")
            if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
                raise ValueError(f"{path}, line {number}: expected 2 or 3 numbers (time [s], x, y), got {line.strip()!r}")
            rows.append(values if len(values) == 3 else values + [0.0])
    return rows


def segments(rows, start_xy, scale=1.0, where="the table"):
    """([(t0, t1, (vx, vy))], [(t, x, y)]): the table's rows (times in s, positions times
    `scale` in m) moved so that the first row lies at `start_xy`; velocities in m/s."""
    if len(rows) < 2:
        raise ValueError(f"{where}: expected at least two rows (time, x[, y])")
    t = [float(r[0]) for r in rows]
    if t[0] < 0 or any(b <= a for a, b in zip(t, t[1:])):
        raise ValueError(f"{where}: expected times >= 0 that increase from row to row, got {t[:6]}")
    xy = np.array([[r[1], r[2] if len(r) > 2 else 0.0] for r in rows], float) * scale
    xy += np.asarray(start_xy, float) - xy[0]
    out = []
    for k in range(len(rows) - 1):
        v = (xy[k + 1] - xy[k]) / (t[k + 1] - t[k])
        if np.any(v != 0):
            out.append((t[k], t[k + 1], (float(v[0]), float(v[1]))))
    if not out:
        raise ValueError(f"{where}: the shoe never moves")
    return out, [(t[k], float(xy[k, 0]), float(xy[k, 1])) for k in range(len(rows))]


def motion_block(segs, indent="            "):
    """demProperties lines of the segments (one translate each)."""
    return "\n".join(f"{indent}move{k} {{ type translate; start {t0:.9g}; end {t1:.9g}; "
                     f"velocity ({v[0]:.9g} {v[1]:.9g} 0); }}" for k, (t0, t1, v) in enumerate(segs))
