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
    """The frame in one particle file; a file that HDF5 cannot read (truncated by a
    run that stopped while writing it, say) or that lacks the positions or the time
    is a ValueError naming it."""
    try:
        with h5py.File(path, "r") as f:
            missing = [k for k in ("position", "radius", "mass") if k not in f]
            if "time" not in f.attrs:
                missing.append("attribute 'time'")
            if missing:
                raise ValueError(f"'{path}' is not a particle field file: no {', '.join(missing)}")
            arrays = {k: f[k][()] for k in FIELDS if k in f}
            time = f.attrs["time"]
            step = f.attrs["step"] if "step" in f.attrs else 0
    except FileNotFoundError:
        raise
    except (OSError, KeyError, RuntimeError) as e:
        raise ValueError(f"'{path}' cannot be read ({e}): a truncated or damaged particle file; "
                         "remove it (and its line in particles.series) or write it again") from None
    for k in ("position", "velocity", "omega", "force"):
        if k in arrays:
            arrays[k] = np.asarray(arrays[k], float).reshape(-1, 3)
    return Frame(np.ravel(time)[0], np.ravel(step)[0], arrays, path)


def output_dir(case_dir, directory="dem"):
    return os.path.join(case_dir, directory)


def _by_step(out):
    """The particles_<step>.h5 files in `out` in step order (the name holds the step)."""
    paths = glob.glob(os.path.join(out, "particles_*.h5"))
    step = re.compile(r"particles_(\d+)\.h5$")
    return sorted(paths, key=lambda p: (int(step.search(p).group(1)) if step.search(p) else -1, p))


def _indexed(case_dir, directory):
    """[(time, path)] from particles.series (or the xdmf index); None without an index."""
    out = output_dir(case_dir, directory)
    index = os.path.join(out, "particles.series")
    entries = []
    if os.path.exists(index):
        with open(index) as f:
            for number, line in enumerate(f, start=1):
                parts = line.split()
                if len(parts) == 4:
                    try:
                        entries.append((float(parts[0]), os.path.join(out, parts[3])))
                    except ValueError:
                        raise ValueError(f"'{index}' line {number}: '{parts[0]}' is not a time; expected "
                                         "lines 'time step particles file'") from None
    elif os.path.exists(os.path.join(out, "particles.xdmf")):
        text = open(os.path.join(out, "particles.xdmf")).read()
        for t, name in re.findall(r'<Time Value="([^"]+)"/>.*?>([^<>:]+\.h5):/position<', text, flags=re.S):
            entries.append((float(t), os.path.join(out, name)))
    else:
        return None
    return [e for e in entries if os.path.exists(e[1])]


def _no_frames(case_dir, directory):
    out = output_dir(case_dir, directory)
    return FileNotFoundError(f"no particle fields (particles_*.h5) in '{out}'; run demRun first")


def list_frames(case_dir, directory="dem"):
    """[(time, path)] in time order, from particles.series (or the xdmf index, or the
    times in the files themselves when there is no index)."""
    entries = _indexed(case_dir, directory)
    if entries is None:
        entries = [(read_frame(p).time, p) for p in _by_step(output_dir(case_dir, directory))]
    entries.sort()
    if not entries:
        raise _no_frames(case_dir, directory)
    return entries


def last_path(case_dir, directory="dem"):
    """The newest particle file, found without opening the others (from the index, or
    by the step in the file names)."""
    entries = _indexed(case_dir, directory)
    paths = _by_step(output_dir(case_dir, directory)) if entries is None else [p for _, p in sorted(entries)]
    if not paths:
        raise _no_frames(case_dir, directory)
    return paths[-1]


def frames(case_dir, directory="dem"):
    for _, path in list_frames(case_dir, directory):
        yield read_frame(path)


def last_frame(case_dir, directory="dem"):
    return read_frame(last_path(case_dir, directory))
