// A wall under load (WallMotion::addLoad): lowered by a hoist no faster than
// its speed, resting under its weight on what it touches, drawn back at its
// speed; its state in restart files and over ranks.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "decomposition_cases.hpp"
#include "sand_without_gravity.hpp"
#include "demLib/communicator.hpp"
#include "demLib/error.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/simulation.hpp"
#include "demLib/wall_motion.hpp"

namespace {

using dem::Vec3;

dem::WallLoad stampLoad(double tStart, double tRaise, double mass, double speed, double stroke) {
    dem::WallLoad load;
    load.tStart = tStart;
    load.tRaise = tRaise;
    load.direction = Vec3(0, 0, -2);  // normalised by addLoad
    load.mass = mass;
    load.speed = speed;
    load.stroke = stroke;
    return load;
}

TEST(WallLoad, HoistLowersAtItsSpeedToTheStopAndDrawsBack) {
    // Nothing under it: gravity pulls, the hoist holds it to 0.01 m/s, the
    // stop at 5 mm holds it there until it is raised at 1.0 s.
    dem::WallMotion m;
    m.addLoad(stampLoad(0.2, 1.0, 0.5, 0.01, 0.005));
    EXPECT_EQ(m.load().direction, Vec3(0, 0, -1));
    EXPECT_FALSE(m.isStatic());
    const double dt = 1e-4, g = 9.81;
    for (long s = 0; s < 20000; ++s) {
        const double t = s * dt;
        m.advanceLoad(t, dt, 0.0, g);
        const double after = t + dt;  // the state now is the wall's at `after`
        if (std::abs(after - 0.4) < 0.5 * dt) {
            // Free fall to 0.01 m/s in 1 ms (0.005 mm), then at 0.01 m/s: 2 mm by 0.4 s.
            EXPECT_NEAR(m.loadState().offset, 0.01 * 0.2 - 0.01 * 0.01 / (2 * g), 2 * dt * 0.01);
            EXPECT_DOUBLE_EQ(m.loadState().velocity, 0.01);
            EXPECT_NEAR(m.at(after).translation.z(), -m.loadState().offset, 1e-15);
            EXPECT_NEAR(m.velocityAt(Vec3::Zero(), after).z(), -0.01, 1e-15);
        }
        if (std::abs(after - 0.9) < 0.5 * dt) {
            EXPECT_DOUBLE_EQ(m.loadState().offset, 0.005);  // at the stop
            EXPECT_DOUBLE_EQ(m.loadState().velocity, 0.0);
        }
        if (std::abs(after - 1.2) < 0.5 * dt) {
            EXPECT_NEAR(m.loadState().offset, 0.005 - 0.01 * 0.2, 2 * dt * 0.01);  // drawn back at 0.01 m/s
            EXPECT_DOUBLE_EQ(m.loadState().velocity, -0.01);
        }
    }
    // Back where it started by tRaise + stroke / speed = 1.5 s, and resting there.
    EXPECT_DOUBLE_EQ(m.load().tEnd(), 1.5);
    EXPECT_EQ(m.loadState().offset, 0.0);
    EXPECT_EQ(m.loadState().velocity, 0.0);
    EXPECT_EQ(m.at(2.0).translation, Vec3::Zero());
    EXPECT_FALSE(m.isMovingAt(0.1));
    EXPECT_TRUE(m.isMovingAt(0.2));
    EXPECT_TRUE(m.isMovingAt(1.49));
    EXPECT_FALSE(m.isMovingAt(1.5));
    EXPECT_EQ(m.nextChangeAfter(0.1), 0.2);
    EXPECT_EQ(m.nextChangeAfter(0.7), 1.5);
    EXPECT_EQ(m.nextChangeAfter(1.5), std::numeric_limits<double>::infinity());
}

TEST(WallLoad, ForceAboveItsWeightStopsItAndPushesItBack) {
    dem::WallMotion m;
    m.addLoad(stampLoad(0.0, 1.0, 0.1, 0.01, 0.005));
    const double dt = 1e-4, g = 9.81;
    for (int s = 0; s < 1000; ++s) m.advanceLoad(s * dt, dt, 0.0, g);  // 1 mm down at 0.01 m/s
    const double down = m.loadState().offset;
    // Pushed back with twice its weight: decelerates at g, stops after
    // 0.01 / g s, then rises; it never rises above where it started.
    for (int s = 1000; s < 1010; ++s) m.advanceLoad(s * dt, dt, -2.0 * 0.1 * g, g);
    EXPECT_NEAR(m.loadState().velocity, 0.01 - 10 * dt * g, 1e-12);
    for (int s = 1010; s < 5000; ++s) m.advanceLoad(s * dt, dt, -2.0 * 0.1 * g, g);
    EXPECT_GT(down, 0.0009);
    EXPECT_EQ(m.loadState().offset, 0.0);
    EXPECT_GE(m.loadState().velocity, 0.0);
}

TEST(WallLoad, RefusesBadLoadsAndOverlapsWithSegments) {
    auto refused = [](dem::WallLoad load, const std::string& fragment) {
        dem::WallMotion m;
        try {
            m.addLoad(load);
            ADD_FAILURE() << "accepted a load that should be refused: " << fragment;
        } catch (const dem::InputError& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    refused(stampLoad(0.0, 1.0, 0.0, 0.01, 0.005), "mass");
    refused(stampLoad(0.0, 1.0, 0.1, -0.01, 0.005), "speed");
    refused(stampLoad(0.0, 1.0, 0.1, 0.01, 0.0), "stroke");
    refused(stampLoad(1.0, 1.0, 0.1, 0.01, 0.005), "tEnd");
    dem::WallLoad zero = stampLoad(0.0, 1.0, 0.1, 0.01, 0.005);
    zero.direction = Vec3::Zero();
    refused(zero, "direction");
    // The window is [0.5, 1.0 + 0.005 / 0.01) = [0.5, 1.5): a segment within it is refused either way round.
    dem::WallMotion before;
    before.addTranslation(1.4, 2.0, Vec3(0, 0, 0.2));
    EXPECT_THROW(before.addLoad(stampLoad(0.5, 1.0, 0.1, 0.01, 0.005)), dem::InputError);
    dem::WallMotion after;
    after.addLoad(stampLoad(0.5, 1.0, 0.1, 0.01, 0.005));
    EXPECT_THROW(after.addTranslation(1.4, 2.0, Vec3(0, 0, 0.2)), dem::InputError);
    after.addTranslation(0.0, 0.5, Vec3(0, 0, -0.2));  // down to where the load starts: fine
    after.addTranslation(1.5, 2.0, Vec3(0, 0, 0.2));   // and away once it is back
    EXPECT_THROW(after.addLoad(stampLoad(3.0, 4.0, 0.1, 0.01, 0.005)), dem::InputError);  // one load
}

// One sphere (radius 1 mm, sand E = 5 MPa) on a fixed floor, a 2 g stamp lowered
// onto it at 0.2 mm/s: at rest the stamp's weight M g goes through the sphere
// (Hertz: F = 4/3 E* sqrt(R) d^1.5 at each contact), so the stamp stands at
// 2 R - d(M g) - d((M + m) g) above the floor.
struct StampOnSphere {
    static constexpr double radius = 1e-3, stampMass = 0.002, speed = 2e-4, gap = 2e-5;
    dem::Simulation sim;
    StampOnSphere() : sim(make()) { sim.insert({{Vec3(0, 0, radius), radius}}, 0, Vec3::Zero()); }
    static dem::SimulationSettings settings() {
        dem::SimulationSettings s;
        s.timeStep = 2e-6;
        s.gravity = Vec3(0, 0, -9.81);
        return s;
    }
    static dem::Simulation make() {
        dem::WallMotion lowered;
        lowered.addLoad(stampLoad(0.0, 1.0, stampMass, speed, 5e-4));
        std::vector<dem::Wall> walls{
            {"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0},
            {"stamp", dem::PlaneWall(Vec3(0, 0, 2 * radius + gap), -Vec3::UnitZ()), lowered, 0}};
        return sandSimulation(std::move(walls), settings());
    }
    static double hertzOverlap(double force) {
        const double youngEff = 5e6 / (2.0 * (1.0 - 0.3 * 0.3));  // sphere and wall of the same material
        return std::pow(3.0 * force / (4.0 * youngEff * std::sqrt(radius)), 2.0 / 3.0);
    }
    double stampHeight() const { return 2 * radius + gap - sim.walls()[1].motion.loadState().offset; }
};

TEST(WallLoad, StampRestsOnASphereUnderItsWeight) {
    StampOnSphere s;
    const double g = 9.81, sphereMass = 2500.0 * 4.0 / 3.0 * M_PI * std::pow(StampOnSphere::radius, 3);
    const double expected = 2 * StampOnSphere::radius - StampOnSphere::hertzOverlap(StampOnSphere::stampMass * g) -
                            StampOnSphere::hertzOverlap((StampOnSphere::stampMass + sphereMass) * g);
    // The gap (20 um) and the two overlaps (31 um each) close at 0.2 mm/s in
    // 0.4 s.  Averaged over its last 0.1 s of rest (it rocks on the sphere by
    // about speed / omega, 0.4 um: the sphere's damping hardly slows a stamp
    // 190 times heavier).
    s.sim.step(400000);  // to 0.8 s
    double sum = 0.0, force = 0.0, floor = 0.0;
    const int samples = 100;
    for (int k = 0; k < samples; ++k) {
        s.sim.step(500);
        sum += s.stampHeight();
        force += s.sim.wallForces()[1].z();
        floor -= s.sim.wallForces()[0].z();
    }
    const double height = sum / samples;
    const double weight = StampOnSphere::stampMass * g;
    std::printf("stamp at %.4f um above the floor, expected %.4f um (Hertz); its weight %.5f N, force on it %.5f N, "
                "the floor carries %.7f N (stamp and sphere: %.7f N)\n",
                height * 1e6, expected * 1e6, weight, force / samples, floor / samples, weight + sphereMass * g);
    // 1 % of the two overlaps is 0.6 um.  Without its weight it would stand
    // 31 um higher.
    EXPECT_NEAR(height, expected, 0.01 * (2 * StampOnSphere::radius - expected));
    EXPECT_NEAR(force / samples, weight, 0.01 * weight);
    EXPECT_NEAR(floor / samples, weight + sphereMass * g, 0.01 * weight);
    // Raised at 1.0 s at 0.2 mm/s: at 1.1 s 20 um higher than at rest.
    s.sim.step(100000);  // from 0.9 s to 1.1 s
    EXPECT_NEAR(s.stampHeight() - height, 2e-5, 1e-6);
    EXPECT_EQ(s.sim.walls()[1].motion.loadState().velocity, -StampOnSphere::speed);
}

TEST(WallLoad, RestartContinuesTheStampBitwise) {
    // Written while the stamp presses, read into a fresh simulation: the same
    // stamp position and the same particle as the uninterrupted run.
    const std::string path =
        (std::filesystem::temp_directory_path() / ("wall_load_restart_" + std::to_string(::getpid()) + ".h5")).string();
    StampOnSphere uninterrupted, first;
    uninterrupted.sim.step(300000);
    first.sim.step(250000);
    first.sim.writeRestart(path);
    dem::Simulation second = StampOnSphere::make();
    second.readRestart(path);
    std::filesystem::remove(path);
    EXPECT_GT(second.walls()[1].motion.loadState().offset, StampOnSphere::gap);  // it was pressing
    EXPECT_EQ(second.walls()[1].motion.loadState().offset, first.sim.walls()[1].motion.loadState().offset);
    second.step(50000);
    EXPECT_EQ(second.walls()[1].motion.loadState().offset, uninterrupted.sim.walls()[1].motion.loadState().offset);
    EXPECT_EQ(second.walls()[1].motion.loadState().velocity, uninterrupted.sim.walls()[1].motion.loadState().velocity);
    EXPECT_EQ(second.particles().position[0], uninterrupted.sim.particles().position[0]);
}

TEST(WallLoad, RestartWithoutTheLoadsStateIsRefusedOnceTheLoadStarted) {
    const std::string path =
        (std::filesystem::temp_directory_path() / ("wall_load_old_" + std::to_string(::getpid()) + ".h5")).string();
    // A run whose stamp rests (no load) writes a file without walls/loadState.
    auto unloaded = [] {
        std::vector<dem::Wall> walls = StampOnSphere::make().walls();
        walls[1].motion = dem::WallMotion();
        return sandSimulation(walls, StampOnSphere::settings());
    }();
    unloaded.insert({{Vec3(0, 0, StampOnSphere::radius), StampOnSphere::radius}}, 0, Vec3::Zero());
    unloaded.step(100);
    unloaded.writeRestart(path);
    dem::Simulation loaded = StampOnSphere::make();
    try {
        loaded.readRestart(path);
        ADD_FAILURE() << "a file without the stamp's position was accepted after its load started";
    } catch (const dem::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("wall 'stamp'"), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
}

// A bed under a loaded plate on 1 and 3 thread ranks: the plate's force is
// summed over the ranks, so it comes down alike (to round-off of the sum).
TEST(WallLoad, DecomposedRunMovesTheStampAsTheSerialOne) {
    decomposition_cases::Case c = decomposition_cases::lattice(6, 3, 3, 1.99e-3, 2e-6, 5);
    c.settings.gravity = Vec3(0, 0, -9.81);
    const double top = 2 * 1.99e-3 + 1.1e-3;
    dem::WallMotion lowered;
    lowered.addLoad(stampLoad(0.0, 1.0, 0.002, 0.05, 2e-3));
    c.walls.push_back(dem::Wall{"stamp", dem::PlaneWall(Vec3(0, 0, top), -Vec3::UnitZ()), lowered, 0});
    const long steps = 3000;  // 6 ms: down 0.1 mm onto the top layer (2 ms) and pressing
    dem::Simulation serial = c.make();
    serial.insert(c.particles, 0, Vec3::Zero());
    serial.step(steps);
    const dem::WallLoadState reference = serial.walls().back().motion.loadState();
    const double force = serial.wallForces().back().z();
    // Lowered onto the bed, which has pushed back with more than its weight
    // (slower than the hoist): where it is depends on the force.
    EXPECT_GT(reference.offset, 1e-4);
    EXPECT_GT(force, 0.0);
    EXPECT_LT(reference.velocity, 0.9 * 0.05);
    std::printf("serial: stamp %.6f mm down at %.6f mm/s, force on it %.5f N (its weight %.5f N)\n",
                reference.offset * 1e3, reference.velocity * 1e3, force, 0.002 * 9.81);
    dem::Communicator::runThreadGroup(3, [&](const dem::Communicator& comm) {
        auto exchange = std::make_shared<dem::GhostExchange>(
            comm, dem::SlabDecomposition::uniform(comm.size(), 0, c.xLower + 0.3e-3, c.xUpper + 0.3e-3));
        dem::Simulation sim = c.make();
        sim.setDecomposition(exchange);
        sim.insert(c.particles, 0, Vec3::Zero());
        sim.step(steps);
        const dem::WallLoadState state = sim.walls().back().motion.loadState();
        EXPECT_NEAR(state.offset, reference.offset, 1e-12) << "rank " << comm.rank();
        EXPECT_NEAR(state.velocity, reference.velocity, 1e-9) << "rank " << comm.rank();
        // Every rank holds the same wall.
        EXPECT_EQ(comm.max(state.offset), comm.min(state.offset));
    });
}

}  // namespace
