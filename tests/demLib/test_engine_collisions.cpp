// Verification of dem::Simulation as a whole: binary collisions against the
// input restitution coefficient, energy conservation of an elastic gas, and
// the engine's refusal of bad input.  Every expected number is a closed form.
#include <gtest/gtest.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "demLib/error.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"

namespace {

using dem::Vec3;

// A soft "glass" (E reduced as usual in DEM): R = 1 mm gives a Rayleigh time
// of 1.22e-4 s and a 1 m/s pair impact of 2.7e-4 s.
dem::Material glass() { return {"glass", 5e6, 0.3, 2500.0}; }

dem::InteractionTable tableFor(const std::vector<dem::Material>& materials, const dem::PairCoefficients& c) {
    dem::InteractionTable table(materials.size());
    for (std::size_t a = 0; a < materials.size(); ++a)
        for (std::size_t b = a; b < materials.size(); ++b) table.set(materials, a, b, c);
    return table;
}

dem::Wall planeWall(const std::string& name, const Vec3& point, const Vec3& normal) {
    return dem::Wall{name, dem::PlaneWall(point, normal), dem::WallMotion(), 0};
}

dem::SimulationSettings noGravity(double dt) {
    dem::SimulationSettings s;
    s.timeStep = dt;
    s.gravity = Vec3::Zero();
    s.source = "test_engine_collisions";
    return s;
}

constexpr double kRadius = 1e-3;
constexpr double kPi = 3.14159265358979323846;

double sphereMass(double r, double density) { return density * 4.0 / 3.0 * kPi * r * r * r; }

// ---------------------------------------------------------------------------
// 1. Restitution.  Two equal spheres approach head-on with relative speed
// 2 v; the contact law promises (relative normal speed after) / (before) = e.
// The measurement waits until the overlap has closed and both spheres fly
// freely, so it includes the whole force history (also the small attractive
// tail of the dashpot, since LIGGGHTS' limitForce is off by default).

double pairRestitution(double e, double v, double dt) {
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    c.restitution = e;
    c.friction = 0.3;  // irrelevant head-on, on to show it does not leak in
    dem::Simulation sim(noGravity(dt), mats, tableFor(mats, c), {});
    const double gap = 0.1 * kRadius;
    sim.insert({{Vec3(-kRadius - gap, 0, 0), kRadius}}, 0, Vec3(v, 0, 0));
    sim.insert({{Vec3(kRadius + gap, 0, 0), kRadius}}, 0, Vec3(-v, 0, 0));
    const double before = 2.0 * v;
    // Free flight to contact, the impact and free flight apart again.
    const double tFlight = 2.0 * gap / before;
    const double m = sphereMass(kRadius, glass().density);
    const dem::InteractionProperties& p = sim.interactions()(0, 0);
    const double tContact = dem::hertzCollisionTime(0.5 * m, 0.5 * kRadius, p.youngsEff, before);
    // The time step must resolve the impact (LIGGGHTS' estimate, pair: m* = m/2).
    EXPECT_LT(dt, tContact / 100.0) << "tc = " << tContact;
    const long steps = static_cast<long>((tFlight + 3.0 * tContact) / dt);
    sim.step(steps);
    EXPECT_EQ(sim.lastStep().contacts.touchingPairs, 0u) << "still in contact";
    const auto& pv = sim.particles().velocity;
    const double after = (pv[1] - pv[0]).x();  // separating: particle 1 moves +x
    // Head-on: no tangential velocity and no spin may appear.
    EXPECT_NEAR(pv[0].y(), 0.0, 1e-12);
    EXPECT_NEAR(sim.particles().omega[0].norm(), 0.0, 1e-9);
    // Momentum is conserved exactly by the pair forces (equal masses).
    EXPECT_NEAR((pv[0] + pv[1]).norm(), 0.0, 1e-12 * v);
    return after / before;
}

double wallRestitution(double e, double v, double dt) {
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    c.restitution = e;
    c.friction = 0.3;
    dem::Simulation sim(noGravity(dt), mats, tableFor(mats, c),
                        {planeWall("floor", Vec3::Zero(), Vec3::UnitX())});
    const double gap = 0.1 * kRadius;
    sim.insert({{Vec3(kRadius + gap, 0, 0), kRadius}}, 0, Vec3(-v, 0, 0));
    const double m = sphereMass(kRadius, glass().density);
    const dem::InteractionProperties& p = sim.interactions()(0, 0);
    // Wall: m* = m, R* = R.
    const double tContact = dem::hertzCollisionTime(m, kRadius, p.youngsEff, v);
    EXPECT_LT(dt, tContact / 100.0) << "tc = " << tContact;
    sim.step(static_cast<long>((gap / v + 3.0 * tContact) / dt));
    EXPECT_EQ(sim.lastStep().contacts.wallContacts, 0u) << "still in contact";
    return sim.particles().velocity[0].x() / v;
}

TEST(EngineCollisions, PairRestitutionMatchesInputWithinOnePercent) {
    OneThread oneThread;
    const double dt = 1e-6;
    for (double e : {0.1, 0.5, 0.9}) {
        const double measured = pairRestitution(e, 1.0, dt);
        std::printf("pair  e_input %.2f  e_measured %.6f  ratio %.5f\n", e, measured, measured / e);
        EXPECT_NEAR(measured / e, 1.0, 0.01) << "e = " << e;
    }
}

TEST(EngineCollisions, WallRestitutionMatchesInputWithinOnePercent) {
    OneThread oneThread;
    const double dt = 1e-6;
    for (double e : {0.1, 0.5, 0.9}) {
        const double measured = wallRestitution(e, 1.0, dt);
        std::printf("wall  e_input %.2f  e_measured %.6f  ratio %.5f\n", e, measured, measured / e);
        EXPECT_NEAR(measured / e, 1.0, 0.01) << "e = " << e;
    }
}

// Hertz with the Tsuji dashpot gives an e that does not depend on the impact
// speed: a linear (constant-stiffness) dashpot would not.
TEST(EngineCollisions, RestitutionIndependentOfImpactSpeed) {
    OneThread oneThread;
    const double slow = pairRestitution(0.5, 0.1, 2e-6);
    const double fast = pairRestitution(0.5, 2.0, 5e-7);
    std::printf("pair e=0.5: v=0.1 -> %.6f, v=2 -> %.6f\n", slow, fast);
    EXPECT_NEAR(slow / fast, 1.0, 0.005);
}

// ---------------------------------------------------------------------------
// 2. Energy.  e = 1 (no dashpot), mu = 0 (no tangential force), no rolling
// resistance, no gravity: the gas in a closed box is conservative.  Total
// energy = kinetic + Hertz elastic energy of the contacts open at that moment,
// U = 8/15 Y* sqrt(R*) d^(5/2) per contact (the integral of 4/3 Y* sqrt(R*) d^(3/2)).
// Velocity Verlet is symplectic: its energy error stays bounded, O(dt^2) per
// impact, so the drift over 1e5 steps stays far below 1e-4.

double hertzEnergy(const dem::Simulation& sim) {
    const auto& p = sim.particles();
    double u = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            const double overlap = p.radius[i] + p.radius[j] - (p.position[i] - p.position[j]).norm();
            if (overlap <= 0.0) continue;
            const double rEff = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
            u += 8.0 / 15.0 * sim.interactions()(p.material[i], p.material[j]).youngsEff * std::sqrt(rEff) *
                 std::pow(overlap, 2.5);
        }
        for (const dem::Wall& w : sim.walls()) {
            std::vector<dem::WallContact> found;
            w.findContacts(p.position[i], p.radius[i], sim.time(), found);
            for (const dem::WallContact& c : found)
                if (c.overlap > 0.0)
                    u += 8.0 / 15.0 * sim.interactions()(p.material[i], w.materialIndex).youngsEff *
                         std::sqrt(p.radius[i]) * std::pow(c.overlap, 2.5);
        }
    }
    return u;
}

TEST(EngineCollisions, ElasticGasInClosedBoxConservesEnergy) {
    OneThread oneThread;
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    c.restitution = 1.0;
    c.friction = 0.0;
    const double L = 0.02;  // box edge
    std::vector<dem::Wall> box{
        planeWall("xMin", Vec3(0, 0, 0), Vec3::UnitX()),  planeWall("xMax", Vec3(L, 0, 0), -Vec3::UnitX()),
        planeWall("yMin", Vec3(0, 0, 0), Vec3::UnitY()),  planeWall("yMax", Vec3(0, L, 0), -Vec3::UnitY()),
        planeWall("zMin", Vec3(0, 0, 0), Vec3::UnitZ()),  planeWall("zMax", Vec3(0, 0, L), -Vec3::UnitZ())};
    const double dt = 1e-6;
    dem::SimulationSettings settings = noGravity(dt);
    settings.domain = dem::AxisAlignedBox{Vec3::Zero(), Vec3::Constant(L)};
    dem::Simulation sim(settings, mats, tableFor(mats, c), box);

    // 125 spheres on a 5^3 lattice (solid fraction 5 %), random velocities of
    // ~0.5 m/s: mean free path ~4.5 mm, ~10 impacts per sphere in 0.1 s.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int perSide = 5;
    const double spacing = L / perSide;
    for (int i = 0; i < perSide; ++i)
        for (int j = 0; j < perSide; ++j)
            for (int k = 0; k < perSide; ++k) {
                const Vec3 x = Vec3(i + 0.5, j + 0.5, k + 0.5) * spacing;
                sim.insert({{x, kRadius}}, 0, 0.5 * Vec3(u(rng), u(rng), u(rng)));
            }
    const double m = sphereMass(kRadius, glass().density);
    const double tContact = dem::hertzCollisionTime(0.5 * m, 0.5 * kRadius, sim.interactions()(0, 0).youngsEff,
                                                    2.0 * 0.5 * std::sqrt(3.0));
    EXPECT_LT(dt, tContact / 100.0) << "tc = " << tContact;

    // The lattice leaves every sphere clear of the others and of the walls.
    ASSERT_EQ(hertzEnergy(sim), 0.0);
    const double e0 = sim.particles().kineticEnergy();
    const long buildsBefore = sim.pairList().buildCount();
    long impacts = 0;
    double maxDeviation = 0.0;
    for (int block = 0; block < 100; ++block) {
        sim.step(1000);
        impacts += static_cast<long>(sim.lastStep().contacts.touchingPairs);
        const double e = sim.particles().kineticEnergy() + hertzEnergy(sim);
        maxDeviation = std::max(maxDeviation, std::abs(e - e0) / e0);
    }
    const double e1 = sim.particles().kineticEnergy() + hertzEnergy(sim);
    const double drift = std::abs(e1 - e0) / e0;
    std::printf("elastic gas: %ld steps, %ld list builds, final drift %.3e, max deviation %.3e\n",
                sim.stepCount(), sim.pairList().buildCount() - buildsBefore, drift, maxDeviation);
    EXPECT_EQ(sim.stepCount(), 100000);
    EXPECT_EQ(sim.lostCount(), 0u);
    EXPECT_LT(drift, 1e-4);
    EXPECT_LT(maxDeviation, 1e-4);
    // Kinetic energy alone, compared at a moment without any contact (as at
    // the start), when no energy is stored in the springs.
    long extra = 0;
    while (extra < 50000 &&
           (sim.lastStep().contacts.touchingPairs > 0 || sim.lastStep().contacts.wallContacts > 0)) {
        sim.step(1);
        ++extra;
    }
    ASSERT_EQ(sim.lastStep().contacts.touchingPairs + sim.lastStep().contacts.wallContacts, 0u)
        << "no contact-free moment found";
    const double kineticDrift = std::abs(sim.particles().kineticEnergy() - e0) / e0;
    std::printf("elastic gas: kinetic energy drift %.3e at the first contact-free step after %ld steps\n",
                kineticDrift, sim.stepCount());
    EXPECT_LT(kineticDrift, 1e-4);
    // The gas really collided (the list was rebuilt, spheres changed direction).
    EXPECT_GT(sim.pairList().buildCount() - buildsBefore, 10);
}

// ---------------------------------------------------------------------------
// 7. Bad input.

TEST(EngineInput, ParticleInsideWallIsRejectedNamingTheWall) {
    OneThread oneThread;
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    c.restitution = 0.5;
    dem::Simulation sim(noGravity(1e-6), mats, tableFor(mats, c),
                        {planeWall("dieFloor", Vec3::Zero(), Vec3::UnitZ())});
    try {
        sim.insert({{Vec3(0, 0, 0.5 * kRadius), kRadius}}, 0, Vec3::Zero());
        FAIL() << "no InputError";
    } catch (const dem::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("dieFloor"), std::string::npos) << what;
        EXPECT_NE(what.find("expected"), std::string::npos) << what;
    }
    EXPECT_EQ(sim.particles().size(), 0u);  // nothing half-inserted
    // Touching (zero overlap) is fine.
    EXPECT_NO_THROW(sim.insert({{Vec3(0, 0, kRadius), kRadius}}, 0, Vec3::Zero()));
}

TEST(EngineInput, NonPositiveRadiusIsRejected) {
    OneThread oneThread;
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    dem::Simulation sim(noGravity(1e-6), mats, tableFor(mats, c), {});
    EXPECT_THROW(sim.insert({{Vec3::Zero(), 0.0}}, 0, Vec3::Zero()), dem::InputError);
    EXPECT_THROW(sim.insert({{Vec3::Zero(), -1e-3}}, 0, Vec3::Zero()), dem::InputError);
    try {
        sim.insert({{Vec3::Zero(), -1e-3}}, 0, Vec3::Zero(), "case.json: particles");
        FAIL() << "no InputError";
    } catch (const dem::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("case.json: particles"), std::string::npos) << what;
        EXPECT_NE(what.find("expected a positive radius"), std::string::npos) << what;
    }
}

// Inserts one sphere at the origin and returns the InputError's message (a
// failure is recorded if the insertion is accepted).
std::string rejectedInsertion(dem::Simulation& sim) {
    try {
        sim.insert({{Vec3::Zero(), kRadius}}, 0, Vec3::Zero());
    } catch (const dem::InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
}

// A number as the error messages print it (default ostream formatting).
std::string printed(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

TEST(EngineInput, TooLargeTimeStepIsRejectedNamingBothValues) {
    OneThread oneThread;
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    const double rayleigh = dem::rayleighTime(kRadius, 2500.0, 5e6, 0.3);
    // Closed form of LIGGGHTS' Rayleigh time for this sphere.
    const double shear = 5e6 / 2.6;
    EXPECT_NEAR(rayleigh, kPi * kRadius * std::sqrt(2500.0 / shear) / (0.1631 * 0.3 + 0.8766), 1e-15);
    const double allowed = 0.2 * rayleigh;
    const double dt = 3.0 * allowed;
    dem::SimulationSettings settings = noGravity(dt);
    dem::Simulation sim(settings, mats, tableFor(mats, c), {});
    const std::string what = rejectedInsertion(sim);
    EXPECT_NE(what.find("timeStep"), std::string::npos) << what;
    EXPECT_NE(what.find(printed(dt)), std::string::npos) << what << " lacks " << printed(dt);
    EXPECT_NE(what.find(printed(allowed)), std::string::npos) << what << " lacks " << printed(allowed);
    EXPECT_NE(what.find("expected"), std::string::npos) << what;
    EXPECT_EQ(sim.particles().size(), 0u);  // a rejected insertion adds nothing
    // Just below the limit is accepted.
    dem::Simulation fine(noGravity(0.99 * allowed), mats, tableFor(mats, c), {});
    EXPECT_NO_THROW(fine.insert({{Vec3::Zero(), kRadius}}, 0, Vec3::Zero()));
    EXPECT_NEAR(fine.maxAllowedTimeStep(), allowed, 1e-12 * allowed);
    // The override lets it through.
    settings.allowLargeTimeStep = true;
    dem::Simulation forced(settings, mats, tableFor(mats, c), {});
    EXPECT_NO_THROW(forced.insert({{Vec3::Zero(), kRadius}}, 0, Vec3::Zero()));
    EXPECT_EQ(forced.particles().size(), 1u);
}

TEST(EngineInput, HertzLimitBindsAtHighImpactVelocity) {
    // At 50 m/s impacts the Hertz collision time of two glass spheres is shorter
    // than the Rayleigh time: 0.1 x Hertz is the binding limit, and a step
    // between the two limits must be refused naming the Hertz value.
    OneThread oneThread;
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    dem::SimulationSettings settings = noGravity(1e-9);
    settings.impactVelocity = 50.0;
    const double mass = sphereMass(kRadius, 2500.0);
    // Y* of two equal spheres: E / (2 (1 - nu^2)); head-on at twice the impact speed
    const double yStar = 5e6 / (2.0 * (1.0 - 0.3 * 0.3));
    const double hertz = dem::hertzCollisionTime(mass, 0.5 * kRadius, yStar, 2.0 * 50.0);
    const double rayleigh = dem::rayleighTime(kRadius, 2500.0, 5e6, 0.3);
    const double hertzLimit = 0.1 * hertz;
    ASSERT_LT(hertzLimit, 0.2 * rayleigh);  // the case tests what it says
    {
        dem::Simulation probe(settings, mats, tableFor(mats, c), {});
        probe.insert({{Vec3::Zero(), kRadius}}, 0, Vec3::Zero());
        EXPECT_NEAR(probe.maxAllowedTimeStep(), hertzLimit, 1e-12 * hertzLimit);
        EXPECT_NEAR(probe.timeStepLimits().hertz, hertzLimit, 1e-12 * hertzLimit);
        EXPECT_NEAR(probe.timeStepLimits().rayleigh, 0.2 * rayleigh, 1e-12 * rayleigh);
    }
    settings.timeStep = 0.5 * (hertzLimit + 0.2 * rayleigh);  // allowed by Rayleigh only
    dem::Simulation sim(settings, mats, tableFor(mats, c), {});
    const std::string what = rejectedInsertion(sim);
    EXPECT_NE(what.find("Hertz"), std::string::npos) << what;
    EXPECT_NE(what.find("impactVelocity"), std::string::npos) << what;
    EXPECT_NE(what.find(printed(hertzLimit)), std::string::npos) << what << " lacks " << printed(hertzLimit);
    settings.timeStep = 0.99 * hertzLimit;
    dem::Simulation fine(settings, mats, tableFor(mats, c), {});
    EXPECT_NO_THROW(fine.insert({{Vec3::Zero(), kRadius}}, 0, Vec3::Zero()));
}

}  // namespace
