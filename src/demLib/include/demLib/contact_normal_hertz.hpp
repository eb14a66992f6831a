#pragma once
// Hertz normal contact with the Tsuji-type viscous damping of LIGGGHTS 3.8
// (src/normal_model_hertz.h, NormalModel<HERTZ>::surfacesIntersect).
//
//   kn = 4/3 Y* sqrt(R* d)          Sn = 2 Y* sqrt(R* d)
//   kt = St = 8 G* sqrt(R* d)
//   gn = -2 sqrt(5/6) beta sqrt(Sn m*) >= 0    gt = -2 sqrt(5/6) beta sqrt(St m*) >= 0
//   Fn = kn d - gn vn                (vn = (v_i - v_j).n, n from j to i; vn < 0 approaching)
//
// Fn > 0 is repulsive.  The damping uses the normal relative velocity only.
// With limitForce the (elastic + damping) force is clamped at 0 so that it is
// never attractive (LIGGGHTS option 'limitForce', default off).
#include <cmath>

#include "demLib/interaction_properties.hpp"
#include "demLib/vec3.hpp"

namespace dem {

struct HertzNormal {
    double normalStiffness;      // kn [N/m] (secant: elastic force = kn * overlap)
    double tangentialStiffness;  // kt [N/m]
    double normalDamping;        // gamma_n >= 0 [kg/s]
    double tangentialDamping;    // gamma_t >= 0 [kg/s] (0 when tangential damping is off)
    double elasticForce;         // kn * overlap [N]
    double force;                // elastic + damping, after the optional limitForce clamp [N]
};

// sqrt(5/6), the factor that makes the Hertz dashpot reproduce e exactly.
inline constexpr double kSqrtFiveSixths = 0.91287092917527685576;

DEM_ALWAYS_INLINE HertzNormal hertzNormal(double overlap, double normalVelocity, double radiusEff,
                               double massEff, const InteractionProperties& properties,
                               bool limitForce, bool tangentialDamping) noexcept {
    // Two square roots: a = sqrt(R* d) and sqrt(a m*).  The constant factors
    // (4/3 Y*, 8 G*, -2 sqrt(5/6) beta sqrt(2 Y*), -2 sqrt(5/6) beta sqrt(8 G*))
    // are taken from the material pair, so sqrt(Sn m*) = sqrt(2 Y*) sqrt(a m*)
    // and sqrt(St m*) = sqrt(8 G*) sqrt(a m*) need no root of their own.
    const double contactScale = std::sqrt(radiusEff * overlap);  // sqrt(R* d) = contact radius
    const double dampingScale = std::sqrt(contactScale * massEff);

    HertzNormal result;
    result.normalStiffness = properties.normalStiffnessFactor * contactScale;
    result.tangentialStiffness = properties.tangentialStiffnessFactor * contactScale;
    result.normalDamping = properties.normalDampingFactor * dampingScale;
    result.tangentialDamping = tangentialDamping ? properties.tangentialDampingFactor * dampingScale : 0.0;
    result.elasticForce = result.normalStiffness * overlap;
    const double force = result.elasticForce - result.normalDamping * normalVelocity;
    result.force = (limitForce && force < 0.0) ? 0.0 : force;
    return result;
}

}  // namespace dem
