// Verification of dem::Simulation on many-particle cases: a poured
// polydisperse bed (settling, containment, packing fraction), bitwise
// reproducibility and restart continuation, and a Lethe-style regression
// against a committed reference file.
//
// Regression reference: tests/demLib/data/regression/settle_reference.txt.
// After a deliberate change of the physics or of the order of floating-point
// operations, regenerate it with
//     DEMLIB_REGENERATE_REFERENCE=1 build/enginetests/tests/test_engine_bed --gtest_filter='EngineRegression.*'
// and commit the new file together with the change that explains it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "demLib/insertion.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"
#include "demLib/size_distribution.hpp"

namespace {

using dem::Vec3;

constexpr double kPi = 3.14159265358979323846;

dem::Material glass() { return {"glass", 5e6, 0.3, 2500.0}; }
dem::Material steel() { return {"steel", 2e7, 0.3, 7800.0}; }

// A closed box [0, W] x [0, W] x [0, H] of six one-sided planes (steel), the
// particles glass.  floorVelocity != 0 makes the floor slide in its own plane.
struct BoxCase {
    double width = 0.012;
    double height = 0.04;
    std::size_t count = 500;
    double dMin = 1.0e-3;
    double dMax = 2.0e-3;
    double dt = 1e-5;
    dem::RollingModel rolling = dem::RollingModel::EPSD2;
    double rollingFriction = 0.1;
    Vec3 floorVelocity = Vec3::Zero();
    Vec3 initialVelocity = Vec3::Zero();
    std::uint64_t seed = 11;
};

dem::SimulationSettings settingsFor(const BoxCase& c) {
    dem::SimulationSettings s;
    s.timeStep = c.dt;
    s.gravity = Vec3(0, 0, -9.81);
    s.forces.rolling = c.rolling;
    s.domain = dem::AxisAlignedBox{Vec3(-0.001, -0.001, -0.001),
                                   Vec3(c.width + 0.001, c.width + 0.001, c.height + 0.001)};
    s.source = "test_engine_bed";
    return s;
}

dem::Simulation makeBox(const BoxCase& c) {
    const std::vector<dem::Material> mats{glass(), steel()};
    dem::InteractionTable table(2);
    dem::PairCoefficients particleParticle;
    particleParticle.restitution = 0.5;
    particleParticle.friction = 0.5;
    particleParticle.rollingFriction = c.rollingFriction;
    dem::PairCoefficients particleWall = particleParticle;
    particleWall.friction = 0.61;
    table.set(mats, 0, 0, particleParticle);
    table.set(mats, 0, 1, particleWall);
    table.set(mats, 1, 1, particleWall);

    const double W = c.width, H = c.height;
    dem::WallMotion floorMotion;
    if (c.floorVelocity.squaredNorm() > 0.0) floorMotion.addTranslation(0.0, 100.0, c.floorVelocity);
    std::vector<dem::Wall> walls{
        {"floor", dem::PlaneWall(Vec3(0, 0, 0), Vec3::UnitZ()), floorMotion, 1},
        {"lid", dem::PlaneWall(Vec3(0, 0, H), -Vec3::UnitZ()), {}, 1},
        {"xMin", dem::PlaneWall(Vec3(0, 0, 0), Vec3::UnitX()), {}, 1},
        {"xMax", dem::PlaneWall(Vec3(W, 0, 0), -Vec3::UnitX()), {}, 1},
        {"yMin", dem::PlaneWall(Vec3(0, 0, 0), Vec3::UnitY()), {}, 1},
        {"yMax", dem::PlaneWall(Vec3(0, W, 0), -Vec3::UnitY()), {}, 1}};
    dem::Simulation sim(settingsFor(c), mats, table, walls);

    const dem::SizeDistribution psd = dem::SizeDistribution::fromPercentages(
        {{c.dMin, 0.5 * (c.dMin + c.dMax), 50.0}, {0.5 * (c.dMin + c.dMax), c.dMax, 50.0}});
    dem::InsertionRequest request;
    request.targetCount = c.count;
    request.density = glass().density;
    request.placement.seed = c.seed;
    request.placement.gapFraction = 0.05;
    request.placement.settleDirection = Vec3(0, 0, -1);
    sim.insert(dem::insertParticles(dem::Region::box(Vec3::Zero(), Vec3(W, W, H)), psd, request), 0,
               c.initialVelocity, "bed insertion");
    return sim;
}

double potentialEnergy(const dem::ParticleStore& p) {
    double u = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) u += p.mass[i] * 9.81 * p.position[i].z();
    return u;
}

// ---------------------------------------------------------------------------
// 5. A poured bed.  500 spheres of 1-2 mm (half the mass in each half of the
// range) fall from a loose lattice into a 12 mm box and settle.
//
// Packing: random packings of frictional spheres (mu = 0.5) lie between
// random loose packing (~0.55) and random close packing (~0.64; a little
// higher for polydisperse mixtures, but the 1:2 range here changes it by
// < 0.01).  The solid fraction is sampled on a grid of points in the core of
// the bed, one largest diameter away from the side walls and the floor and two
// below the surface, where the wall ordering does not reach.
//
// Height: in a box only 6-12 diameters wide the layers at the walls pack
// looser than the core (a 10 % taller bed than phi_core predicts), so the
// height is predicted from the solid fraction of the whole cross-section
// below the surface region, H = V_solid / (A phi_bulk), and compared with the
// measured surface (where a thin slice's solid fraction falls to half of
// phi_bulk) within 3 %: overlapping or lost particles, or spheres hovering
// above the bed, would break it.

// Fraction of grid points in [lo, hi] that lie inside some sphere.
double solidFraction(const dem::ParticleStore& p, const Vec3& lo, const Vec3& hi, int n) {
    long inside = 0, total = 0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
            for (int c = 0; c < n; ++c) {
                const Vec3 x = lo + Vec3((a + 0.5) / n, (b + 0.5) / n, (c + 0.5) / n).cwiseProduct(hi - lo);
                ++total;
                for (std::size_t i = 0; i < p.size(); ++i)
                    if ((p.position[i] - x).squaredNorm() < p.radius[i] * p.radius[i]) {
                        ++inside;
                        break;
                    }
            }
    return static_cast<double>(inside) / total;
}

// Kinetic energy that the contacts can dissipate.  Hertz-Mindlin (as in
// LIGGGHTS) has no twisting resistance: a sphere that rests on ONE contact
// (a rattler on the floor) keeps any spin about that contact's normal forever,
// since a point contact exerts no torque about it.  That spin is a constant of
// the model, not a failure to settle; it is reported separately.
struct SettlingEnergy {
    double dissipatable = 0.0;  // translation + rotation except the free spin
    double freeSpin = 0.0;      // spin of single-contact spheres about their contact normal
};

SettlingEnergy settlingEnergy(const dem::Simulation& sim) {
    const dem::ParticleStore& p = sim.particles();
    const std::size_t n = p.size();
    std::vector<int> contacts(n, 0);
    std::vector<Vec3> normal(n, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            const Vec3 d = p.position[i] - p.position[j];
            if (d.norm() < p.radius[i] + p.radius[j]) {
                ++contacts[i];
                ++contacts[j];
                normal[i] = normal[j] = d.normalized();
            }
        }
    for (const dem::WallContactRecord& r : sim.wallContacts().records()) {
        std::vector<dem::WallContact> found;
        sim.walls()[r.wall].findContacts(p.position[r.particle], p.radius[r.particle], sim.time(), found);
        for (const dem::WallContact& c : found)
            if (c.feature == r.feature && c.overlap > 0.0) {
                ++contacts[r.particle];
                normal[r.particle] = c.normal;
            }
    }
    SettlingEnergy e;
    for (std::size_t i = 0; i < n; ++i) {
        const double inertia = 0.4 * p.mass[i] * p.radius[i] * p.radius[i];
        double spin = 0.0;
        if (contacts[i] == 1) spin = 0.5 * inertia * std::pow(p.omega[i].dot(normal[i]), 2);
        e.dissipatable += 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
                          0.5 * inertia * p.omega[i].squaredNorm() - spin;
        e.freeSpin += spin;
    }
    return e;
}

TEST(EngineBed, PouredBedSettlesInsideTheBoxWithSoundPacking) {
    ThreadCount threads(1);
    BoxCase c;
    dem::Simulation sim = makeBox(c);
    const auto& p = sim.particles();
    ASSERT_EQ(p.size(), c.count);
    const double u0 = potentialEnergy(p);
    double kineticOverDrop = 1.0;
    double maxKinetic = 0.0;
    SettlingEnergy energy;
    while (sim.time() < 1.0) {
        sim.step(2000);
        maxKinetic = std::max(maxKinetic, p.kineticEnergy());
        energy = settlingEnergy(sim);
        kineticOverDrop = energy.dissipatable / (u0 - potentialEnergy(p));
        if (sim.time() > 0.2 && kineticOverDrop < 1e-6) break;
    }
    const double drop = u0 - potentialEnergy(p);
    std::printf("bed: settled at t = %.3f s, KE / potential drop = %.3e (free spin of single-contact spheres "
                "%.3e, peak KE %.3e)\n",
                sim.time(), kineticOverDrop, energy.freeSpin / drop, maxKinetic / drop);
    EXPECT_LT(kineticOverDrop, 1e-6);
    EXPECT_GT(maxKinetic / drop, 0.05);  // it really fell
    EXPECT_EQ(sim.lostCount(), 0u);
    EXPECT_EQ(p.size(), c.count);

    double solidVolume = 0.0, top = 0.0, maxOverlapRatio = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& x = p.position[i];
        const double r = p.radius[i];
        solidVolume += 4.0 / 3.0 * kPi * r * r * r;
        top = std::max(top, x.z() + r);
        // Inside the box: a centre may be at most a small Hertz overlap outside r.
        for (int k = 0; k < 3; ++k) {
            const double extent = k == 2 ? c.height : c.width;
            EXPECT_GT(x[k], 0.99 * r) << "particle " << i;
            EXPECT_LT(x[k], extent - 0.99 * r) << "particle " << i;
        }
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            const double overlap = r + p.radius[j] - (x - p.position[j]).norm();
            maxOverlapRatio = std::max(maxOverlapRatio, overlap / std::min(r, p.radius[j]));
        }
    }
    // Under ~10 layers of weight the Hertz overlaps stay small (soft E = 5 MPa).
    EXPECT_LT(maxOverlapRatio, 0.02);

    // Surface height: where the solid fraction of a thin full-width slice falls
    // below half of the bulk value.
    const double m = c.dMax;
    const double coreTop = top - 2.0 * m;
    ASSERT_GT(coreTop, 2.0 * m);
    const double phiCore = solidFraction(p, Vec3(m, m, m), Vec3(c.width - m, c.width - m, coreTop), 40);
    // Whole cross-section up to the same height: includes the looser layers at
    // the walls and the floor, so it predicts the height of this box.
    const double phiBulk = solidFraction(p, Vec3(0, 0, 0), Vec3(c.width, c.width, coreTop), 40);
    double surface = 0.0;
    for (double z = 0.0; z < top; z += 0.05 * m) {
        const double phiSlice = solidFraction(p, Vec3(0, 0, z), Vec3(c.width, c.width, z + 0.05 * m), 30);
        if (phiSlice >= 0.5 * phiBulk) surface = z + 0.025 * m;
    }
    const double predicted = solidVolume / (c.width * c.width * phiBulk);
    std::printf("bed: phi_core = %.4f, phi_bulk = %.4f, surface %.3f mm, predicted %.3f mm (ratio %.4f), "
                "max overlap/r %.4f\n",
                phiCore, phiBulk, 1e3 * surface, 1e3 * predicted, surface / predicted, maxOverlapRatio);
    EXPECT_GT(phiCore, 0.55);
    EXPECT_LT(phiCore, 0.64);
    EXPECT_LT(phiBulk, phiCore);  // walls loosen the packing next to them
    EXPECT_NEAR(surface / predicted, 1.0, 0.03);

    // At rest the walls carry the bed: the forces of the particles on the
    // walls add up to the bed's weight, straight down.  The floor carries
    // most of it; the frictional side walls hold friction locked in as the
    // bed landed and sprang back (here about 7 % of the weight, pulling the
    // bed down), the lid nothing.
    double weight = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) weight += p.mass[i] * 9.81;
    const std::vector<Vec3> onWalls = sim.wallForces();
    ASSERT_EQ(onWalls.size(), sim.walls().size());
    Vec3 total = Vec3::Zero();
    for (const Vec3& f : onWalls) total += f;
    const double floorShare = -onWalls[0].z() / weight, lidShare = onWalls[1].norm() / weight;
    std::printf("bed: forces on the walls: total (%.4e %.4e %.4e) N, weight %.4e N; floor carries %.4f, "
                "side walls %.4f, lid %.1e of it; xMin/xMax push %.3e / %.3e N\n",
                total.x(), total.y(), total.z(), weight, floorShare, 1.0 - floorShare, lidShare,
                onWalls[2].x(), onWalls[3].x());
    EXPECT_NEAR(total.z() / weight, -1.0, 2e-3);
    EXPECT_LT(std::hypot(total.x(), total.y()) / weight, 2e-3);
    EXPECT_GT(floorShare, 0.8);
    EXPECT_LT(floorShare, 1.2);
    EXPECT_EQ(lidShare, 0.0);
    EXPECT_LT(onWalls[2].x(), -1e-3 * weight);  // the bed pushes the side walls outwards
    EXPECT_GT(onWalls[3].x(), 1e-3 * weight);
}

// ---------------------------------------------------------------------------
// 6. Reproducibility and restart.  A smaller box whose floor slides in its own
// plane (a moving wall with sustained, sliding contacts), EPSD2 rolling
// history, particles resting on each other.

struct State {
    std::vector<Vec3> position, velocity, omega;
};

State stateOf(const dem::Simulation& sim) {
    return {sim.particles().position, sim.particles().velocity, sim.particles().omega};
}

void expectBitwiseEqual(const State& a, const State& b, const std::string& what) {
    ASSERT_EQ(a.position.size(), b.position.size()) << what;
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.position.size(); ++i)
        if (!(a.position[i] == b.position[i]) || !(a.velocity[i] == b.velocity[i]) || !(a.omega[i] == b.omega[i]))
            ++differing;
    EXPECT_EQ(differing, 0u) << what << ": particles that differ";
}

BoxCase restartCase() {
    BoxCase c;
    c.width = 0.008;
    c.height = 0.03;
    c.count = 150;
    c.floorVelocity = Vec3(0.02, 0.0, 0.0);
    c.initialVelocity = Vec3(0.0, 0.0, -0.3);  // thrown down: a dense heap within 4000 steps
    c.seed = 5;
    return c;
}

constexpr long kStepsBefore = 4000;  // fall and land: contacts everywhere at the restart
constexpr long kStepsAfter = 1500;

void checkRepeatAndRestart(int threadCount) {
    ThreadCount threads(threadCount);
    const BoxCase c = restartCase();
    const std::string path = ::testing::TempDir() + "engine_restart_" + std::to_string(threadCount) + ".h5";

    dem::Simulation first = makeBox(c);
    first.step(kStepsBefore);
    // The restart point must be a hard one: touching pairs, wall contacts on
    // the moving floor, non-zero rolling and tangential history.
    EXPECT_GT(first.lastStep().contacts.touchingPairs, c.count / 2);
    EXPECT_GT(first.lastStep().contacts.wallContacts, 10u);
    double rollingHistory = 0.0, shearHistory = 0.0;
    for (const dem::PairState& s : first.pairList().state()) {
        rollingHistory = std::max(rollingHistory, s.contact.rollingAngle.norm());
        shearHistory = std::max(shearHistory, s.contact.shear.norm());
    }
    EXPECT_GT(rollingHistory, 0.0);
    EXPECT_GT(shearHistory, 0.0);
    std::printf("restart point (%d threads): %zu touching pairs, %zu wall contacts, max |rolling angle| %.3e rad\n",
                threadCount, first.lastStep().contacts.touchingPairs, first.lastStep().contacts.wallContacts,
                rollingHistory);
    first.writeRestart(path);
    const std::vector<Vec3> wallForcesAtRestart = first.wallForces();
    // The floor slides in +x under the heap: its friction drags the particles
    // along, and they hold the floor back.
    EXPECT_LT(wallForcesAtRestart[0].x(), -1e-3 * std::abs(wallForcesAtRestart[0].z()));
    first.step(kStepsAfter);

    // Same thread count, same input: the same bits.
    dem::Simulation again = makeBox(c);
    again.step(kStepsBefore + kStepsAfter);
    expectBitwiseEqual(stateOf(first), stateOf(again), "repeated run, " + std::to_string(threadCount) + " threads");

    dem::Simulation continued(settingsFor(c), first.materials(), first.interactions(), first.walls());
    continued.readRestart(path);
    EXPECT_EQ(continued.stepCount(), kStepsBefore);
    const std::vector<Vec3> wallForcesRead = continued.wallForces();
    for (std::size_t w = 0; w < wallForcesRead.size(); ++w)
        EXPECT_EQ(wallForcesRead[w], wallForcesAtRestart[w]) << "wall " << w << " force after readRestart";
    continued.step(kStepsAfter);
    EXPECT_EQ(continued.stepCount(), first.stepCount());
    EXPECT_EQ(continued.time(), first.time());
    expectBitwiseEqual(stateOf(first), stateOf(continued), "restart, " + std::to_string(threadCount) + " threads");
    EXPECT_EQ(continued.lostCount(), first.lostCount());
    std::remove(path.c_str());
}

TEST(EngineRestart, BitwiseRepeatAndRestartOneThread) { checkRepeatAndRestart(1); }
TEST(EngineRestart, BitwiseRepeatAndRestartTwoThreads) { checkRepeatAndRestart(2); }

// ---------------------------------------------------------------------------
// 8. Regression (Lethe style): 200 spheres settle for 20 000 steps on one
// thread; every final position and velocity is compared with the committed
// reference within 1e-9 of the scale (box width for positions, sqrt(g W) for
// velocities).  The run is chaotic, so a change of the order of floating-point
// operations (compiler, flags, summation order) may move it beyond that
// tolerance: then inspect the change and regenerate (see the top of the file).

std::string referencePath() { return std::string(DEMLIB_TEST_DATA_DIR) + "/regression/settle_reference.txt"; }

TEST(EngineRegression, SettlingMatchesCommittedReference) {
    ThreadCount threads(1);
    BoxCase c;
    c.width = 0.010;
    c.height = 0.025;
    c.count = 200;
    c.seed = 2024;
    dem::Simulation sim = makeBox(c);
    sim.step(20000);
    const auto& p = sim.particles();
    ASSERT_EQ(p.size(), c.count);

    const char* regenerate = std::getenv("DEMLIB_REGENERATE_REFERENCE");
    if (regenerate && std::string(regenerate) == "1") {
        std::ofstream out(referencePath());
        ASSERT_TRUE(out) << "cannot write " << referencePath();
        out << "# demLib regression: test_engine_bed EngineRegression.SettlingMatchesCommittedReference\n"
            << "# 200 glass spheres (1-2 mm) settled 20000 steps of 1e-5 s in a 10 mm steel box, 1 thread.\n"
            << "# Regenerate: DEMLIB_REGENERATE_REFERENCE=1 test_engine_bed --gtest_filter='EngineRegression.*'\n"
            << "# id x y z vx vy vz [SI]\n";
        out.precision(17);
        for (std::size_t i = 0; i < p.size(); ++i)
            out << p.id[i] << ' ' << p.position[i].x() << ' ' << p.position[i].y() << ' ' << p.position[i].z()
                << ' ' << p.velocity[i].x() << ' ' << p.velocity[i].y() << ' ' << p.velocity[i].z() << '\n';
        GTEST_SKIP() << "reference regenerated: " << referencePath();
    }

    std::ifstream in(referencePath());
    ASSERT_TRUE(in) << "missing reference " << referencePath()
                    << " (generate it with DEMLIB_REGENERATE_REFERENCE=1)";
    std::vector<std::int64_t> ids;
    std::vector<Vec3> x, v;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        std::int64_t id;
        Vec3 a, b;
        s >> id >> a.x() >> a.y() >> a.z() >> b.x() >> b.y() >> b.z();
        ASSERT_FALSE(s.fail()) << "bad line in reference: " << line;
        ids.push_back(id);
        x.push_back(a);
        v.push_back(b);
    }
    ASSERT_EQ(ids.size(), p.size());
    const double positionScale = c.width;
    const double velocityScale = std::sqrt(9.81 * c.width);
    double worstPosition = 0.0, worstVelocity = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        ASSERT_EQ(p.id[i], ids[i]);
        worstPosition = std::max(worstPosition, (p.position[i] - x[i]).cwiseAbs().maxCoeff() / positionScale);
        worstVelocity = std::max(worstVelocity, (p.velocity[i] - v[i]).cwiseAbs().maxCoeff() / velocityScale);
    }
    std::printf("regression: worst relative deviation position %.3e, velocity %.3e\n", worstPosition,
                worstVelocity);
    EXPECT_LT(worstPosition, 1e-9);
    EXPECT_LT(worstVelocity, 1e-9);
}

}  // namespace
