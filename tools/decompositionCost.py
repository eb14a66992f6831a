#!/usr/bin/env python3
"""Cost of decomposing a die filling's particles over P ranks: slabs with
moving (equal-count) cuts against recursive coordinate bisection (RCB).

    decompositionCost.py -case DIR [-times T ...] [-ranks P ...] [-skin S] [-bridge B]

For each chosen output (nearest to each time T in s; 'last' for the last file;
default: 1 and last) and each rank count P (default 2 4 8 16):

  (0) fixed equal-width slabs along x over the x range of all chosen outputs
      (fixed cuts, no balancing: max/mean only);
  (a) slabs along x, cuts at the count quantiles (what SlabDecomposition::balanced gives);
  (b) the same along the axis of largest extent (SlabDecomposition::axisOfLargestExtent),
      and along the axis that gives the fewest ghosts;
  (c) RCB: the particles split in two at the count quantile p1/p (p1 = p // 2) along
      the axis of largest extent of the part, recursively, down to one part per rank.

It prints max/mean owned and the ghost fraction: (number of (particle, rank) pairs
with the particle within the halo width h of that rank's region and owned by
another rank) / N, i.e. the ghosts all ranks receive, per particle.  h is demLib's:
h = 2 r_max + skin + bridge reach, skin = S r_max (default 0.4), reach = B r_max
(default 0.2).  Distances to a slab are along its axis; to an RCB box, Euclidean.
Reads only the positions and radii of the particle files (dem/particles_*.h5)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import argument_parser, frame_at, non_negative, positive_int, run_main  # noqa: E402
from diefillpost import series  # noqa: E402

AXES = "xyz"


def quantile_cuts(coordinate, parts):
    """Interior cuts giving `parts` slabs of equal count (to one particle): between
    the sorted coordinates k N/parts - 1 and k N/parts."""
    c = np.sort(coordinate)
    n = len(c)
    cuts = []
    for k in range(1, parts):
        m = (k * n) // parts
        cuts.append(0.5 * (c[m - 1] + c[m]) if 0 < m < n else (c[0] if m <= 0 else np.nextafter(c[-1], np.inf)))
    return cuts


def slab_boxes(position, axis, parts):
    """Regions (lower corner, upper corner) of equal-count slabs along `axis`."""
    edges = [-np.inf] + quantile_cuts(position[:, axis], parts) + [np.inf]
    boxes = []
    for r in range(parts):
        lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
        lo[axis], hi[axis] = edges[r], edges[r + 1]
        boxes.append((lo, hi))
    return boxes


def rcb_boxes(position, parts):
    """Regions of recursive coordinate bisection with equal counts."""
    boxes = []

    def split(index, parts, lo, hi):
        if parts == 1:
            boxes.append((lo, hi))
            return
        p = position[index]
        axis = int(np.argmax(p.max(axis=0) - p.min(axis=0))) if len(p) else 0
        first = parts // 2
        c = np.sort(p[:, axis])
        m = (len(c) * first) // parts
        cut = 0.5 * (c[m - 1] + c[m]) if 0 < m < len(c) else (lo[axis] if m <= 0 else hi[axis])
        below = p[:, axis] < cut
        hi1, lo2 = hi.copy(), lo.copy()
        hi1[axis] = lo2[axis] = cut
        split(index[below], first, lo, hi1)
        split(index[~below], parts - first, lo2, hi)

    split(np.arange(len(position)), parts, np.full(3, -np.inf), np.full(3, np.inf))
    return boxes


def owner_and_ghosts(position, boxes, halo):
    """(owned count per region, ghost count summed over regions): a particle is owned by
    the region holding it (lo <= x < hi on every axis) and a ghost of every other region
    within `halo` of it."""
    owned, ghosts = [], 0
    for lo, hi in boxes:
        excess = np.maximum(0.0, np.maximum(lo - position, position - hi))
        excess = np.where(np.isfinite(excess), excess, 0.0)
        distance = np.sqrt((excess**2).sum(axis=1))
        inside = np.all((position >= lo) & (position < hi), axis=1)
        owned.append(int(inside.sum()))
        ghosts += int(((~inside) & (distance < halo)).sum())
    return np.array(owned), ghosts


def measure(position, boxes, halo):
    owned, ghosts = owner_and_ghosts(position, boxes, halo)
    if owned.sum() != len(position):
        raise ValueError(f"regions own {owned.sum()} of {len(position)} particles: not a partition")
    return owned.max() / owned.mean(), ghosts / len(position)


def main():
    ap = argument_parser(__doc__)
    ap.add_argument("-case", required=True, help="case directory (with dem/particles_*.h5)")
    ap.add_argument("-times", nargs="+", default=["1", "last"], help="output times (s), or 'last'")
    ap.add_argument("-ranks", nargs="+", type=positive_int, default=[2, 4, 8, 16])
    ap.add_argument("-skin", type=non_negative, default=0.4, help="neighbour skin / r_max (default 0.4)")
    ap.add_argument("-bridge", type=non_negative, default=0.2, help="bridge reach / r_max (default 0.2)")
    args = ap.parse_args()
    frames = [frame_at(args.case, None if text == "last" else float(text)) for text in args.times]
    positions = []
    for frame in frames:
        position = np.asarray(frame.position, float)
        positions.append(position[np.all(np.isfinite(position), axis=1)])
    x_range = (min(p[:, 0].min() for p in positions), max(p[:, 0].max() for p in positions))
    for frame, position in zip(frames, positions):
        r_max = float(np.max(frame.radius))
        halo = (2.0 + args.skin + args.bridge) * r_max
        extent = position.max(axis=0) - position.min(axis=0)
        longest = int(np.argmax(extent))
        print(f"\n{os.path.relpath(frame.path, args.case)}: t = {frame.time:g} s, N = {len(position)}, "
              f"r_max = {r_max * 1e3:.3g} mm, h = {halo * 1e3:.3g} mm, extent x y z = "
              + " ".join(f"{e * 1e3:.1f}" for e in extent) + " mm")
        print(f"{'P':>3}  {'fixed x':>8}  {'slabs x':>15}  {'slabs ' + AXES[longest] + ' (longest)':>18}  "
              f"{'slabs best axis':>17}  {'RCB':>15}")
        print(f"{'':>3}  {'max/mean':>8}  " + "  ".join(f"{'max/mean ghosts':>{w}}" for w in (15, 18, 17, 15)))
        for parts in args.ranks:
            by_axis = [measure(position, slab_boxes(position, a, parts), halo) for a in range(3)]
            best = min(range(3), key=lambda a: by_axis[a][1])
            rcb = measure(position, rcb_boxes(position, parts), halo)
            fixed = np.linspace(x_range[0], x_range[1], parts + 1)
            fixed_owned = np.bincount(np.searchsorted(fixed[1:-1], position[:, 0], side="right"), minlength=parts)
            cells = [by_axis[0], by_axis[longest], by_axis[best], rcb]
            text_cells = [f"{b:8.3f} {g:6.3f}" for b, g in cells]
            text_cells[2] = f"{AXES[best]} " + text_cells[2]
            print(f"{parts:>3}  {fixed_owned.max() / fixed_owned.mean():8.3f}  {text_cells[0]:>15}  {text_cells[1]:>18}  {text_cells[2]:>17}  {text_cells[3]:>15}")
    return 0


if __name__ == "__main__":
    run_main(main)
