// The walls' forces a front end logs (RunTotals::wallForces): the mean over
// the steps since Simulation::restartWallForceMeans(), i.e. the impulse the
// particles gave each wall over that time divided by the time.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "demLib/simulation.hpp"
#include "sand_without_gravity.hpp"

namespace {

using dem::Vec3;

TEST(WallForceMeans, TheMeanIsTheImpulseOverTheInterval) {
    // A sphere thrown down at 0.5 m/s bounces once off a floor (contact of
    // about 0.1 ms) within 2 ms and flies again: over the interval the floor's
    // mean force times the time is what changed the sphere's momentum, less
    // gravity's share:  F T = -(m dv + m g T) (the force on the floor).
    dem::SimulationSettings settings;
    settings.timeStep = 1e-6;
    settings.gravity = Vec3(0, 0, -9.81);
    dem::Simulation sim =
        sandSimulation({{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0}}, settings);
    sim.insert({{Vec3(0, 0, 1.2e-3), 1e-3}}, 0, Vec3(0, 0, -0.5));
    sim.step(10);  // forces computed, still in flight
    sim.restartWallForceMeans();
    const double m = sim.particles().mass[0];
    const double v0 = sim.particles().velocity[0].z();
    const long steps = 2000;
    sim.step(steps);
    const double v1 = sim.particles().velocity[0].z();
    const double T = steps * settings.timeStep;
    ASSERT_GT(v1, 0.1);                                  // bounced
    ASSERT_GT(sim.particles().position[0].z(), 1e-3);    // and flies again
    EXPECT_EQ(sim.wallForces()[0], Vec3::Zero());        // the last step's force: none
    const double logged = sim.totalsOverRanks().wallForces[0].z();
    const double impulse = -(m * (v1 - v0) + m * 9.81 * T);
    std::printf("mean force on the floor %.9g N over %g s; -(m dv + m g T) / T = %.9g N\n", logged, T, impulse / T);
    EXPECT_NEAR(logged * T, impulse, 1e-9 * std::abs(impulse));
    // Started again: a flight without contact gives zero.
    sim.restartWallForceMeans();
    sim.step(100);
    EXPECT_EQ(sim.totalsOverRanks().wallForces[0], Vec3::Zero());
}

TEST(WallForceMeans, WithoutAStepSinceTheStartTheLastStepsForceIsGiven) {
    dem::SimulationSettings settings;
    settings.timeStep = 1e-6;
    settings.gravity = Vec3(0, 0, -9.81);
    dem::Simulation sim =
        sandSimulation({{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0}}, settings);
    sim.insert({{Vec3(0, 0, 1e-3), 1e-3}}, 0, Vec3::Zero());  // on the floor, pressed by its weight
    sim.step(200);
    sim.restartWallForceMeans();
    EXPECT_EQ(sim.totalsOverRanks().wallForces[0], sim.wallForces()[0]);
    EXPECT_LT(sim.wallForces()[0].z(), 0.0);
}

}  // namespace
