"""dem/summary.csv: one line per log interval (time, step, particles, kineticEnergy, ...,
lostCount, lostMass, mass_<region>)."""
import os

import numpy as np


class Columns(dict):
    """The columns of a summary.csv by name; a missing one is a KeyError that names
    the file and the columns it has."""

    def __init__(self, path, columns):
        super().__init__(columns)
        self.path = path

    def __missing__(self, name):
        raise KeyError(f"'{self.path}' has no column '{name}' (columns: {', '.join(self)})")


def read(case_dir, directory="dem"):
    """Columns of summary.csv as a dict of numpy arrays.  A file that is empty, has
    no data line, a line with another number of fields than the header or a field
    that is not a number is a ValueError naming the file and the line."""
    path = os.path.join(case_dir, directory, "summary.csv")
    with open(path) as f:
        lines = f.read().splitlines()
    if not lines or not lines[0].strip():
        raise ValueError(f"'{path}' is empty (no header); expected the header line time,step,... "
                         "and one line per log interval, as demRun writes")
    header = [name.strip() for name in lines[0].split(",")]
    if "time" not in header:
        raise ValueError(f"'{path}' line 1: no column 'time' in the header; expected the header line "
                         "time,step,... that demRun writes")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != len(header):
            raise ValueError(f"'{path}' line {number}: {len(fields)} fields, the header has {len(header)}")
        try:
            rows.append([float(v) for v in fields])
        except ValueError:
            bad = next(v for v in fields if not _is_number(v))
            raise ValueError(f"'{path}' line {number}: '{bad.strip()}' is not a number") from None
    if not rows:
        raise ValueError(f"'{path}' has a header but no data line; expected one line per log interval")
    data = np.array(rows, float)
    return Columns(path, {name: data[:, k] for k, name in enumerate(header)})


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def fill_ratio(mass_in_region, reference_mass):
    """Fill ratio: mass in a region (e.g. the die) over a reference mass (the mass
    that fills it completely, or the mass poured)."""
    if not (reference_mass > 0 and np.isfinite(reference_mass)):
        raise ValueError(f"fill_ratio: the reference mass must be a positive number, got {reference_mass}")
    return np.asarray(mass_in_region, float) / reference_mass
