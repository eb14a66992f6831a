// Stability of the explicit integration for contacts held closed
// (contact_stability.hpp): the linear model against the closed form of one
// damped mode, the engine against the model's threshold (a sphere resting on a
// floor turns unstable within 2 % of the predicted step), and the capillary
// time-step limit of Simulation.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "demLib/contact_rolling_resistance.hpp"
#include "demLib/contact_stability.hpp"
#include "demLib/error.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"

namespace {

using dem::Vec3;
constexpr double kPi = 3.14159265358979323846;

dem::InteractionTable tableFor(const std::vector<dem::Material>& materials, const dem::PairCoefficients& c) {
    dem::InteractionTable table(materials.size());
    for (std::size_t a = 0; a < materials.size(); ++a)
        for (std::size_t b = a; b < materials.size(); ++b) table.set(materials, a, b, c);
    return table;
}

// x'' = -w^2 x - 2 z w x', integrated by velocity Verlet with the damping seen
// at the half-step velocity: with u = v(n - 1/2) the step is
// u' = (1 - 2 z w h) u - w^2 h x, x' = x + h u', of trace 2 - (wh)^2 - 2 z w h and
// determinant 1 - 2 z w h; Jury's conditions give  w h <= 2 (sqrt(1 + z^2) - z).
TEST(ContactStability, OneDampedModeMatchesTheClosedForm) {
    const double mass = 2.0, stiffness = 800.0;  // w = 20 rad/s
    const double w = std::sqrt(stiffness / mass);
    for (double zeta : {0.0, 0.3, 0.591, 1.0, 2.0}) {
        dem::ContactClusterModel model;
        model.mass.diagonal().setConstant(mass);
        model.stiffness.diagonal().setConstant(stiffness);
        model.damping.diagonal().setConstant(2.0 * zeta * w * mass);
        const double expected = 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / w;
        // The bisection counts a mode as growing from a spectral radius of 1 + 1e-5
        // (neutral modes come out of the eigensolver a few 1e-7 above 1): up to
        // ~2e-6 beyond the bound.
        EXPECT_NEAR(dem::verletStableTimeStep(model), expected, 1e-5 * expected) << "zeta " << zeta;
        EXPECT_LE(dem::verletSpectralRadius(model, 0.999 * expected), 1.0 + 1e-9);
        EXPECT_GT(dem::verletSpectralRadius(model, 1.001 * expected), 1.0 + 1e-7);
    }
}

TEST(ContactStability, HeavierDampingAndMoreContactsLowerTheLimit) {
    dem::InteractionProperties props =
        dem::makeInteraction({"sand", 5e6, 0.3, 2650.0}, {"sand", 5e6, 0.3, 2650.0}, {0.1, 0.7, 0.0, 0.0});
    const double r = 0.5e-3, m = 2650.0 * 4.0 / 3.0 * kPi * r * r * r;
    const dem::LinearContact contact = dem::linearHertzContact(props, 0.5 * r, 0.5 * m, 1e-6);
    // Tangent stiffness of Hertz: dF/dd = 2 Y* sqrt(R* d).
    EXPECT_NEAR(contact.normalStiffness, 2.0 * props.youngsEff * std::sqrt(0.5 * r * 1e-6),
                1e-12 * contact.normalStiffness);
    const double six = dem::verletStableTimeStep(dem::cubicContactCluster(r, m, contact, r));
    dem::ContactClusterModel two;
    two.mass.diagonal() << m, m, m, 0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r;
    dem::addContact(two, r, Vec3::UnitZ(), contact);
    dem::addContact(two, r, -Vec3::UnitZ(), contact);
    EXPECT_LT(six, dem::verletStableTimeStep(two));
    dem::LinearContact undamped = contact;
    undamped.normalDamping = undamped.tangentialDamping = 0.0;
    EXPECT_LT(six, 0.8 * dem::verletStableTimeStep(dem::cubicContactCluster(r, m, undamped, r)));
}

// A sphere resting on a floor under gravity, with heavy damping (e = 0.1): one
// contact, whose sliding mode (translation and spin together, effective mass
// m/3.5) is the fastest.  Given a small sliding velocity, the contact point's
// slip dies out below the predicted step and grows above it.
double slipAfter(double dtFactor, dem::RollingModel rolling = dem::RollingModel::None) {
    OneThread oneThread;
    const dem::Material glass{"glass", 5e6, 0.3, 2500.0};
    const std::vector<dem::Material> mats{glass};
    dem::PairCoefficients c;
    c.restitution = 0.1;
    c.friction = 0.5;
    c.rollingFriction = 0.5;
    c.rollingViscousDamping = 0.3;
    const dem::InteractionTable table = tableFor(mats, c);
    const double r = 1e-3, m = 2500.0 * 4.0 / 3.0 * kPi * r * r * r, g = 9.81;
    // Rest on a wall: R* = R, m* = m; m g = (4/3 Y*) sqrt(R) d^1.5.
    const double overlap = std::pow(m * g / (table(0, 0).normalStiffnessFactor * std::sqrt(r)), 2.0 / 3.0);
    dem::ContactClusterModel model;
    model.mass.diagonal() << m, m, m, 0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r;
    dem::addContact(model, r, -Vec3::UnitZ(),
                    dem::linearHertzContact(table(0, 0), r, m, overlap, rolling, dem::rollingInertiaWall(m, r)));
    const double predicted = dem::verletStableTimeStep(model);

    dem::SimulationSettings settings;
    settings.timeStep = dtFactor * predicted;
    settings.gravity = Vec3(0, 0, -g);
    settings.allowLargeTimeStep = true;  // the point is to go beyond the limit
    settings.source = "test_contact_stability";
    settings.forces.rolling = rolling;
    dem::Simulation sim(settings, mats, table,
                        {dem::Wall{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0}});
    sim.insert({{Vec3(0, 0, r - 0.99e-6 * r), r}}, 0, Vec3(1e-5, 0, 0));
    // Slip of the contact point (0, 0, -r): v + w x (-r z).  Rolling without
    // slip is the neutral mode and keeps its speed; it does not count.
    auto slip = [&] {
        const Vec3 w = sim.particles().omega[0];
        return (sim.particles().velocity[0] + w.cross(Vec3(0, 0, -r))).head<2>().norm();
    };
    double largest = 0.0;
    for (int k = 0; k < 4000; ++k) {
        sim.step(1);
        if (k >= 3800) largest = std::max(largest, slip());
    }
    return largest;
}

TEST(ContactStability, EngineTurnsUnstableWhereTheModelSays) {
    // Measured: the slip is 3.3e-9 m/s at 0.5-0.99 x the predicted step (from
    // 1e-5 m/s at the start) and 5e-3 m/s, capped by friction, at 1.01-1.1 x.
    EXPECT_LT(slipAfter(0.98), 1e-7) << "slip at 0.98 x the predicted step";
    EXPECT_GT(slipAfter(1.02), 1e-4) << "slip at 1.02 x the predicted step";
    // With a rolling spring (EPSD2) or spring and dashpot (EPSD, eta_r = 0.3) in the
    // model as in the contact law, the onset moves with it.
    for (dem::RollingModel rolling : {dem::RollingModel::EPSD2, dem::RollingModel::EPSD}) {
        EXPECT_LT(slipAfter(0.98, rolling), 1e-7) << "rolling model " << static_cast<int>(rolling);
        EXPECT_GT(slipAfter(1.02, rolling), 1e-4) << "rolling model " << static_cast<int>(rolling);
    }
}

// The paper's sand (Table 3) and its sand-sand coefficients (Table 2).
dem::Material paperSand() { return {"sand", 5e6, 0.3, 2650.0}; }
dem::PairCoefficients paperSandPair() {
    dem::PairCoefficients c;
    c.restitution = 0.1;
    c.friction = 0.7;
    c.rollingFriction = 0.5;
    return c;
}

// EPSD2's rolling spring stiffens the spin modes: a lower limit than CDT's.
TEST(ContactStability, RollingSpringLowersTheWetLimit) {
    const dem::Material sand = paperSand();
    const dem::PairCoefficients c = paperSandPair();
    const dem::InteractionProperties props = dem::makeInteraction(sand, sand, c);
    const double scale = std::pow(5.0, 2.0142);
    auto limit = [&](dem::RollingModel rolling) {
        return dem::capillaryClusterStableTimeStep(0.225e-3, sand, 1.25e-3, sand, props, dem::CapillaryParameters{},
                                                   scale, rolling);
    };
    EXPECT_LT(limit(dem::RollingModel::EPSD2), 0.99 * limit(dem::RollingModel::CDT));
}

// Spheres of radius R around one of radius r = ratio R: 12 for equal ones
// (fcc, icosahedron), 6 in an octahedral hole (ratio sqrt 2 - 1), 4 in a
// tetrahedral one (sqrt(3/2) - 1), and the Tammes counts in between.
TEST(ContactStability, ContactNumberAroundASphere) {
    EXPECT_EQ(dem::contactNumberAround(1.0), 12);
    EXPECT_EQ(dem::contactNumberAround(0.91), 12);
    EXPECT_EQ(dem::contactNumberAround(0.89), 10);
    EXPECT_EQ(dem::contactNumberAround(0.7), 8);
    EXPECT_EQ(dem::contactNumberAround(std::sqrt(2.0) - 1.0 + 1e-6), 6);
    EXPECT_EQ(dem::contactNumberAround(std::sqrt(1.5) - 1.0 + 1e-6), 4);
    EXPECT_EQ(dem::contactNumberAround(0.18), 3);
    EXPECT_EQ(dem::contactNumberAround(0.8), 9);
    EXPECT_EQ(dem::contactNumberAround(0.6), 7);
    // Each threshold 1 / sin(d_N / 2) - 1 from the Tammes separations d_N [deg]: N fits just
    // above it, not just below (N = 11 needs as much room as 12, N = 5 as 6).
    const double deg = kPi / 180.0;
    const std::vector<std::pair<int, double>> tammes{{12, 63.4349}, {10, 66.1468}, {9, 70.5288}, {8, 74.8585},
                                                     {7, 77.8695}, {6, 90.0}, {4, 109.4712}, {3, 120.0}};
    int below = 0;
    for (const auto& [count, separation] : tammes) {
        const double threshold = 1.0 / std::sin(0.5 * separation * deg) - 1.0;
        // (the table holds the thresholds rounded up to 1e-6)
        EXPECT_EQ(dem::contactNumberAround(threshold * (1.0 + 1e-5)), count) << count;
        const int next = dem::contactNumberAround(threshold * (1.0 - 1e-5));
        EXPECT_LT(next, count) << count;
        if (below > 0) {
            EXPECT_EQ(below, count) << "the count below the previous threshold";
        }
        below = next;
    }
    // (Twelve around an equal sphere touch it without overlapping each other: the
    // icosahedron's neighbouring vertices are acos(1/sqrt 5) = 63.43 deg apart, more
    // than the 60 deg that two touching equal spheres subtend.)
}

// The wet-bed cluster of a grain among equal ones: twelve contacts in an
// icosahedron act as the six of the cube with springs and dashpots doubled
// (both arrangements have sum n n^T = N/3 I and sum n = 0).
TEST(ContactStability, TwelveContactsActAsSixDoubled) {
    const dem::Material sand = paperSand();
    const dem::PairCoefficients c = paperSandPair();
    const dem::InteractionTable table = tableFor({sand}, c);
    const double r = 0.6e-3, m = 2650.0 * 4.0 / 3.0 * kPi * r * r * r, overlap = 0.02 * r;
    for (dem::RollingModel rolling : {dem::RollingModel::CDT, dem::RollingModel::EPSD2}) {
        dem::LinearContact contact = dem::linearHertzContact(table(0, 0), 0.5 * r, 0.5 * m, overlap, rolling);
        dem::ContactClusterModel icosahedron;
        icosahedron.mass.diagonal() << m, m, m, 0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r;
        const double phi = 0.5 * (1.0 + std::sqrt(5.0));
        for (double a : {1.0, -1.0})
            for (double b : {phi, -phi}) {
                dem::addContact(icosahedron, r - 0.5 * overlap, Eigen::Vector3d(0, a, b), contact);
                dem::addContact(icosahedron, r - 0.5 * overlap, Eigen::Vector3d(a, b, 0), contact);
                dem::addContact(icosahedron, r - 0.5 * overlap, Eigen::Vector3d(b, 0, a), contact);
            }
        for (double* part : {&contact.normalStiffness, &contact.tangentialStiffness, &contact.normalDamping,
                             &contact.tangentialDamping, &contact.rollingStiffness, &contact.rollingDamping})
            *part *= 2.0;
        const double cube = dem::verletStableTimeStep(dem::cubicContactCluster(r, m, contact, r - 0.5 * overlap));
        EXPECT_NEAR(dem::verletStableTimeStep(icosahedron) / cube, 1.0, 1e-6) << static_cast<int>(rolling);
    }
    // The engine's limit for equal grains counts twelve neighbours: 1/sqrt(2)
    // of six's without damping; with it, a little less (the doubled dashpots
    // damp harder).  Measured on a settled monodisperse wet bed: docs/engine.md.
    const dem::CapillaryParameters water{};
    const auto cluster = [&](double neighbourRadius, int count) {
        return dem::capillaryClusterStableTimeStep(r, sand, neighbourRadius, sand, table(0, 0), water, 25.0,
                                                   dem::RollingModel::CDT, count);
    };
    EXPECT_DOUBLE_EQ(cluster(r, 0), cluster(r, 12));             // equal grains: twelve
    EXPECT_LT(cluster(r, 12), 0.75 * cluster(r, 6));              // measured 0.52 here
    EXPECT_DOUBLE_EQ(cluster(r / 0.8, 0), cluster(r / 0.8, 9));  // ratio 0.8: nine
    EXPECT_DOUBLE_EQ(cluster(r / 0.18, 0), cluster(r / 0.18, 6));  // F32's 0.18 would fit 3: six at least
}

// Eq 1 at contact: pi gamma sqrt(R1 R2) (exp(B) + C), largest at the smallest
// reduced volume sampled (1e-5) for theta = 0.
TEST(ContactStability, CapillaryContactForceBoundIsEq1AtTheSmallestVolume) {
    const dem::CapillaryParameters water{0.072, 0.0};
    const double r1 = 0.2e-3, r2 = 0.6e-3, logV = std::log(1e-5);
    const double expected =
        kPi * 0.072 * std::sqrt(r1 * r2) * (std::exp(-0.0082 * logV + 0.48) + 0.0018 * logV + 0.078);
    EXPECT_NEAR(dem::capillaryContactForceBound(r1, r2, water, 1.0), expected, 1e-10 * expected);
    EXPECT_NEAR(dem::capillaryContactForceBound(r2, r1, water, 25.0), 25.0 * expected, 25e-10 * expected);
}

dem::SimulationSettings wetSettings(double dt, double forceScale) {
    dem::SimulationSettings s;
    s.timeStep = dt;
    s.source = "wet.dict";
    s.forces.cohesion = dem::CohesionModel::Capillary;
    s.forces.capillaryForceScale = forceScale;
    return s;
}

// The limit of a wet bed: six of the largest grains around the smallest (F32: ratio 0.18),
// pressed by the coarse-grained capillary force.  A stronger force (coarse
// grain l^k) presses harder: a smaller limit.  The engine refuses a step above
// it, naming the keyword, and takes one below.
TEST(ContactStability, WetBedTimeStepLimitIsChecked) {
    OneThread oneThread;
    const dem::Material sand{"sand", 5e6, 0.3, 2650.0};
    const std::vector<dem::Material> mats{sand};
    dem::PairCoefficients c;
    c.restitution = 0.1;
    c.friction = 0.7;
    const dem::InteractionTable table = tableFor(mats, c);
    const double small = 0.225e-3, large = 1.25e-3;  // F32 x 5: 0.09 and 0.5 mm grains
    const double scale = std::pow(5.0, 2.0142);
    const double limit = dem::capillaryClusterStableTimeStep(small, sand, large, sand, table(0, 0),
                                                             dem::CapillaryParameters{}, scale);
    // Measured with demRun (docs/engine.md): a wet F32 x 5 bed rests at 3.5e-6 s, rattles from 4.2e-6 s.
    EXPECT_GT(limit, 3.4e-6);
    EXPECT_LT(limit, 4.0e-6);
    EXPECT_GT(dem::capillaryClusterStableTimeStep(small, sand, large, sand, table(0, 0), dem::CapillaryParameters{},
                                                  1.0),
              1.5 * limit);
    // The engine allows 0.9 of it by default (room for the bed's weight, docs/engine.md).
    const double fraction = dem::SimulationSettings{}.maxCapillaryClusterFraction;
    EXPECT_DOUBLE_EQ(fraction, 0.9);
    const double allowed = fraction * limit;
    const std::vector<dem::InsertedParticle> bed{{Vec3(0, 0, 0), small}, {Vec3(0.01, 0, 0), large}};
    dem::Simulation probe(wetSettings(1e-9, scale), mats, table, {});
    probe.insert(bed, 0, Vec3::Zero());
    EXPECT_NEAR(probe.timeStepLimits().capillary, allowed, 1e-9 * allowed);
    EXPECT_NEAR(probe.maxAllowedTimeStep(), allowed, 1e-9 * allowed);  // below Rayleigh and Hertz here

    dem::Simulation tooLarge(wetSettings(1.05 * allowed, scale), mats, table, {});
    try {
        tooLarge.insert(bed, 0, Vec3::Zero());
        ADD_FAILURE() << "a time step above the wet-bed limit was accepted";
    } catch (const dem::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("wet.dict"), std::string::npos) << what;
        EXPECT_NE(what.find("maxCapillaryClusterFraction"), std::string::npos) << what;
        EXPECT_NE(what.find("expected timeStep"), std::string::npos) << what;
    }
    EXPECT_EQ(tooLarge.particles().size(), 0u);
    dem::Simulation fine(wetSettings(0.99 * allowed, scale), mats, table, {});
    EXPECT_NO_THROW(fine.insert(bed, 0, Vec3::Zero()));
    // Dry, the same step is only held to the Rayleigh and Hertz limits.
    dem::SimulationSettings dry = wetSettings(1.05 * allowed, scale);
    dry.forces.cohesion = dem::CohesionModel::None;
    dem::Simulation dryBed(dry, mats, table, {});
    EXPECT_NO_THROW(dryBed.insert(bed, 0, Vec3::Zero()));
    EXPECT_TRUE(std::isinf(dryBed.timeStepLimits().capillary));

    // A restart file written beyond the limit (forced) is not continued without the override.
    dem::SimulationSettings forcedSettings = wetSettings(1.05 * allowed, scale);
    forcedSettings.allowLargeTimeStep = true;
    dem::Simulation forced(forcedSettings, mats, table, {});
    forced.insert(bed, 0, Vec3::Zero());
    forced.step(2);
    const std::string path =
        (std::filesystem::temp_directory_path() / ("test_contact_stability_" + std::to_string(::getpid()) + ".h5"))
            .string();
    forced.writeRestart(path);
    dem::Simulation continued(wetSettings(1.05 * allowed, scale), mats, table, {});
    try {
        continued.readRestart(path);
        ADD_FAILURE() << "a restart beyond the wet-bed limit was continued";
    } catch (const dem::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("restart file '" + path + "'"), std::string::npos) << what;
        EXPECT_NE(what.find("maxCapillaryClusterFraction"), std::string::npos) << what;
    }
    dem::Simulation overridden(forcedSettings, mats, table, {});
    EXPECT_NO_THROW(overridden.readRestart(path));
    EXPECT_EQ(overridden.particles().size(), 2u);
    std::filesystem::remove(path);
}

}  // namespace
