// The drift's extras (DriftExtras): the neighbour list's rebuild test and the
// force reset done in the same pass as the kicks and the drift must give
// exactly what the separate loops give (the engine relies on this to keep its
// results bitwise unchanged), with 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "demLib/integrator.hpp"
#include "demLib/particle_particle_neighbor_list.hpp"
#include "thread_count.hpp"

using dem::Vec3;

namespace {

// 20 000 particles (enough for two threads in the light loops) with random
// velocities, spins, forces and torques; every 7th with an external force.
dem::ParticleStore randomParticles(unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto v3 = [&](double s) { return Vec3(s * u(rng), s * u(rng), s * u(rng)); };
    dem::ParticleStore p;
    for (int i = 0; i < 20000; ++i) {
        p.add(i, v3(0.1), v3(0.5), 1e-3 * (1.0 + 0.3 * u(rng)), 2650.0, 0);
        p.omega[i] = v3(50.0);
        p.force[i] = v3(1e-3);
        p.torque[i] = v3(1e-7);
    }
    for (std::size_t i = 0; i < p.size(); i += 7) p.externalForce[i] = v3(1e-4);
    return p;
}

void expectSameBits(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) differing += a[i][c] != b[i][c];
    EXPECT_EQ(differing, 0u) << what;
}

struct Outcome {
    dem::ParticleStore particles;
    bool movedFar = false;
};

// reference: kick(); kickAndDrift(); needsRebuild(); reset F and T.  fused: one
// kickKickAndDrift with the extras.  The list is built at the start positions
// with the given skin.
Outcome run(bool fused, double skin, double dt, int threads) {
    ThreadCount scope(threads);
    const Vec3 g(0.0, 0.0, -9.81);
    Outcome out{randomParticles(5), false};
    dem::ParticleStore& p = out.particles;
    dem::ParticleParticleNeighborList list;
    list.setRanges(skin, 0.0);
    list.build(p);
    if (fused) {
        dem::DriftExtras extras;
        extras.displacementFrom = list.positionsAtBuild().data();
        extras.limitSquared = list.rebuildDisplacementSquared();
        extras.resetForces = true;
        extras.gravity = g;
        out.movedFar = dem::kickKickAndDrift(p, dt, p.size(), extras).movedFar;
    } else {
        dem::kick(p, dt);
        dem::kickAndDrift(p, dt);
        out.movedFar = list.needsRebuild(p);
        dem::resetForces(p, g);
    }
    return out;
}

}  // namespace

TEST(FusedDrift, KicksDriftRebuildTestAndForceResetAreThoseOfSeparateLoops) {
    for (int threads : {1, 2}) {
        // A skin that no particle leaves in one step, and one that some leave
        // (0.5 m/s x 1e-4 s = 5e-5 m against skin/2).
        for (double skin : {1e-3, 6e-5}) {
            const Outcome reference = run(false, skin, 1e-4, threads);
            const Outcome fused = run(true, skin, 1e-4, threads);
            expectSameBits(reference.particles.position, fused.particles.position, "position");
            expectSameBits(reference.particles.velocity, fused.particles.velocity, "velocity");
            expectSameBits(reference.particles.omega, fused.particles.omega, "omega");
            expectSameBits(reference.particles.force, fused.particles.force, "force");
            expectSameBits(reference.particles.torque, fused.particles.torque, "torque");
            EXPECT_EQ(reference.movedFar, fused.movedFar) << "skin " << skin << ", " << threads << " thread(s)";
            EXPECT_EQ(fused.movedFar, skin < 1e-4) << "skin " << skin;
        }
    }
    // The reset force is m g + F_external, the torque zero; particles 0 and 7
    // carry an external force, particle 1 none.
    const Outcome fused = run(true, 1e-3, 1e-4, 1);
    const dem::ParticleStore& p = fused.particles;
    ASSERT_FALSE(p.externalForce[0].isZero(0.0));
    ASSERT_FALSE(p.externalForce[7].isZero(0.0));
    ASSERT_TRUE(p.externalForce[1].isZero(0.0));
    for (std::size_t i : {std::size_t(0), std::size_t(1), std::size_t(7)}) {
        const Vec3 expected = p.mass[i] * Vec3(0.0, 0.0, -9.81) + p.externalForce[i];
        EXPECT_EQ(p.force[i], expected) << i;
        EXPECT_TRUE(p.torque[i].isZero(0.0)) << i;
    }
}

// The lost-particle test in the drift: reports a particle that ends outside
// the box or not finite (as Simulation::removeLostParticles tests), and
// nothing when all are inside or when the test is not asked for.
TEST(FusedDrift, ReportsAParticleThatLeavesTheDomainBoxOrIsNotFinite) {
    // The rebuild test's list, built at the finite start positions.
    dem::ParticleParticleNeighborList list;
    list.setRanges(1e-3, 0.0);
    list.build(randomParticles(9));
    auto drift = [&](dem::ParticleStore p, const Vec3& lo, const Vec3& hi, bool test, int threads) {
        ThreadCount scope(threads);
        const dem::AxisAlignedBox box{lo, hi};
        dem::DriftExtras extras;
        extras.displacementFrom = list.positionsAtBuild().data();
        extras.limitSquared = list.rebuildDisplacementSquared();
        extras.domain = test ? &box : nullptr;
        return dem::kickKickAndDrift(p, 1e-4, p.size(), extras).leftDomain;
    };
    // Positions within [-0.1, 0.1] + 0.5 m/s x 1e-4 s: inside a box of +-0.2.
    const Vec3 lo(-0.2, -0.2, -0.2), hi(0.2, 0.2, 0.2);
    for (int threads : {1, 2}) {
        const dem::ParticleStore p = randomParticles(9);
        EXPECT_FALSE(drift(p, lo, hi, true, threads));
        // Tighter in one direction only: some end above z = 0.05.
        EXPECT_TRUE(drift(p, lo, Vec3(0.2, 0.2, 0.05), true, threads));
        EXPECT_FALSE(drift(p, lo, Vec3(0.2, 0.2, 0.05), false, threads));
        // One particle (the last, on the second thread's share) out below, or not finite.
        for (double bad : {-0.3, std::nan("")}) {
            dem::ParticleStore q = p;
            q.position.back().z() = bad;
            q.velocity.back().setZero();
            EXPECT_TRUE(drift(q, lo, hi, true, threads)) << bad << ", " << threads << " thread(s)";
        }
    }
}
