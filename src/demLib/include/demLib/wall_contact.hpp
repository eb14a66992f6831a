#pragma once
// What a wall reports to the DEM engine for one sphere, and the axis-aligned
// box the engine uses to skip walls far from a particle.  Shared by every wall
// shape (plane, cylinder, triangle mesh) and by dem::Wall, which is why it has
// a header of its own.
#include <limits>

#include "demLib/vec3.hpp"

namespace dem {

struct WallContact {
    Vec3 normal = Vec3::Zero();        // unit, from the wall surface towards the sphere centre
    double overlap = 0.0;              // radius - distance(centre, point) > 0
    Vec3 point = Vec3::Zero();         // contact point on the wall surface
    Vec3 wallVelocity = Vec3::Zero();  // velocity of the wall material at `point`
    int feature = 0;                   // stable id of the touched surface feature (see docs/walls.md)
};

// Closed axis-aligned box; infinite bounds stand for unbounded shapes (planes).
struct BoundingBox {
    Vec3 lower = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 upper = Vec3::Constant(-std::numeric_limits<double>::infinity());

    static BoundingBox unbounded() {
        const double inf = std::numeric_limits<double>::infinity();
        return {Vec3::Constant(-inf), Vec3::Constant(inf)};
    }
    bool isEmpty() const { return (lower.array() > upper.array()).any(); }
    bool isUnbounded() const {
        return !lower.allFinite() || !upper.allFinite();
    }
    void expand(const Vec3& p) {
        lower = lower.cwiseMin(p);
        upper = upper.cwiseMax(p);
    }
    // True when the box and the cube [centre - radius, centre + radius] overlap:
    // a cheap necessary condition for the sphere to touch what the box encloses.
    bool overlapsSphere(const Vec3& centre, double radius) const {
        return ((centre.array() + radius) >= lower.array()).all() &&
               ((centre.array() - radius) <= upper.array()).all();
    }
};

}  // namespace dem
