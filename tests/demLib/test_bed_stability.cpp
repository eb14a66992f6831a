// The stable time step of a bed from its actual contacts (bed_stability.hpp)
// against the one-particle model of contact_stability.hpp where that model is
// exact: a sphere resting on a floor, and two free spheres in contact (their
// relative motion is one sphere's against a fixed one with the springs and
// dashpots doubled).  The wet beds it was validated on are in tests/wetColumn.
#include <gtest/gtest.h>

#include <Eigen/Dense>
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

// The spheres of these tests: 1 mm of sand (density 2500).
constexpr double kRadius = 1e-3;
const double kMass = 2500.0 * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;

// Two free spheres of radius r along x, touching with `overlap`.
void insertTouchingPair(dem::Simulation& sim, double r, double overlap) {
    sim.insert({{Vec3(-r + 0.5 * overlap, 0, 0), r}, {Vec3(r - 0.5 * overlap, 0, 0), r}}, 0, Vec3::Zero());
}

dem::BedStabilityOptions fine() {
    dem::BedStabilityOptions o;
    o.relativeTolerance = 0.002;
    return o;
}

TEST(BedStability, SphereOnAFloorMatchesTheOneParticleModel) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = kRadius, m = kMass;
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
    EXPECT_TRUE(report.stableAtRunStep);
}

TEST(BedStability, TwoFreeSpheresMatchTheRelativeMotionModel) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = kRadius, m = kMass, overlap = 2e-3 * r;
    // CDT: no rolling spring (the rolling mode of two spheres is not the slip
    // mode, so the doubled one-particle model is exact only without it).
    dem::Simulation sim(settings(1e-7, Vec3::Zero(), dem::RollingModel::CDT), mats, table, {});
    insertTouchingPair(sim, r, overlap);
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
    const double r = kRadius, m = kMass, overlap = 2e-3 * r;
    dem::Simulation sim(settings(1e-7, Vec3::Zero(), dem::RollingModel::CDT), mats, table, {});
    insertTouchingPair(sim, r, overlap);
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

// Three spheres with contacts of non-parallel normals (a floor, a neighbour
// tilted in x-z, one tilted in y-z) and EPSD2's rolling springs: the analysis
// against the velocity Verlet map of the same contacts assembled here as dense
// matrices from the contact-point kinematics and solved for its eigenvalues.
// (With one contact per particle, as above, a sign error in a lever arm, a
// normal or a rolling term changes nothing; here it does.)
TEST(BedStability, ContactsOfManyDirectionsMatchADenseEigenSolve) {
    const std::vector<dem::Material> mats = sand();
    const dem::InteractionTable table = tableFor(mats);
    const double r = 1e-3, pairOverlap = 3e-3 * r, wallOverlap = 2e-3 * r;
    dem::Simulation sim(settings(1e-7, Vec3::Zero(), dem::RollingModel::EPSD2), mats, table,
                        {dem::Wall{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0}});
    const Vec3 a(0, 0, r);
    const double gap = 2.0 * r - pairOverlap;
    const Vec3 b = a + gap * Vec3(std::sin(0.7), 0, std::cos(0.7));
    const Vec3 c = a + gap * Vec3(0, -std::sin(1.1), std::cos(1.1));
    sim.insert({{a, r}, {b, r}, {c, r}}, 0, Vec3::Zero());
    sim.particles().position[0].z() = r - wallOverlap;  // pressed into the floor (not allowed at insertion)
    const dem::ParticleStore& p = sim.particles();

    // Dense K and C: per contact, B maps the 18 coordinates to the contact point's
    // relative velocity (i minus j): tangential P_t (v_i - v_j - c_i n x w_i - c_j n x w_j),
    // normal n n^T (v_i - v_j), rolling P_t (w_i - w_j); K += B^T k B.
    const int dof = 18;
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dof, dof), C = K;
    auto cross = [](const Eigen::Vector3d& v) {
        Eigen::Matrix3d m;
        m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
        return m;
    };
    auto add = [&](int i, int j, const Eigen::Vector3d& n, double overlap, const dem::LinearContact& law) {
        const Eigen::Matrix3d Pn = n * n.transpose(), Pt = Eigen::Matrix3d::Identity() - Pn;
        Eigen::MatrixXd Bt = Eigen::MatrixXd::Zero(3, dof), Bn = Bt, Br = Bt;
        const double lever = r - 0.5 * overlap;
        Bt.block<3, 3>(0, 6 * i) = Pt;
        Bt.block<3, 3>(0, 6 * i + 3) = -lever * Pt * cross(n);
        Bn.block<3, 3>(0, 6 * i) = Pn;
        Br.block<3, 3>(0, 6 * i + 3) = Pt;
        if (j >= 0) {
            Bt.block<3, 3>(0, 6 * j) = -Pt;
            Bt.block<3, 3>(0, 6 * j + 3) = -lever * Pt * cross(n);
            Bn.block<3, 3>(0, 6 * j) = -Pn;
            Br.block<3, 3>(0, 6 * j + 3) = -Pt;
        }
        K += law.tangentialStiffness * Bt.transpose() * Bt + law.normalStiffness * Bn.transpose() * Bn +
             law.rollingStiffness * Br.transpose() * Br;
        C += law.tangentialDamping * Bt.transpose() * Bt + law.normalDamping * Bn.transpose() * Bn +
             law.rollingDamping * Br.transpose() * Br;
    };
    const double m = p.mass[0];
    for (int j : {1, 2}) {
        const Vec3 d = p.position[j] - p.position[0];
        const double overlap = 2.0 * r - d.norm();
        add(0, j, d.normalized(), overlap,
            dem::linearHertzContact(table(0, 0), 0.5 * r, 0.5 * m, overlap, dem::RollingModel::EPSD2));
    }
    add(0, -1, -Eigen::Vector3d::UnitZ(), wallOverlap,
        dem::linearHertzContact(table(0, 0), r, m, wallOverlap, dem::RollingModel::EPSD2));
    Eigen::VectorXd inverseMass(dof);
    for (int i = 0; i < 3; ++i) {
        inverseMass.segment<3>(6 * i).setConstant(1.0 / m);
        inverseMass.segment<3>(6 * i + 3).setConstant(1.0 / (0.4 * m * r * r));
    }
    const Eigen::MatrixXd AK = inverseMass.asDiagonal() * K, AC = inverseMass.asDiagonal() * C;
    auto spectralRadius = [&](double dt) {
        // u' = u - dt (AK x + AC u), x' = x + dt u'
        Eigen::MatrixXd step(2 * dof, 2 * dof);
        const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dof, dof);
        step.topLeftCorner(dof, dof) = I - dt * dt * AK;
        step.topRightCorner(dof, dof) = dt * (I - dt * AC);
        step.bottomLeftCorner(dof, dof) = -dt * AK;
        step.bottomRightCorner(dof, dof) = I - dt * AC;
        return Eigen::EigenSolver<Eigen::MatrixXd>(step, false).eigenvalues().cwiseAbs().maxCoeff();
    };
    // Free directions make defective eigenvalues 1 that come out a little above 1.
    double low = 0.0, high = 2.0 / std::sqrt(Eigen::EigenSolver<Eigen::MatrixXd>(AK, false).eigenvalues().real().maxCoeff());
    while (high - low > 1e-4 * high) {
        const double mid = 0.5 * (low + high);
        (spectralRadius(mid) <= 1.0 + 1e-4 ? low : high) = mid;
    }
    ASSERT_GT(spectralRadius(1.02 * low), 1.001);  // a real instability beyond it

    const dem::BedStabilityReport report = dem::analyseBedStability(sim, fine());
    EXPECT_EQ(report.particleContacts, 2u);
    EXPECT_EQ(report.wallContacts, 1u);
    EXPECT_NEAR(report.stableTimeStep / low, 1.0, 0.01) << "bed " << report.stableTimeStep << " dense " << low;
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
