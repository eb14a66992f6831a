#pragma once
// The simulation domain: an axis-aligned box.  A particle that leaves it (or
// whose position is no longer finite) is lost and removed.
#include "demLib/vec3.hpp"

namespace dem {

struct AxisAlignedBox {
    Vec3 min = Vec3::Zero();
    Vec3 max = Vec3::Zero();
    bool contains(const Vec3& x) const {
        return (x.array() >= min.array()).all() && (x.array() <= max.array()).all();
    }
    // The engine's lost-particle test (Simulation::removeLostParticles, and
    // the drift's pass that spares it).
    bool loses(const Vec3& x) const { return !contains(x) || !x.allFinite(); }
};

}  // namespace dem
