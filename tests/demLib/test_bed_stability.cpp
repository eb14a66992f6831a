// The stable time step of a bed from its actual contacts (bed_stability.hpp)
// against the one-particle model of contact_stability.hpp where that model is
// exact: a sphere resting on a floor, and two free spheres in contact (their
// relative motion is one sphere's against a fixed one with the springs and
// dashpots doubled).  The wet beds it was validated on are in tests/wetColumn.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "demLib/bed_stability.hpp"
#include "demLib/contact_rolling_resistance.hpp"
#include "demLib/contact_stability.hpp"
#include "demLib/simulation.hpp"

namespace {

using dem::Vec3;
constexpr double kPi = 3.14159265358979323846;

dem::InteractionTable tableFor(const std::vector<dem::Material>& materials) {
    dem::PairCoefficients c;
    c.restitution = 0.1;
    c.friction = 0.5;
    c.rollingFriction = 0.5;
    c.rollingViscousDamping = 0.3;
    dem::InteractionTable table(materials.size());
    table.set(materials, 0, 0, c);
    return table;
}

std::vector<dem::Material> sand() {
    dem::Material m;
    m.name = "sand";
    m.youngsModulus = 5e6;
    m.poissonRatio = 0.3;
    m.density = 2500.0;
    return {m};
}

dem::SimulationSettings settings(double dt, Vec3 gravity, dem::RollingModel rolling) {
    dem::SimulationSettings s;
    s.timeStep = dt;
    s.gravity = gravity;
    s.source = "test_bed_stability";
    s.forces.rolling = rolling;
    return s;
}

// The one-particle model: mass m, one contact towards `normal` with the law at `overlap`.
dem::ContactClusterModel oneContact(double r, double m, const dem::LinearContact& law, double overlap,
                                    const Vec3& normal) {
    dem::ContactClusterModel model;
    model.mass.diagonal() << m, m, m, 0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r;
    dem::addContact(model, r - 0.5 * overlap, normal, law);
    return model;
}

dem::BedStabilityOptions fine() {
    dem::BedStabilityOptions o;
    o.relativeTolerance = 0.002;
    return o;
}

TEST(BedStability, SphereOnAFloorMatchesTheOneParticleModel) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = 1e-3, m = 2500.0 * 4.0 / 3.0 * kPi * r * r * r;
    // EPSD: the rolling spring and dashpot of the wall contact count too.
    dem::Simulation sim(settings(1e-6, Vec3(0, 0, -9.81), dem::RollingModel::EPSD), mats, table,
                        {dem::Wall{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0}});
    sim.insert({{Vec3(0, 0, r - 0.5e-6 * r), r}}, 0, Vec3::Zero());
    sim.step(20000);  // comes to rest at the overlap of its weight
    const double overlap = r - sim.particles().position[0].z();
    ASSERT_GT(overlap, 0.0);
    const double expected = dem::verletStableTimeStep(
        oneContact(r, m,
                   dem::linearHertzContact(table(0, 0), r, m, overlap, dem::RollingModel::EPSD,
                                           dem::rollingInertiaWall(m, r)),
                   overlap, -Vec3::UnitZ()));
    const dem::BedStabilityReport report = dem::analyseBedStability(sim, fine());
    EXPECT_EQ(report.particles, 1u);
    EXPECT_EQ(report.wallContacts, 1u);
    EXPECT_EQ(report.particleContacts, 0u);
    EXPECT_NEAR(report.stableTimeStep / expected, 1.0, 0.01) << "bed " << report.stableTimeStep << " model " << expected;
    EXPECT_GE(report.undampedLimit, report.stableTimeStep);
    EXPECT_TRUE(report.stableAtRunStep);
}

TEST(BedStability, TwoFreeSpheresMatchTheRelativeMotionModel) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = 1e-3, m = 2500.0 * 4.0 / 3.0 * kPi * r * r * r, overlap = 2e-3 * r;
    // CDT: no rolling spring (the rolling mode of two spheres is not the slip
    // mode, so the doubled one-particle model is exact only without it).
    dem::Simulation sim(settings(1e-7, Vec3::Zero(), dem::RollingModel::CDT), mats, table, {});
    sim.insert({{Vec3(-r + 0.5 * overlap, 0, 0), r}, {Vec3(r - 0.5 * overlap, 0, 0), r}}, 0, Vec3::Zero());
    dem::LinearContact law = dem::linearHertzContact(table(0, 0), 0.5 * r, 0.5 * m, overlap);
    for (double* part : {&law.normalStiffness, &law.tangentialStiffness, &law.normalDamping, &law.tangentialDamping})
        *part *= 2.0;
    const double expected = dem::verletStableTimeStep(oneContact(r, m, law, overlap, Vec3::UnitX()));

    const dem::BedStabilityReport report = dem::analyseBedStability(sim, fine());
    EXPECT_EQ(report.particleContacts, 1u);
    EXPECT_EQ(report.wallContacts, 0u);
    ASSERT_GE(report.contactsPerParticle.size(), 2u);
    EXPECT_EQ(report.contactsPerParticle[1], 2u);
    EXPECT_NEAR(report.stableTimeStep / expected, 1.0, 0.01) << "bed " << report.stableTimeStep << " model " << expected;

    // The verdict on a given step: a mode grows beyond the limit, none below it.
    dem::BedStabilityOptions judge;
    judge.relativeTolerance = 0.05;
    judge.timeStep = 1.05 * expected;
    const dem::BedStabilityReport beyond = dem::analyseBedStability(sim, judge);
    EXPECT_FALSE(beyond.stableAtRunStep);
    EXPECT_GT(beyond.growthAtRunStep, 10.0 / judge.iterations);
    EXPECT_DOUBLE_EQ(beyond.runTimeStep, 1.05 * expected);
    judge.timeStep = 0.95 * expected;
    EXPECT_TRUE(dem::analyseBedStability(sim, judge).stableAtRunStep);
}

// A region holding one of the two spheres: the other is held fixed, as a
// wall, so the contact acts undoubled.
TEST(BedStability, ParticlesOutsideTheRegionAreHeldFixed) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = 1e-3, m = 2500.0 * 4.0 / 3.0 * kPi * r * r * r, overlap = 2e-3 * r;
    dem::Simulation sim(settings(1e-7, Vec3::Zero(), dem::RollingModel::CDT), mats, table, {});
    sim.insert({{Vec3(-r + 0.5 * overlap, 0, 0), r}, {Vec3(r - 0.5 * overlap, 0, 0), r}}, 0, Vec3::Zero());
    const dem::LinearContact law = dem::linearHertzContact(table(0, 0), 0.5 * r, 0.5 * m, overlap);
    const double expected = dem::verletStableTimeStep(oneContact(r, m, law, overlap, Vec3::UnitX()));
    dem::BedStabilityOptions o = fine();
    o.regionUpper = Vec3(0, 1, 1);  // x <= 0: the first sphere only
    const dem::BedStabilityReport report = dem::analyseBedStability(sim, o);
    EXPECT_EQ(report.particles, 1u);
    EXPECT_EQ(report.particleContacts, 0u);
    EXPECT_EQ(report.fixedParticleContacts, 1u);
    EXPECT_NEAR(report.stableTimeStep / expected, 1.0, 0.01) << "bed " << report.stableTimeStep << " model " << expected;
}

TEST(BedStability, ABedWithoutContactsHasNoLimit) {
    const std::vector<dem::Material> mats = sand();
    dem::Simulation sim(settings(1e-6, Vec3::Zero(), dem::RollingModel::CDT), mats, tableFor(mats), {});
    sim.insert({{Vec3(0, 0, 0), 1e-3}, {Vec3(3e-3, 0, 0), 1e-3}}, 0, Vec3::Zero());
    const dem::BedStabilityReport report = dem::analyseBedStability(sim);
    EXPECT_EQ(report.particleContacts + report.wallContacts, 0u);
    EXPECT_EQ(report.stableTimeStep, std::numeric_limits<double>::infinity());
    EXPECT_TRUE(report.stableAtRunStep);
}

}  // namespace
