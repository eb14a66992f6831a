#pragma once
// Rolling resistance models of LIGGGHTS 3.8 (src/rolling_model_cdt.h,
// src/rolling_model_epsd.h, src/rolling_model_epsd2.h); Ai et al. 2011 models A
// (CDT: constant directional torque) and C (EPSD: elastic-plastic spring-dashpot).
// All torques returned here act on particle i; particle j receives the opposite.
// omega is the relative angular velocity w_i - w_j (w_i for a wall).
#include <cmath>

#include "demLib/vec3.hpp"

namespace dem {

// CDT: M_i = -mu_r Fel L (w / |w|), then its component along n (torsion) is
// removed.  Fel = kn d is the ELASTIC normal force (no damping, no cohesion);
// L is R* for particle pairs and R - d/2 for walls (LIGGGHTS 'cri').
// Note that the direction is normalised BEFORE the torsion part is removed, so
// |M_i| = mu_r Fel L |w_t| / |w|.
inline Vec3 cdtRollingTorque(const Vec3& omega, const Vec3& normal, double rollingFriction,
                             double elasticNormalForce, double leverArm) noexcept {
    const double omegaLength = omega.norm();
    if (!(omegaLength > 0.0)) return Vec3::Zero();
    const Vec3 torque = (rollingFriction * elasticNormalForce * leverArm / omegaLength) * omega;
    return -(torque - torque.dot(normal) * normal);
}

// EPSD stiffness (Ai et al. 2011, eq. 14, 3D prefactor 2.25): kr = 2.25 kn mu_r^2 R*^2,
// kn being the Hertz secant stiffness 4/3 Y* sqrt(R* d).
inline double epsdRollingStiffness(double normalStiffness, double rollingFriction,
                                   double radiusEff) noexcept {
    return 2.25 * normalStiffness * rollingFriction * rollingFriction * radiusEff * radiusEff;
}

// EPSD2 stiffness (Iwashita & Oda 1998 as in LIGGGHTS): kr = kt R*^2.
inline double epsd2RollingStiffness(double tangentialStiffness, double radiusEff) noexcept {
    return tangentialStiffness * radiusEff * radiusEff;
}

// Rolling inertia used for the EPSD critical damping (3D):
// I_r = 1/(1/(I_i + m_i R_i^2) + 1/(I_j + m_j R_j^2)), I = 0.4 m R^2 for a sphere.
inline double rollingInertiaEff(double massI, double radiusI, double massJ,
                                double radiusJ) noexcept {
    const double reducedI = massI * radiusI * radiusI;
    const double reducedJ = massJ * radiusJ * radiusJ;
    return 1.4 * reducedI * reducedJ / (reducedI + reducedJ);
}
inline double rollingInertiaWall(double mass, double radius) noexcept {
    return 1.4 * mass * radius * radius;
}

// EPSD and EPSD2 share this update.  The rolling spring is kept as the rolled
// ANGLE theta [rad] (in ContactHistory, of i relative to j), advanced with the
// tangential part w_t of omega and projected onto the current tangent plane as
// the tangential shear spring is; the spring torque is evaluated from it with
// the CURRENT stiffness:
//   theta += w_t dt;  theta -= (theta.n) n
//   M = -kr theta
//   if |M| > Mmax:  theta *= Mmax/|M| (so that |kr theta| = Mmax), returned
//                   M Mmax/|M| without damping (full mobilisation)
//   else:           returned M - c w_t  with c = eta_r 2 sqrt(I_r kr) (EPSD) or 0 (EPSD2)
// Mmax = mu_r R* |Fn| with Fn the total normal force of the normal model.
//
// This departs from LIGGGHTS 3.8, which keeps the spring TORQUE M and
// increments it, M -= kr w_t dt.  kr depends on the current overlap (EPSD:
// kn ~ sqrt(R* d); EPSD2: kt ~ sqrt(R* d)), so a stored torque keeps its value
// while kr changes, and the spring energy M^2/(2 kr) changes without work: an
// overlap that oscillates (contacts compressed by capillary bridges) pumps
// energy into the rolling springs.  An angle gives the energy kr theta^2/2 of
// the current stiffness, which returns to zero when the rolled angle does.
// For a constant kr and omega in the tangent plane both forms give the same
// torques.
DEM_ALWAYS_INLINE Vec3 elasticPlasticRollingTorque(Vec3& springAngle, const Vec3& omega, const Vec3& normal,
                                        double dt, double rollingStiffness, double torqueLimit,
                                        double viscousCoefficient) noexcept {
    const Vec3 omegaTangential = omega - omega.dot(normal) * normal;
    springAngle += omegaTangential * dt;
    springAngle -= springAngle.dot(normal) * normal;
    Vec3 torque = -rollingStiffness * springAngle;
    // |M| > Mmax in squared form (both >= 0): the root only when the limit is reached.
    const double torqueSquared = torque.squaredNorm();
    if (torqueSquared > torqueLimit * torqueLimit) {
        const double scale = torqueLimit / std::sqrt(torqueSquared);
        springAngle *= scale;
        torque *= scale;
        return torque;
    }
    return torque - viscousCoefficient * omegaTangential;
}

}  // namespace dem
