#!/usr/bin/env python3
"""What ParaView must show of a case's particle output, read from the files themselves with
h5py (a process of its own: ParaView's HDF5 and h5py's are different builds):

    expected.py CASE OUT.json

For each entry of CASE/dem/particles.series (time, step, count, file): the time, the count,
and for a non-empty file the bounds of the positions, of the radii and of the ids, the z range
of the particles' spheres (z - r, z + r) and the number of distinct ids."""
import json
import os
import sys

import h5py
import numpy as np


def main():
    case, out = sys.argv[1:3]
    dem = os.path.join(case, "dem")
    entries = []
    for line in open(os.path.join(dem, "particles.series")):
        time, step, count, name = line.split()
        entry = {"time": float(time), "step": int(step), "count": int(count), "file": name}
        if entry["count"] > 0:
            with h5py.File(os.path.join(dem, name), "r") as f:
                x, r, ids = f["position"][()], f["radius"][()], f["id"][()]
            if len(x) != entry["count"]:
                sys.exit(f"{name}: {len(x)} positions, particles.series says {entry['count']}")
            entry.update({
                "positionMin": x.min(axis=0).tolist(), "positionMax": x.max(axis=0).tolist(),
                "radiusRange": [float(r.min()), float(r.max())],
                "idRange": [int(ids.min()), int(ids.max())], "distinctIds": int(len(np.unique(ids))),
                "sphereZ": [float((x[:, 2] - r).min()), float((x[:, 2] + r).max())],
            })
        entries.append(entry)
    json.dump({"case": case, "entries": entries}, open(out, "w"), indent=1)


if __name__ == "__main__":
    main()
