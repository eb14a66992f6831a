// The MPI design of demLib, checked in one process: the communicator (serial
// fallback; refusal to run over MPI that the caller did not initialise; ranks
// as threads), slab geometry, and the decomposed code path (id-keyed history
// stash, migration bookkeeping, owned/ghost split) on one rank, which must
// reproduce the plain serial engine bit for bit, and on 2 and 3 thread ranks,
// which must follow it (decomposition_checks.hpp, also run on MPI ranks by
// mpi/test_mpi_decomposition.cpp under mpirun).
#include <gtest/gtest.h>

#include <atomic>
#include <limits>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include "decomposition_cases.hpp"
#include "decomposition_checks.hpp"
#include "demLib/communicator.hpp"
#include "demLib/domain_decomposition.hpp"
#include "demLib/error.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"

#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

namespace {

using dem::Vec3;
using namespace decomposition_cases;

TEST(Communicator, SerialIsOneRankWithIdentityCollectives) {
    const dem::Communicator c = dem::Communicator::serial();
    EXPECT_EQ(c.rank(), 0);
    EXPECT_EQ(c.size(), 1);
    EXPECT_TRUE(c.isSerial());
    EXPECT_FALSE(c.usesMpi());
    EXPECT_EQ(c.sum(2.5), 2.5);
    EXPECT_EQ(c.sum(std::int64_t{7}), 7);
    EXPECT_EQ(c.min(-3.0), -3.0);
    EXPECT_EQ(c.max(4.0), 4.0);
    EXPECT_TRUE(c.anyTrue(true));
    EXPECT_FALSE(c.anyTrue(false));
    const auto back = c.exchange({{'a', 'b', 'c'}});
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(std::string(back[0].begin(), back[0].end()), "abc");
    EXPECT_THROW(c.exchange({{'a'}, {'b'}}), dem::RuntimeError);
}

#if DEMLIB_HAS_MPI
// This program never calls MPI_Init: demLib must refuse an MPI communicator
// instead of initialising MPI itself (OpenFOAM's argList owns MPI_Init).
TEST(Communicator, RefusesMpiThatTheCallerDidNotInitialise) {
    int initialised = 1;
    MPI_Initialized(&initialised);
    ASSERT_EQ(initialised, 0) << "the test program itself must not have initialised MPI";
    try {
        dem::communicatorFromMpi(MPI_COMM_WORLD);
        FAIL() << "expected dem::RuntimeError";
    } catch (const dem::RuntimeError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("not initialised"), std::string::npos) << what;
        EXPECT_NE(what.find("the caller must call MPI_Init"), std::string::npos) << what;
        EXPECT_NE(what.find("demLib never does"), std::string::npos) << what;
    }
    // ... and it did not initialise MPI while refusing.
    MPI_Initialized(&initialised);
    EXPECT_EQ(initialised, 0);
}
#endif

TEST(SlabDecomposition, OwnerAndDistanceFollowTheCuts) {
    const dem::SlabDecomposition s(3, 1, {0.0, 2.0});  // y < 0 | 0 <= y < 2 | y >= 2
    EXPECT_EQ(s.ownerOf(Vec3(5, -1e-9, 0), 0), 0);
    EXPECT_EQ(s.ownerOf(Vec3(5, 0.0, 0), 0), 1);  // a cut belongs to the slab above it
    EXPECT_EQ(s.ownerOf(Vec3(5, 1.999, 0), 0), 1);
    EXPECT_EQ(s.ownerOf(Vec3(5, 2.0, 0), 0), 2);
    EXPECT_EQ(s.ownerOf(Vec3(5, 1e300, 0), 0), 2);
    EXPECT_EQ(s.ownerOf(Vec3(0, std::numeric_limits<double>::quiet_NaN(), 0), 1), 1);
    EXPECT_DOUBLE_EQ(s.distanceToSlab(1, Vec3(0, -0.25, 0)), 0.25);
    EXPECT_DOUBLE_EQ(s.distanceToSlab(1, Vec3(0, 2.5, 0)), 0.5);
    EXPECT_EQ(s.distanceToSlab(1, Vec3(0, 1.0, 0)), 0.0);
    EXPECT_DOUBLE_EQ(s.distanceToSlab(0, Vec3(0, 3.0, 0)), 3.0);
    EXPECT_EQ(s.distanceToSlab(2, Vec3(0, 1e6, 0)), 0.0);
    const dem::SlabDecomposition u = dem::SlabDecomposition::uniform(4, 0, 0.0, 1.0);
    ASSERT_EQ(u.interiorCuts().size(), 3u);
    EXPECT_DOUBLE_EQ(u.interiorCuts()[1], 0.5);
}

TEST(SlabDecomposition, RejectsInconsistentInput) {
    EXPECT_THROW(dem::SlabDecomposition(2, 0, {}), dem::InputError);
    EXPECT_THROW(dem::SlabDecomposition(3, 0, {1.0, 1.0}), dem::InputError);
    EXPECT_THROW(dem::SlabDecomposition(2, 3, {0.0}), dem::InputError);
    EXPECT_THROW(dem::SlabDecomposition(0, 0, {}), dem::InputError);
    EXPECT_THROW(dem::SlabDecomposition::uniform(2, 0, 1.0, 1.0), dem::InputError);
    // Two slabs for a one-process communicator.
    EXPECT_THROW(dem::GhostExchange(dem::Communicator::serial(), dem::SlabDecomposition(2, 0, {0.0})),
                 dem::InputError);
}

std::shared_ptr<dem::GhostExchange> oneRankDecomposition() {
    return std::make_shared<dem::GhostExchange>(dem::Communicator::serial(), dem::SlabDecomposition(1, 0, {}));
}

TEST(Decomposition, RefusesWhatItDoesNotSupportYet) {
    Case c = agitatedGas();
    {
        dem::Simulation sim = c.make();
        sim.insert(c.particles, 0, Vec3::Zero());
        EXPECT_THROW(sim.setDecomposition(oneRankDecomposition()), dem::InputError);  // after insertion
    }
    {
        dem::Simulation sim = c.make();
        sim.setDecomposition(oneRankDecomposition());
        sim.insert(c.particles, 0, Vec3::Zero());
        EXPECT_THROW(sim.writeRestart("never_written.h5"), dem::InputError);
        EXPECT_THROW(sim.setWaterContent(0.01), dem::InputError);
    }
    Case wet = c;
    wet.settings.forces.cohesion = dem::CohesionModel::Capillary;
    dem::Simulation sim = wet.make();
    EXPECT_THROW(sim.setDecomposition(oneRankDecomposition()), dem::InputError);
}

// On one rank the decomposed path has no ghosts, but still carries all pair
// and wall history through the id-keyed stash at every list build and runs
// migration (to nowhere): it must give the serial engine's numbers exactly.
TEST(Decomposition, OneRankReproducesTheSerialEngineBitwise) {
    OneThread one;
    const Case c = agitatedGas();
    dem::Simulation serial = c.make();
    serial.insert(c.particles, 0, Vec3::Zero());
    setMotionById(serial, c);
    dem::Simulation decomposed = c.make();
    auto exchange = oneRankDecomposition();
    decomposed.setDecomposition(exchange);
    decomposed.insert(c.particles, 0, Vec3::Zero());
    setMotionById(decomposed, c);
    const long steps = 400;
    for (long s = 0; s < steps; s += 50) {
        serial.step(50);
        decomposed.step(50);
    }
    const dem::ParticleStore& a = serial.particles();
    const dem::ParticleStore& b = decomposed.particles();
    ASSERT_EQ(exchange->ghostCount(), 0u);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_GT(serial.lostCount(), 0u) << "the case should lose particles through the open top";
    EXPECT_EQ(serial.lostCount(), decomposed.lostCount());
    EXPECT_GT(serial.pairList().buildCount(), 5) << "the case should rebuild the list several times";
    EXPECT_GT(serial.lastStep().contacts.touchingPairs, 10u);
    EXPECT_GT(serial.lastStep().contacts.wallContacts, 0u);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a.id[i], b.id[i]);
        if (a.position[i] != b.position[i] || a.velocity[i] != b.velocity[i] || a.omega[i] != b.omega[i] ||
            a.force[i] != b.force[i] || a.torque[i] != b.torque[i])
            ++differ;
    }
    EXPECT_EQ(differ, 0u) << "particles whose state differs from the serial run";
}

// Ranks that are threads of this process: the same collectives as MPI's,
// for 1 to 4 ranks, many times over (the slots of two phases alternate).
TEST(ThreadRanks, CollectivesGiveEveryRankTheSameResults) {
    for (int ranks = 1; ranks <= 4; ++ranks) {
        std::atomic<int> seen{0};
        dem::Communicator::runThreadGroup(ranks, [&](const dem::Communicator& c) {
            EXPECT_TRUE(c.usesThreads());
            EXPECT_FALSE(c.usesMpi());
            EXPECT_EQ(c.size(), ranks);
            seen += 1 << c.rank();
            for (int round = 0; round < 50; ++round) {
                decomposition_checks::collectivesAgree(c);
                // A rank that runs ahead must not change what a slower one
                // still reads: values change with every call.
                const double mine = round * 100.0 + c.rank();
                EXPECT_EQ(c.max(mine), round * 100.0 + ranks - 1);
                EXPECT_EQ(c.sum(static_cast<std::int64_t>(round)), std::int64_t{round} * ranks);
            }
        });
        EXPECT_EQ(seen.load(), (1 << ranks) - 1) << "each rank ran once";
    }
    EXPECT_THROW(dem::Communicator::runThreadGroup(0, [](const dem::Communicator&) {}), dem::InputError);
}

// A rank that fails releases the others from their collective with an error,
// and the first exception reaches the caller after all threads ended.
TEST(ThreadRanks, AFailingRankStopsTheGroupWithItsError) {
    try {
        dem::Communicator::runThreadGroup(3, [](const dem::Communicator& c) {
            if (c.rank() == 1) throw std::runtime_error("rank 1 failed on purpose");
            c.sum(1.0);  // waits for rank 1 forever without the release
        });
        FAIL() << "expected the error of rank 1";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "rank 1 failed on purpose");
    }
}

TEST(ThreadRanks, GhostsGiveTheSerialContactForces) {
    for (int ranks : {2, 3})
        dem::Communicator::runThreadGroup(ranks, decomposition_checks::ghostsGiveTheSerialContactForces);
}

TEST(ThreadRanks, MultiStepRunFollowsTheSerialRun) {
    for (int ranks : {2, 3})
        dem::Communicator::runThreadGroup(ranks, decomposition_checks::multiStepRunFollowsTheSerialRun);
}

}  // namespace
