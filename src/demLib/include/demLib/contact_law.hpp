#pragma once
// The complete granular contact law of LIGGGHTS 3.8 'pair gran model hertz
// tangential history rolling_friction {off|cdt|epsd|epsd2}' (and the matching
// 'fix wall/gran'), composed from the per-part headers.  Everything is inline,
// allocation-free and resolved at compile time (if constexpr, no virtual calls).
// One departure from LIGGGHTS: the EPSD/EPSD2 rolling spring is kept as an
// angle, not a torque (see elasticPlasticRollingTorque).
// Formulas, references and conventions: docs/contact-models.md.
//
// Conventions
//  * i is the particle, j the other particle or the wall.
//  * normal n is a unit vector from j towards i; overlap d > 0.
//  * relVelocity = velocity of i relative to j AT THE CONTACT POINT:
//      v_i - v_j - (c_i w_i + c_j w_j) x n     (pair)
//      v_i - v_wall - c_i w_i x n              (wall)
//    with the LIGGGHTS lever arm c = R - d/2 (src/surface_model_default.h).
//  * The torque of the tangential force is the engine's job; LIGGGHTS uses the
//    same lever arm: torque_i = -c_i n x Ft, torque_j = -c_j n x Ft (Ft = force on i).
//  * ContactHistory must be zeroed when the contact opens (LIGGGHTS surfacesClose),
//    and both vectors negated if the engine ever swaps i and j of a live contact.
#include <cmath>

#include "demLib/constants.hpp"
#include "demLib/contact_normal_hertz.hpp"
#include "demLib/contact_rolling_resistance.hpp"
#include "demLib/contact_tangential_history.hpp"
#include "demLib/interaction_properties.hpp"
#include "demLib/vec3.hpp"

namespace dem {

enum class RollingModel { None, CDT, EPSD, EPSD2 };

// Switches with the LIGGGHTS 3.8 defaults.  Make a struct with the same three
// members to change one; they are compile-time constants.
struct LiggghtsDefaultContactSettings {
    // 'model hertz limitForce': clamp the Hertz force (elastic + damping) at >= 0.
    static constexpr bool limitForce = false;
    // 'model hertz tangential_damping': dashpot in the sticking tangential force.
    static constexpr bool tangentialDamping = true;
    // 'cohesion ... tangential_reduce': whether extraNormalForce is added to the
    // normal force that sets the Coulomb limit mu|Fn| and the rolling limit
    // mu_r R*|Fn|.  Off by default in LIGGGHTS (sjkr, sjkr2, easo/capillary/viscous).
    static constexpr bool cohesionInFrictionLimits = false;
};

struct ContactKinematics {
    Vec3 normal;               // unit, from j towards i
    double overlap;            // > 0
    double radiusEff, massEff; // R*, m*  (wall: R* = R_i, m* = m_i)
    Vec3 relVelocity;          // of i relative to j at the contact point (incl. rotation terms)
    Vec3 relOmega;             // w_i - w_j (w_i for walls)
    double dt;
    bool isWall = false;             // selects the LIGGGHTS wall variants of the rolling models
    double rollingInertiaEff = 0.0;  // EPSD only: rollingInertiaEff(...) / rollingInertiaWall(...)
};

struct ContactHistory {
    Vec3 shear = Vec3::Zero();          // tangential spring displacement [m]
    Vec3 rollingAngle = Vec3::Zero();   // EPSD/EPSD2 rolling spring: angle rolled by i relative to j [rad]
};

struct ContactForces {
    Vec3 force;            // on i: normal + tangential, applied at the contact point [N]
    Vec3 tangentialForce;  // on i [N]
    Vec3 rollingTorque;    // on i [N m]; j receives -rollingTorque
    double normalForce;    // signed, + repulsive: Hertz (elastic + damping) + extraNormalForce [N]
};

template <RollingModel Rolling, class Settings = LiggghtsDefaultContactSettings>
struct ContactLaw {
    // extraNormalForce: cohesive normal force from another model (negative =
    // attractive).  It is always part of the returned force; it enters the
    // friction and rolling limits only if Settings::cohesionInFrictionLimits.
    DEM_ALWAYS_INLINE static ContactForces evaluate(const ContactKinematics& kin, const InteractionProperties& props,
                                  ContactHistory& history, double extraNormalForce = 0.0) noexcept {
        const double normalVelocity = kin.relVelocity.dot(kin.normal);
        const Vec3 tangentialVelocity = kin.relVelocity - normalVelocity * kin.normal;

        const HertzNormal hertz =
            hertzNormal(kin.overlap, normalVelocity, kin.radiusEff, kin.massEff, props,
                        Settings::limitForce, Settings::tangentialDamping);
        const double normalForce = hertz.force + extraNormalForce;
        const double limitingNormalForce =
            std::abs(Settings::cohesionInFrictionLimits ? normalForce : hertz.force);

        const Vec3 tangentialForce = tangentialHistoryForce(
            history.shear, kin.normal, tangentialVelocity, kin.dt, hertz.tangentialStiffness,
            hertz.tangentialDamping, props.friction * limitingNormalForce);

        Vec3 rollingTorque = Vec3::Zero();
        if constexpr (Rolling == RollingModel::CDT) {
            // LIGGGHTS: R* for pairs, the contact radius R - d/2 for walls.
            const double leverArm =
                kin.isWall ? kin.radiusEff - 0.5 * kin.overlap : kin.radiusEff;
            rollingTorque = cdtRollingTorque(kin.relOmega, kin.normal, props.rollingFriction,
                                             hertz.elasticForce, leverArm);
        } else if constexpr (Rolling == RollingModel::EPSD || Rolling == RollingModel::EPSD2) {
            // For walls LIGGGHTS feeds w_i (R - d/2)/(R - d) (its 'wr' = cr w rinv).
            const Vec3 omega =
                kin.isWall ? Vec3(kin.relOmega * ((kin.radiusEff - 0.5 * kin.overlap) /
                                                  (kin.radiusEff - kin.overlap)))
                           : kin.relOmega;
            double stiffness = 0.0;
            double viscous = 0.0;
            if constexpr (Rolling == RollingModel::EPSD) {
                stiffness = epsdRollingStiffness(hertz.normalStiffness, props.rollingFriction,
                                                 kin.radiusEff);
                viscous = props.rollingViscousDamping * 2.0 *
                          std::sqrt(kin.rollingInertiaEff * stiffness);
            } else {
                stiffness = epsd2RollingStiffness(hertz.tangentialStiffness, kin.radiusEff);
            }
            rollingTorque = elasticPlasticRollingTorque(
                history.rollingAngle, omega, kin.normal, kin.dt, stiffness,
                props.rollingFriction * kin.radiusEff * limitingNormalForce, viscous);
        }

        ContactForces result;
        result.tangentialForce = tangentialForce;
        result.force = normalForce * kin.normal + tangentialForce;
        result.rollingTorque = rollingTorque;
        result.normalForce = normalForce;
        return result;
    }
};

// ---------------------------------------------------------------------------
// Time-step estimates (LIGGGHTS src/fix_check_timestep_gran.cpp).

// Rayleigh time pi R sqrt(rho/G) / (0.1631 nu + 0.8766), G = E / (2(1 + nu)).
// This is the LIGGGHTS value, without a factor 0.5; LIGGGHTS warns when dt
// exceeds a user-given fraction of it (typically 0.2).
inline double rayleighTime(double radius, double density, double youngsModulus,
                           double poissonRatio) noexcept {
    const double shearModulus = youngsModulus / (2.0 * (1.0 + poissonRatio));
    return pi * radius * std::sqrt(density / shearModulus) / (0.1631 * poissonRatio + 0.8766);
}

// The smallest Rayleigh time of a material for particles of radius >= radius.
inline double criticalTimeStep(const Material& material, double radius) noexcept {
    return rayleighTime(radius, material.density, material.youngsModulus, material.poissonRatio);
}

// Duration of an elastic Hertz impact, 2.87 (m*^2 / (R* Y*^2 v))^(1/5).
// LIGGGHTS evaluates it with m* = m_particle (NOT m/2), R* = R/2, Y* of the
// type pair and v = the largest relative velocity (2 |v|max for pairs).
inline double hertzCollisionTime(double massEff, double radiusEff, double youngsEff,
                                 double impactVelocity) noexcept {
    return 2.87 * std::pow(massEff * massEff / (radiusEff * youngsEff * youngsEff * impactVelocity),
                           0.2);
}

}  // namespace dem
