"""dem/summary.csv: one line per log interval (time, step, particles, kineticEnergy, ...,
lostCount, lostMass, mass_<region>)."""
import os

import numpy as np


def read(case_dir, directory="dem"):
    """Columns of summary.csv as a dict of numpy arrays."""
    path = os.path.join(case_dir, directory, "summary.csv")
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.strip().split(",") for line in f if line.strip()]
    data = np.array(rows, float).reshape(-1, len(header))
    return {name: data[:, k] for k, name in enumerate(header)}


def fill_ratio(mass_in_region, reference_mass):
    """Fill ratio: mass in a region (e.g. the die) over a reference mass (the mass
    that fills it completely, or the mass poured)."""
    if not reference_mass > 0:
        raise ValueError("fill_ratio: reference_mass must be positive")
    return np.asarray(mass_in_region, float) / reference_mass
