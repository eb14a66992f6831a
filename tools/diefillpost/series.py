"""The particle field series written by demRun: <case>/dem/particles_*.h5,
indexed by dem/particles.series (time step count file) and dem/particles.xdmf."""
import glob
import os
import re

import h5py
import numpy as np

FIELDS = ("id", "position", "velocity", "omega", "force", "radius", "mass", "material")


class Frame:
    """One output time: numpy arrays named as the HDF5 datasets, plus time and step."""

    def __init__(self, time, step, arrays, path=""):
        self.time = float(time)
        self.step = int(step)
        self.path = path
        for k in FIELDS:
            setattr(self, k, arrays.get(k))

    @property
    def count(self):
        return 0 if self.position is None else len(self.position)

    @property
    def total_mass(self):
        return float(np.sum(self.mass)) if self.count else 0.0

    @classmethod
    def from_arrays(cls, position, radius, density=2650.0, time=0.0, velocity=None, ids=None):
        """A frame built from arrays (synthetic data in tests)."""
        position = np.asarray(position, float).reshape(-1, 3)
        radius = np.broadcast_to(np.asarray(radius, float), (len(position),)).copy()
        arrays = {
            "position": position,
            "radius": radius,
            "mass": density * 4.0 / 3.0 * np.pi * radius**3,
            "velocity": np.zeros_like(position) if velocity is None else np.asarray(velocity, float),
            "omega": np.zeros_like(position),
            "force": np.zeros_like(position),
            "id": np.arange(len(position)) if ids is None else np.asarray(ids),
            "material": np.zeros(len(position), int),
        }
        return cls(time, 0, arrays)


def read_frame(path):
    with h5py.File(path, "r") as f:
        arrays = {k: f[k][()] for k in FIELDS if k in f}
        time = f.attrs["time"]
        step = f.attrs["step"] if "step" in f.attrs else 0
    for k in ("position", "velocity", "omega", "force"):
        if k in arrays:
            arrays[k] = np.asarray(arrays[k], float).reshape(-1, 3)
    return Frame(np.ravel(time)[0], np.ravel(step)[0], arrays, path)


def output_dir(case_dir, directory="dem"):
    return os.path.join(case_dir, directory)


def list_frames(case_dir, directory="dem"):
    """[(time, path)] in time order, from particles.series (or the xdmf index, or a glob)."""
    out = output_dir(case_dir, directory)
    index = os.path.join(out, "particles.series")
    entries = []
    if os.path.exists(index):
        with open(index) as f:
            for line in f:
                parts = line.split()
                if len(parts) == 4:
                    entries.append((float(parts[0]), os.path.join(out, parts[3])))
    elif os.path.exists(os.path.join(out, "particles.xdmf")):
        text = open(os.path.join(out, "particles.xdmf")).read()
        for t, name in re.findall(r'<Time Value="([^"]+)"/>.*?>([^<>:]+\.h5):/position<', text, flags=re.S):
            entries.append((float(t), os.path.join(out, name)))
    else:
        for p in sorted(glob.glob(os.path.join(out, "particles_*.h5"))):
            entries.append((read_frame(p).time, p))
    entries = [e for e in entries if os.path.exists(e[1])]
    entries.sort()
    if not entries:
        raise FileNotFoundError(f"no particle fields (particles_*.h5) in '{out}'; run demRun first")
    return entries


def frames(case_dir, directory="dem"):
    for _, path in list_frames(case_dir, directory):
        yield read_frame(path)


def last_frame(case_dir, directory="dem"):
    return read_frame(list_frames(case_dir, directory)[-1][1])
