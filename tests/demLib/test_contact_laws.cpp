// Verification of the LIGGGHTS 3.8 contact laws (Hertz + history + rolling models)
// against closed forms, hand values and a restitution experiment integrated here.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "demLib/contact_law.hpp"
#include "demLib/error.hpp"
#include "demLib/interaction_properties.hpp"

namespace {

using dem::ContactForces;
using dem::ContactHistory;
using dem::ContactKinematics;
using dem::ContactLaw;
using dem::InteractionProperties;
using dem::Material;
using dem::PairCoefficients;
using dem::RollingModel;
using dem::Vec3;

constexpr double kPi = 3.14159265358979323846;

// Table 3 of the paper.
const Material kSand{"sand", 5.0e6, 0.3, 2650.0};
const Material kSteel{"steel", 7.0e10, 0.3, 7800.0};

double sphereMass(double radius, double density) {
    return 4.0 / 3.0 * kPi * radius * radius * radius * density;
}

InteractionProperties sandSand(double restitution = 0.1, double friction = 0.7,
                               double rollingFriction = 0.5, double rollingDamping = 0.3) {
    return dem::makeInteraction(kSand, kSand,
                                PairCoefficients{restitution, friction, rollingFriction,
                                                 rollingDamping});
}

double relativeError(double value, double reference) {
    return std::abs(value - reference) / std::abs(reference);
}

// A resting pair contact along z: n = +z, no relative motion.
ContactKinematics restingPair(double overlap, double radius, double mass, double dt) {
    ContactKinematics kin;
    kin.normal = Vec3(0.0, 0.0, 1.0);
    kin.overlap = overlap;
    kin.radiusEff = 0.5 * radius;
    kin.massEff = 0.5 * mass;
    kin.relVelocity = Vec3::Zero();
    kin.relOmega = Vec3::Zero();
    kin.dt = dt;
    kin.rollingInertiaEff = dem::rollingInertiaEff(mass, radius, mass, radius);
    return kin;
}

double hertzElastic(double youngsEff, double radiusEff, double overlap) {
    return 4.0 / 3.0 * youngsEff * std::sqrt(radiusEff) * std::pow(overlap, 1.5);
}

struct NoTangentialDamping {
    static constexpr bool limitForce = false;
    static constexpr bool tangentialDamping = false;
    static constexpr bool cohesionInFrictionLimits = false;
};
struct WithLimitForce {
    static constexpr bool limitForce = true;
    static constexpr bool tangentialDamping = true;
    static constexpr bool cohesionInFrictionLimits = false;
};
struct CohesionReducesFriction {
    static constexpr bool limitForce = false;
    static constexpr bool tangentialDamping = true;
    static constexpr bool cohesionInFrictionLimits = true;
};

// ---------------------------------------------------------------------------
// Effective properties

TEST(InteractionProperties, PaperTablesTwoAndThreeAgainstHandValues) {
    // sand-sand: Y* = E / (2 (1 - 0.09)) = 5e6 / 1.82;  G* = E / (4 * 1.7 * 1.3) = 5e6 / 8.84
    const InteractionProperties pp =
        dem::makeInteraction(kSand, kSand, PairCoefficients{0.10, 0.70, 0.50, 0.0});
    EXPECT_NEAR(pp.youngsEff, 2747252.747252747, 1e-12 * 2747252.747252747);
    EXPECT_NEAR(pp.shearEff, 565610.8597285068, 1e-12 * 565610.8597285068);
    // beta(0.1) = ln 0.1 / sqrt(ln^2 0.1 + pi^2)
    EXPECT_NEAR(pp.beta, -0.5911550337988976, 1e-13);
    EXPECT_DOUBLE_EQ(pp.friction, 0.70);
    EXPECT_DOUBLE_EQ(pp.rollingFriction, 0.50);

    // sand-steel: Y* = 1/(0.91/5e6 + 0.91/7e10), G* = 1/(4.42/5e6 + 4.42/7e10)
    const InteractionProperties pw =
        dem::makeInteraction(kSand, kSteel, PairCoefficients{0.15, 0.61, 0.50, 0.0});
    EXPECT_NEAR(pw.youngsEff, 5494113.057858504, 1e-12 * 5494113.057858504);
    EXPECT_NEAR(pw.shearEff, 1131140.9236767509, 1e-12 * 1131140.9236767509);
    EXPECT_NEAR(pw.beta, -0.5169308662051556, 1e-13);

    // e = 1 means no dissipation at all.
    EXPECT_EQ(dem::dampingBetaFromRestitution(1.0), 0.0);
}

TEST(InteractionProperties, RejectsOutOfRangeInputNamingQuantityAndRange) {
    auto expectInputError = [](const Material& a, const PairCoefficients& c,
                               const std::string& keyword, const std::string& range) {
        try {
            dem::makeInteraction(a, kSand, c);
            ADD_FAILURE() << "no InputError for " << keyword;
        } catch (const dem::InputError& error) {
            const std::string message = error.what();
            EXPECT_NE(message.find(keyword), std::string::npos) << message;
            EXPECT_NE(message.find(range), std::string::npos) << message;
        }
    };
    const PairCoefficients ok{0.5, 0.5, 0.1, 0.1};
    expectInputError(kSand, {0.0, 0.5, 0.1, 0.1}, "restitution", "0 < restitution <= 1");
    expectInputError(kSand, {1.2, 0.5, 0.1, 0.1}, "restitution", "0 < restitution <= 1");
    expectInputError(kSand, {std::nan(""), 0.5, 0.1, 0.1}, "restitution", "0 < restitution <= 1");
    expectInputError(kSand, {0.5, -0.1, 0.1, 0.1}, "friction", ">= 0");
    expectInputError(kSand, {0.5, 0.5, -0.1, 0.1}, "rollingFriction", ">= 0");
    expectInputError(kSand, {0.5, 0.5, 0.1, -1.0}, "rollingViscousDamping", ">= 0");
    expectInputError(Material{"soft", 0.0, 0.3, 2650.0}, ok, "youngsModulus", "> 0");
    expectInputError(Material{"odd", 5e6, 0.6, 2650.0}, ok, "poissonRatio", "0 <= poissonRatio <= 0.5");
    expectInputError(Material{"void", 5e6, 0.3, -1.0}, ok, "density", "> 0");
}

TEST(InteractionTable, SymmetricLookupAndCompletenessCheck) {
    const std::vector<Material> materials{kSand, kSteel};
    dem::InteractionTable table(materials.size());
    table.set(materials, 0, 0, PairCoefficients{0.10, 0.70, 0.50, 0.0});
    EXPECT_THROW(table.requireComplete(materials), dem::InputError);
    table.set(materials, 1, 0, PairCoefficients{0.15, 0.61, 0.50, 0.0});
    EXPECT_THROW(table.requireComplete(materials), dem::InputError);  // steel-steel missing
    table.set(materials, 1, 1, PairCoefficients{0.9, 0.3, 0.0, 0.0});
    EXPECT_NO_THROW(table.requireComplete(materials));
    EXPECT_TRUE(table.isSet(0, 1));
    EXPECT_DOUBLE_EQ(table(0, 1).friction, 0.61);
    EXPECT_DOUBLE_EQ(table(1, 0).friction, 0.61);
    EXPECT_DOUBLE_EQ(table(0, 1).youngsEff, table(1, 0).youngsEff);
    EXPECT_DOUBLE_EQ(table(0, 0).friction, 0.70);
    EXPECT_THROW(table.set(2, 0, table(0, 0)), dem::InputError);
}

// ---------------------------------------------------------------------------
// Normal force

TEST(HertzNormal, ElasticForceMatchesClosedForm) {
    const InteractionProperties props = sandSand();
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    for (double overlap : {1e-8, 1e-7, 1e-6, 1e-5, 5e-5}) {
        ContactKinematics kin = restingPair(overlap, radius, mass, 1e-7);
        ContactHistory history;
        const ContactForces f = ContactLaw<RollingModel::None>::evaluate(kin, props, history);
        const double expected = hertzElastic(props.youngsEff, kin.radiusEff, overlap);
        EXPECT_LT(relativeError(f.normalForce, expected), 1e-12) << "overlap " << overlap;
        EXPECT_LT(relativeError(f.force.z(), expected), 1e-12);
        EXPECT_EQ(f.force.x(), 0.0);
        EXPECT_EQ(f.force.y(), 0.0);
    }
}

TEST(HertzNormal, DampingUsesNormalRelativeVelocityOnlyWithTsujiCoefficient) {
    const InteractionProperties props = sandSand(0.5);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 2e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, 1e-7);
    kin.relVelocity = Vec3(0.0, 0.0, -0.3);  // approaching
    ContactHistory history;
    const double approaching =
        ContactLaw<RollingModel::None>::evaluate(kin, props, history).normalForce;

    kin.relVelocity = Vec3(0.7, -0.4, -0.3);  // same vn, plus sliding
    ContactHistory history2;
    const double sliding =
        ContactLaw<RollingModel::None>::evaluate(kin, props, history2).normalForce;
    EXPECT_DOUBLE_EQ(sliding, approaching);

    const double sn = 2.0 * props.youngsEff * std::sqrt(kin.radiusEff * overlap);
    const double gammaN = -2.0 * std::sqrt(5.0 / 6.0) * props.beta * std::sqrt(sn * kin.massEff);
    const double expected = hertzElastic(props.youngsEff, kin.radiusEff, overlap) + gammaN * 0.3;
    EXPECT_LT(relativeError(approaching, expected), 1e-12);
}

TEST(HertzNormal, LimitForceClampsAttractiveDampingOnlyWhenEnabled) {
    const InteractionProperties props = sandSand(0.1);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    ContactKinematics kin = restingPair(1e-8, radius, mass, 1e-7);
    kin.relVelocity = Vec3(0.0, 0.0, 1.0);  // separating fast at tiny overlap
    ContactHistory h1, h2;
    const double plain = ContactLaw<RollingModel::None>::evaluate(kin, props, h1).normalForce;
    const double limited =
        ContactLaw<RollingModel::None, WithLimitForce>::evaluate(kin, props, h2).normalForce;
    EXPECT_LT(plain, 0.0);
    EXPECT_EQ(limited, 0.0);
}

// ---------------------------------------------------------------------------
// Restitution: 1D head-on impacts integrated with velocity Verlet (forces from
// half-step velocities, as LAMMPS/LIGGGHTS fix nve/sphere).

double measuredRestitutionPair(double restitution, double impactVelocity) {
    const InteractionProperties props = dem::makeInteraction(
        kSand, kSand, PairCoefficients{restitution, 0.7, 0.0, 0.0});
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double collisionTime = dem::hertzCollisionTime(0.5 * mass, 0.5 * radius,
                                                         props.youngsEff, impactVelocity);
    const double dt = collisionTime / 200.0;
    // A at x = 0 moving +x, B touching it at x = 2R moving -x; i = A, j = B.
    double xA = 0.0, xB = 2.0 * radius;
    double vA = 0.5 * impactVelocity, vB = -0.5 * impactVelocity;
    double forceOnA = 0.0;
    ContactHistory history;
    bool touched = false;
    for (int step = 0; step < 100000; ++step) {
        vA += 0.5 * dt * forceOnA / mass;
        vB -= 0.5 * dt * forceOnA / mass;
        xA += dt * vA;
        xB += dt * vB;
        const double overlap = 2.0 * radius - (xB - xA);
        forceOnA = 0.0;
        if (overlap > 0.0) {
            touched = true;
            ContactKinematics kin;
            kin.normal = Vec3(-1.0, 0.0, 0.0);  // from B to A
            kin.overlap = overlap;
            kin.radiusEff = 0.5 * radius;
            kin.massEff = 0.5 * mass;
            kin.relVelocity = Vec3(vA - vB, 0.0, 0.0);
            kin.relOmega = Vec3::Zero();
            kin.dt = dt;
            forceOnA = ContactLaw<RollingModel::None>::evaluate(kin, props, history).force.x();
        } else if (touched) {
            return (vB - vA) / impactVelocity;
        }
        vA += 0.5 * dt * forceOnA / mass;
        vB -= 0.5 * dt * forceOnA / mass;
    }
    return -1.0;
}

double measuredRestitutionWall(double restitution, double impactVelocity) {
    const InteractionProperties props = dem::makeInteraction(
        kSand, kSteel, PairCoefficients{restitution, 0.61, 0.0, 0.0});
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double collisionTime =
        dem::hertzCollisionTime(mass, radius, props.youngsEff, impactVelocity);
    const double dt = collisionTime / 200.0;
    double x = radius, v = -impactVelocity, force = 0.0;  // wall plane x = 0
    ContactHistory history;
    bool touched = false;
    for (int step = 0; step < 100000; ++step) {
        v += 0.5 * dt * force / mass;
        x += dt * v;
        const double overlap = radius - x;
        force = 0.0;
        if (overlap > 0.0) {
            touched = true;
            ContactKinematics kin;
            kin.normal = Vec3(1.0, 0.0, 0.0);  // from wall to particle
            kin.overlap = overlap;
            kin.radiusEff = radius;
            kin.massEff = mass;
            kin.relVelocity = Vec3(v, 0.0, 0.0);
            kin.relOmega = Vec3::Zero();
            kin.dt = dt;
            kin.isWall = true;
            force = ContactLaw<RollingModel::None>::evaluate(kin, props, history).force.x();
        } else if (touched) {
            return v / impactVelocity;
        }
        v += 0.5 * dt * force / mass;
    }
    return -1.0;
}

TEST(HertzNormal, HeadOnPairCollisionReproducesRestitution) {
    for (double e : {0.1, 0.5, 0.9}) {
        for (double impact : {0.1, 1.0}) {
            const double measured = measuredRestitutionPair(e, impact);
            EXPECT_LT(relativeError(measured, e), 0.01) << "e " << e << " v " << impact
                                                        << " measured " << measured;
        }
    }
}

TEST(HertzNormal, SphereWallCollisionReproducesRestitution) {
    for (double e : {0.1, 0.5, 0.9}) {
        for (double impact : {0.1, 1.0}) {
            const double measured = measuredRestitutionWall(e, impact);
            EXPECT_LT(relativeError(measured, e), 0.01) << "e " << e << " v " << impact
                                                        << " measured " << measured;
        }
    }
}

// ---------------------------------------------------------------------------
// Tangential force

TEST(TangentialHistory, GrowsLinearlyThenSaturatesExactlyAtCoulombLimit) {
    const InteractionProperties props = sandSand(0.5, 0.7);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 1e-5, speed = 0.01, dt = 1e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, dt);
    kin.relVelocity = Vec3(speed, 0.0, 0.0);

    const double contactScale = std::sqrt(kin.radiusEff * overlap);
    const double kt = 8.0 * props.shearEff * contactScale;
    const double gammaT = -2.0 * std::sqrt(5.0 / 6.0) * props.beta *
                          std::sqrt(8.0 * props.shearEff * contactScale * kin.massEff);
    const double limit = props.friction * hertzElastic(props.youngsEff, kin.radiusEff, overlap);

    ContactHistory withDamping, withoutDamping;
    int saturatedSteps = 0, stickingSteps = 0;
    for (int k = 1; k <= 2000; ++k) {
        const ContactForces f = ContactLaw<RollingModel::None>::evaluate(kin, props, withDamping);
        const ContactForces g =
            ContactLaw<RollingModel::None, NoTangentialDamping>::evaluate(kin, props,
                                                                          withoutDamping);
        const double springForce = kt * k * speed * dt;
        EXPECT_EQ(f.tangentialForce.y(), 0.0);
        EXPECT_EQ(f.tangentialForce.z(), 0.0);
        if (springForce <= limit) {
            ++stickingSteps;
            // Damping is part of the sticking force but not of the sliding test.
            EXPECT_LT(relativeError(-f.tangentialForce.x(), springForce + gammaT * speed), 1e-10);
            EXPECT_LT(relativeError(-g.tangentialForce.x(), springForce), 1e-10);
        } else {
            ++saturatedSteps;
            EXPECT_LT(relativeError(-f.tangentialForce.x(), limit), 1e-12);
            EXPECT_LT(relativeError(-g.tangentialForce.x(), limit), 1e-12);
            EXPECT_LT(relativeError(withDamping.shear.x(), limit / kt), 1e-12);
        }
    }
    EXPECT_GT(stickingSteps, 100);
    EXPECT_GT(saturatedSteps, 100);
}

TEST(TangentialHistory, RotatedTangentPlaneProjectsHistoryWithoutRescaling) {
    const InteractionProperties props = sandSand(0.5, 0.7);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 1e-5, shearLength = 1e-6, angle = 0.3;
    ContactKinematics kin = restingPair(overlap, radius, mass, 1e-6);
    kin.normal = Vec3(std::sin(angle), 0.0, std::cos(angle));
    ContactHistory history;
    history.shear = Vec3(shearLength, 0.0, 0.0);
    const ContactForces f = ContactLaw<RollingModel::None>::evaluate(kin, props, history);

    // LIGGGHTS subtracts the normal part and keeps the shorter vector.
    EXPECT_NEAR(history.shear.dot(kin.normal), 0.0, 1e-22);
    EXPECT_LT(relativeError(history.shear.norm(), shearLength * std::cos(angle)), 1e-12);
    const double kt = 8.0 * props.shearEff * std::sqrt(kin.radiusEff * overlap);
    EXPECT_LT((f.tangentialForce + kt * history.shear).norm(), 1e-12 * kt * shearLength);
}

TEST(TangentialHistory, CohesiveForceEntersFrictionLimitOnlyWhenRequested) {
    const InteractionProperties props = sandSand(0.5, 0.5);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 1e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, 1e-6);
    const double hertz = hertzElastic(props.youngsEff, kin.radiusEff, overlap);
    const double cohesion = -0.4 * hertz;

    ContactHistory defaultHistory, reducedHistory;
    defaultHistory.shear = reducedHistory.shear = Vec3(1e-3, 0.0, 0.0);  // far beyond sliding
    const ContactForces def =
        ContactLaw<RollingModel::None>::evaluate(kin, props, defaultHistory, cohesion);
    const ContactForces red = ContactLaw<RollingModel::None, CohesionReducesFriction>::evaluate(
        kin, props, reducedHistory, cohesion);

    EXPECT_LT(relativeError(def.normalForce, hertz + cohesion), 1e-12);
    EXPECT_LT(relativeError(red.normalForce, hertz + cohesion), 1e-12);
    EXPECT_LT(relativeError(def.force.z(), hertz + cohesion), 1e-12);
    EXPECT_LT(relativeError(def.tangentialForce.norm(), 0.5 * hertz), 1e-12);
    EXPECT_LT(relativeError(red.tangentialForce.norm(), 0.5 * std::abs(hertz + cohesion)), 1e-12);
}

// ---------------------------------------------------------------------------
// Rolling resistance

TEST(RollingCDT, ConstantTorqueOpposesRelativeRotation) {
    const InteractionProperties props = sandSand(0.5, 0.7, 0.5);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 4e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, 1e-6);
    const double fel = hertzElastic(props.youngsEff, kin.radiusEff, overlap);
    const double magnitude = props.rollingFriction * kin.radiusEff * fel;

    kin.relOmega = Vec3(0.0, 2.0, 0.0);
    ContactHistory history;
    Vec3 torque = ContactLaw<RollingModel::CDT>::evaluate(kin, props, history).rollingTorque;
    EXPECT_LT((torque - Vec3(0.0, -magnitude, 0.0)).norm(), 1e-12 * magnitude);

    // Independent of |w|, and the torsion part is removed after normalising.
    kin.relOmega = Vec3(0.0, 30.0, 40.0);
    torque = ContactLaw<RollingModel::CDT>::evaluate(kin, props, history).rollingTorque;
    EXPECT_LT((torque - Vec3(0.0, -0.6 * magnitude, 0.0)).norm(), 1e-12 * magnitude);

    // Uses the elastic force only: normal damping does not change it.
    kin.relOmega = Vec3(0.0, 2.0, 0.0);
    kin.relVelocity = Vec3(0.0, 0.0, -0.5);
    torque = ContactLaw<RollingModel::CDT>::evaluate(kin, props, history).rollingTorque;
    EXPECT_LT((torque - Vec3(0.0, -magnitude, 0.0)).norm(), 1e-12 * magnitude);

    // Wall: R* = R, and LIGGGHTS' lever arm is the contact radius R - d/2.
    ContactKinematics wall = kin;
    wall.relVelocity = Vec3::Zero();
    wall.isWall = true;
    wall.radiusEff = radius;
    wall.massEff = mass;
    const double wallForce = hertzElastic(props.youngsEff, radius, overlap);
    torque = ContactLaw<RollingModel::CDT>::evaluate(wall, props, history).rollingTorque;
    EXPECT_LT(relativeError(-torque.y(), props.rollingFriction * wallForce * (radius - 0.5 * overlap)),
              1e-12);

    // No rotation, no torque.
    kin.relOmega = Vec3::Zero();
    EXPECT_EQ(ContactLaw<RollingModel::CDT>::evaluate(kin, props, history).rollingTorque.norm(),
              0.0);
}

TEST(RollingEPSD2, SpringTorqueGrowsWithRotationThenSaturates) {
    // The spring is kept as the rolled angle (tangential part of w dt, summed);
    // the torque is -kr times it, up to the limit mu_r R* |Fn|.
    const InteractionProperties props = sandSand(0.5, 0.7, 0.5);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 4e-6, omega = 2.0, dt = 1e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, dt);
    kin.relOmega = Vec3(0.0, omega, 7.0);  // the torsion part (z) must be ignored
    const double kt = 8.0 * props.shearEff * std::sqrt(kin.radiusEff * overlap);
    const double kr = kt * kin.radiusEff * kin.radiusEff;
    const double limit = props.rollingFriction * kin.radiusEff *
                         hertzElastic(props.youngsEff, kin.radiusEff, overlap);

    ContactHistory history;
    int elastic = 0, plastic = 0;
    for (int k = 1; k <= 4000; ++k) {
        const Vec3 torque =
            ContactLaw<RollingModel::EPSD2>::evaluate(kin, props, history).rollingTorque;
        EXPECT_EQ(torque.x(), 0.0);
        EXPECT_EQ(torque.z(), 0.0);
        EXPECT_EQ(history.rollingAngle.x(), 0.0);
        EXPECT_EQ(history.rollingAngle.z(), 0.0);  // the torsion part is not stored
        const double angle = omega * dt * k;  // rolled angle
        const double spring = kr * angle;
        if (spring <= limit) {
            ++elastic;
            EXPECT_LT(relativeError(-torque.y(), spring), 1e-10);
            EXPECT_LT(relativeError(history.rollingAngle.y(), angle), 1e-10);
        } else {
            ++plastic;
            EXPECT_LT(relativeError(-torque.y(), limit), 1e-12);
            // Full mobilisation: the stored angle is cut back to limit / kr.
            EXPECT_LT(relativeError(history.rollingAngle.y(), limit / kr), 1e-12);
        }
    }
    EXPECT_GT(elastic, 100);
    EXPECT_GT(plastic, 100);
}

TEST(RollingEPSD2, WallUsesParticleRadiusAndLiggghtsAngularVelocityScaling) {
    const InteractionProperties props =
        dem::makeInteraction(kSand, kSteel, PairCoefficients{0.15, 0.61, 0.5, 0.0});
    const double radius = 1e-3, overlap = 4e-6, omega = 0.5, dt = 1e-7;
    ContactKinematics kin = restingPair(overlap, radius, sphereMass(radius, kSand.density), dt);
    kin.isWall = true;
    kin.radiusEff = radius;
    kin.massEff = sphereMass(radius, kSand.density);
    kin.relOmega = Vec3(0.0, omega, 0.0);
    ContactHistory history;
    const Vec3 torque = ContactLaw<RollingModel::EPSD2>::evaluate(kin, props, history).rollingTorque;
    const double kt = 8.0 * props.shearEff * std::sqrt(radius * overlap);
    const double scale = (radius - 0.5 * overlap) / (radius - overlap);
    EXPECT_LT(relativeError(-torque.y(), kt * radius * radius * omega * scale * dt), 1e-12);
}

TEST(RollingEPSD, DampingTermMatchesFormulaAndIsDroppedAtFullMobilisation) {
    const InteractionProperties props = sandSand(0.5, 0.7, 0.5, 0.3);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double overlap = 4e-6, omega = 0.5, dt = 1e-6;
    ContactKinematics kin = restingPair(overlap, radius, mass, dt);
    kin.relOmega = Vec3(0.0, omega, 0.0);

    const double kn = 4.0 / 3.0 * props.youngsEff * std::sqrt(kin.radiusEff * overlap);
    const double kr = 2.25 * kn * props.rollingFriction * props.rollingFriction *
                      kin.radiusEff * kin.radiusEff;
    const double inertia = 1.4 * (mass * radius * radius) / 2.0;  // equal spheres
    EXPECT_LT(relativeError(kin.rollingInertiaEff, inertia), 1e-14);
    const double viscous = props.rollingViscousDamping * 2.0 * std::sqrt(inertia * kr);
    const double limit = props.rollingFriction * kin.radiusEff *
                         hertzElastic(props.youngsEff, kin.radiusEff, overlap);

    ContactHistory history;
    Vec3 torque = ContactLaw<RollingModel::EPSD>::evaluate(kin, props, history).rollingTorque;
    EXPECT_LT(relativeError(-torque.y(), kr * omega * dt + viscous * omega), 1e-12);
    // The history keeps the spring's rolled angle only (no dashpot in it).
    EXPECT_LT(relativeError(history.rollingAngle.y(), omega * dt), 1e-12);

    int steps = 1;
    for (; steps < 200000 && kr * std::abs(history.rollingAngle.y()) < limit; ++steps)
        torque = ContactLaw<RollingModel::EPSD>::evaluate(kin, props, history).rollingTorque;
    // The limit is reached after limit / (kr w dt) steps.
    EXPECT_NEAR(steps, limit / (kr * omega * dt), 2.0);
    torque = ContactLaw<RollingModel::EPSD>::evaluate(kin, props, history).rollingTorque;
    EXPECT_LT(relativeError(-torque.y(), limit), 1e-12);  // no dashpot when fully mobilised
    EXPECT_LT(relativeError(history.rollingAngle.y(), limit / kr), 1e-12);
}

// The rolling spring must not create energy when the overlap (and with it kr)
// changes.  A closed cycle of the rolled angle: roll by +a at overlap d1,
// compress to d2 (kr grows), roll back by -a, release to d1.  The spring ends
// where it started, unloaded.  The LIGGGHTS form, which keeps the spring
// TORQUE and adds -kr w dt, would end with the torque (kr(d2) - kr(d1)) a and
// the energy of that spring, taken from nowhere: repeated, this pumped the
// wet (capillary-compressed) die-filling bed of the EPSD2 runs.
template <RollingModel Rolling>
void expectClosedRollingCycleLeavesTheSpringUnloaded() {
    const InteractionProperties props = sandSand(0.5, 0.7, 0.5, 0.3);
    const double radius = 1e-3;
    const double mass = sphereMass(radius, kSand.density);
    const double dt = 1e-6, omega = 0.5;
    const double overlap1 = 2e-6, overlap2 = 8e-6;
    const int steps = 400;  // a = 2e-4 rad: elastic at both overlaps
    const double a = omega * dt * steps;
    ContactKinematics kin = restingPair(overlap1, radius, mass, dt);
    auto stiffness = [&](double overlap) {
        const double contact = std::sqrt(kin.radiusEff * overlap);
        return Rolling == RollingModel::EPSD
                   ? dem::epsdRollingStiffness(4.0 / 3.0 * props.youngsEff * contact, props.rollingFriction,
                                               kin.radiusEff)
                   : dem::epsd2RollingStiffness(8.0 * props.shearEff * contact, kin.radiusEff);
    };
    const double kr1 = stiffness(overlap1), kr2 = stiffness(overlap2);
    ASSERT_LT(kr1 * a, 0.5 * props.rollingFriction * kin.radiusEff *
                           hertzElastic(props.youngsEff, kin.radiusEff, overlap1));
    ASSERT_GT(kr2, 1.9 * kr1);

    ContactHistory history;
    auto roll = [&](double overlap, double w, int n) {
        kin.overlap = overlap;
        kin.relOmega = Vec3(0.0, w, 0.0);
        Vec3 torque = Vec3::Zero();
        for (int k = 0; k < n; ++k) torque = ContactLaw<Rolling>::evaluate(kin, props, history).rollingTorque;
        return torque;
    };
    for (int cycle = 1; cycle <= 20; ++cycle) {
        SCOPED_TRACE("cycle " + std::to_string(cycle));
        roll(overlap1, omega, steps);
        EXPECT_LT(relativeError(history.rollingAngle.y(), a), 1e-9);
        // At rest (no dashpot): the spring torque of the current stiffness.
        Vec3 torque = roll(overlap1, 0.0, 1);
        EXPECT_LT(relativeError(-torque.y(), kr1 * a), 1e-9);
        torque = roll(overlap2, 0.0, 1);  // compressed: same angle, stiffer spring
        EXPECT_LT(relativeError(-torque.y(), kr2 * a), 1e-9);
        roll(overlap2, -omega, steps);
        torque = roll(overlap1, 0.0, 1);  // released
        EXPECT_LT(std::abs(history.rollingAngle.y()), 1e-9 * a);
        EXPECT_LT(std::abs(torque.y()), 1e-9 * kr1 * a);
        EXPECT_EQ(torque.x(), 0.0);
        EXPECT_EQ(torque.z(), 0.0);
    }
    // (LIGGGHTS keeps the torque, incremented by -kr dtheta with the current kr: each
    // cycle would leave (kr2 - kr1) a in it, 20 (kr2 - kr1) a > 18 kr1 a after these.)
}

TEST(RollingEPSD2, ClosedRollingCycleUnderChangingOverlapLeavesTheSpringUnloaded) {
    expectClosedRollingCycleLeavesTheSpringUnloaded<RollingModel::EPSD2>();
}

TEST(RollingEPSD, ClosedRollingCycleUnderChangingOverlapLeavesTheSpringUnloaded) {
    expectClosedRollingCycleLeavesTheSpringUnloaded<RollingModel::EPSD>();
}

// The stored angle lies in the current tangent plane: when the normal turns,
// its normal part is dropped (as for the tangential shear spring).
TEST(RollingEPSD2, RolledAngleIsProjectedOntoTheTangentPlane) {
    const InteractionProperties props = sandSand(0.5, 0.7, 0.5);
    const double radius = 1e-3, overlap = 4e-6, dt = 1e-6;
    ContactKinematics kin = restingPair(overlap, radius, sphereMass(radius, kSand.density), dt);
    ContactHistory history;
    history.rollingAngle = Vec3(1e-5, 2e-5, 0.0);
    const double c = std::sqrt(0.5);
    kin.normal = Vec3(0.0, c, c);  // turned by 45 degrees about x
    const Vec3 torque = ContactLaw<RollingModel::EPSD2>::evaluate(kin, props, history).rollingTorque;
    const Vec3 expected(1e-5, 1e-5, -1e-5);  // minus (theta.n) n
    EXPECT_LT((history.rollingAngle - expected).norm(), 1e-12 * expected.norm());
    EXPECT_NEAR(history.rollingAngle.dot(kin.normal), 0.0, 1e-20);
    const double kr = dem::epsd2RollingStiffness(8.0 * props.shearEff * std::sqrt(kin.radiusEff * overlap),
                                                 kin.radiusEff);
    EXPECT_LT((torque + kr * expected).norm(), 1e-12 * kr * expected.norm());
}

// ---------------------------------------------------------------------------
// Time-step estimates

TEST(TimeStep, RayleighAndHertzTimesAgainstHandValues) {
    // G = 5e6 / 2.6; T_R = pi * 1e-3 * sqrt(2650 / G) / (0.1631 * 0.3 + 0.8766)
    EXPECT_LT(relativeError(dem::criticalTimeStep(kSand, 1e-3), 1.2600389815604188e-4), 1e-12);
    EXPECT_LT(relativeError(dem::rayleighTime(1e-3, 2650.0, 5e6, 0.3), 1.2600389815604188e-4),
              1e-12);
    // LIGGGHTS check/timestep/gran: m = 4/3 pi R^3 rho, R* = R/2, Y* sand-sand, v = 1 m/s
    const double mass = sphereMass(1e-3, kSand.density);
    EXPECT_LT(relativeError(dem::hertzCollisionTime(mass, 0.5e-3, 2747252.747252747, 1.0),
                            3.636321239340649e-4),
              1e-12);
}

}  // namespace
