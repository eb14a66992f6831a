#pragma once
// Tangential force with shear history and Coulomb truncation, as LIGGGHTS 3.8
// does it (src/tangential_model_history.h, TangentialModel<TANGENTIAL_HISTORY>).
//
// Per step, in this order:
//   1. s += vt dt                         (vt: tangential relative velocity at the contact)
//   2. s -= (s.n) n                       (projection onto the current tangent plane;
//                                          LIGGGHTS does NOT restore |s| afterwards)
//   3. Ft = -kt s
//   4. if kt|s| > mu|Fn|:  Ft *= mu|Fn| / (kt|s|),  s = -Ft/kt   (sliding, no damping)
//      else:               Ft -= gt vt                           (sticking, with damping)
// Ft is the force on particle i; j receives -Ft.
#include <cmath>

#include "demLib/vec3.hpp"

namespace dem {

// Advances `shear` (metres, lives in ContactHistory) and returns the tangential
// force on i.  frictionLimit = mu |Fn| >= 0 is decided by the caller.
DEM_ALWAYS_INLINE Vec3 tangentialHistoryForce(Vec3& shear, const Vec3& normal, const Vec3& tangentialVelocity,
                                   double dt, double tangentialStiffness, double tangentialDamping,
                                   double frictionLimit) noexcept {
    shear += tangentialVelocity * dt;
    shear -= shear.dot(normal) * normal;

    // The Coulomb test kt|s| > mu|Fn| in squared form (both sides are >= 0):
    // the square root and the division are needed only when the contact slides.
    const double shearLengthSquared = shear.squaredNorm();
    Vec3 force = -tangentialStiffness * shear;
    if (tangentialStiffness * tangentialStiffness * shearLengthSquared > frictionLimit * frictionLimit) {
        // |s| > 0 here.  Ft = -kt s mu|Fn| / (kt|s|) and s = -Ft/kt = s mu|Fn| / (kt|s|).
        const double scale = frictionLimit / (tangentialStiffness * std::sqrt(shearLengthSquared));
        force *= scale;
        shear *= scale;
    } else {
        force -= tangentialDamping * tangentialVelocity;
    }
    return force;
}

}  // namespace dem
