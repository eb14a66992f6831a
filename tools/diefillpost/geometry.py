"""Rotations, the pose of a moving wall from its motion block, and named regions
(boxes and cylinders, as in demProperties) with the particle mass inside them."""
import numpy as np


def unit(v):
    v = np.asarray(v, float)
    n = np.linalg.norm(v)
    if not n > 0:
        raise ValueError("zero direction vector")
    return v / n


def rotation_matrix(axis, angle):
    """Right-hand rotation by `angle` (rad) about the unit `axis` (Rodrigues)."""
    e = unit(axis)
    k = np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


class WallPose:
    """x_world = R x_ref + x0 of a wall whose motion is a sequence of segments
    {type translate; start; end; velocity} / {type rotate; start; end; axisPoint;
    axis; angularVelocity (deg/s)} as in demProperties (docs/walls.md)."""

    def __init__(self, motion=None):
        self.segments = []
        for seg in (motion or {}).values():
            s = dict(seg)
            s["start"], s["end"] = float(s["start"]), float(s["end"])
            self.segments.append(s)
        self.segments.sort(key=lambda s: s["start"])

    def pose(self, t):
        R, x0 = np.eye(3), np.zeros(3)
        for s in self.segments:
            tau = min(max(t - s["start"], 0.0), s["end"] - s["start"])
            if tau <= 0:
                continue
            if s["type"] == "translate":
                x0 = x0 + np.asarray(s["velocity"], float) * tau
            else:
                Q = rotation_matrix(s["axis"], np.radians(float(s["angularVelocity"])) * tau)
                a = np.asarray(s["axisPoint"], float)
                R, x0 = Q @ R, Q @ (x0 - a) + a
        return R, x0

    def rotation_angle(self, t):
        """Total rotation (degrees) accumulated by the rotate segments up to t."""
        total = 0.0
        for s in self.segments:
            if s["type"] == "rotate":
                tau = min(max(t - s["start"], 0.0), s["end"] - s["start"])
                total += float(s["angularVelocity"]) * tau
        return total

    def to_reference(self, points, t):
        """World points mapped into the wall's reference frame at time t."""
        R, x0 = self.pose(t)
        return (np.asarray(points, float) - x0) @ R


def wall_pose(case_dict, wall_name):
    walls = case_dict.get("walls", {})
    if wall_name not in walls:
        raise KeyError(f"demProperties has no wall '{wall_name}' (walls: {', '.join(walls)})")
    return WallPose(walls[wall_name].get("motion"))


class Box:
    def __init__(self, lo, hi):
        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)
        if self.lo.shape != (3,) or self.hi.shape != (3,) or not np.all(self.lo < self.hi):
            raise ValueError(f"box: expected min below max in x, y and z, got min {self.lo.tolist()} "
                             f"max {self.hi.tolist()}")

    def contains(self, x):
        x = np.asarray(x, float)
        return np.all((x >= self.lo) & (x <= self.hi), axis=1)


class Cylinder:
    def __init__(self, axis_point, axis, radius, lo, hi):
        self.a, self.e = np.asarray(axis_point, float), unit(axis)
        self.radius, self.lo, self.hi = float(radius), float(lo), float(hi)
        if not (np.isfinite(self.radius) and self.radius > 0 and self.lo < self.hi and np.all(np.isfinite(self.a))):
            raise ValueError(f"cylinder: expected a radius above zero and a range low < high, got radius "
                             f"{self.radius:g}, range {self.lo:g} {self.hi:g}")

    def contains(self, x):
        d = np.asarray(x, float) - self.a
        z = d @ self.e
        rho = np.linalg.norm(d - np.outer(z, self.e), axis=1)
        return (rho <= self.radius) & (z >= self.lo) & (z <= self.hi)


def region_from_dict(d):
    """A region as written in demProperties (type box / cylinder)."""
    if d["type"] == "box":
        return Box(d["min"], d["max"])
    if d["type"] == "cylinder":
        return Cylinder(d["axisPoint"], d["axis"], d["radius"], *d["range"])
    raise ValueError(f"region type '{d['type']}' is not supported here (box, cylinder)")


def mass_in_region(frame, region):
    """Mass of the particles whose centres lie in the region (as demLib's massInRegion)."""
    if frame.count == 0:
        return 0.0
    return float(np.sum(frame.mass[region.contains(frame.position)]))
