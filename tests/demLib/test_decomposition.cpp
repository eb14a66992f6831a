// The MPI design of demLib, checked in one process: the communicator (serial
// fallback; refusal to run over MPI that the caller did not initialise; ranks
// as threads), slab geometry, and the decomposed code path (id-keyed history
// stash, migration bookkeeping, owned/ghost split) on one rank, which must
// reproduce the plain serial engine bit for bit, and on 2 and 3 thread ranks,
// which must follow it (decomposition_checks.hpp, also run on MPI ranks by
// mpi/test_mpi_decomposition.cpp under mpirun).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
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
#include "demLib/liquid_bridges_over_ranks.hpp"
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
    // A restart file is read into a decomposed simulation before any insertion.
    dem::Simulation sim = c.make();
    sim.setDecomposition(oneRankDecomposition());
    sim.insert(c.particles, 0, Vec3::Zero());
    EXPECT_THROW(sim.readRestart("never_read.h5"), dem::InputError);
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

// The wet gas on one rank of the decomposition: the liquid is shared by the
// serial rule (one rank), so every bit matches the serial engine.
TEST(Decomposition, OneRankWetRunReproducesTheSerialEngineBitwise) {
    OneThread one;
    const Case c = wetGas();
    dem::Simulation serial = c.make();
    serial.insert(c.particles, 0, Vec3::Zero());
    setMotionById(serial, c);
    serial.setWaterContent(c.waterContent);
    dem::Simulation decomposed = c.make();
    decomposed.setDecomposition(oneRankDecomposition());
    decomposed.insert(c.particles, 0, Vec3::Zero());
    setMotionById(decomposed, c);
    decomposed.setWaterContent(c.waterContent);
    serial.step(300);
    decomposed.step(300);
    const dem::ParticleStore& a = serial.particles();
    const dem::ParticleStore& b = decomposed.particles();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_GT(serial.liquid().bridgeCount, 100u);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a.id[i] != b.id[i] || a.position[i] != b.position[i] || a.velocity[i] != b.velocity[i] ||
            a.force[i] != b.force[i])
            ++differ;
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(serial.pairList().bridgeVolume(), decomposed.pairList().bridgeVolume());
    EXPECT_EQ(serial.liquid().bridgeCount, decomposed.liquidOverRanks().bridgeCount);
}

TEST(ThreadRanks, WetRunSharesTheSerialLiquid) {
    for (int ranks : {2, 3, 4})
        dem::Communicator::runThreadGroup(ranks, decomposition_checks::wetRunSharesTheSerialLiquid);
}

// The whole state of a run by global id, gathered on rank 0: particles
// (position, velocity, spin) and the pairs with history or a bridge (by
// smaller id first; history seen from the smaller id).
struct RunState {
    std::map<std::int64_t, std::array<double, 9>> particles;
    std::map<std::pair<std::int64_t, std::int64_t>, std::array<double, 7>> pairs;
    std::size_t wallRecords = 0;
};

void gatherState(const dem::Communicator& comm, const dem::Simulation& sim, RunState& into) {
    const dem::ParticleStore& p = sim.particles();
    const std::size_t owned = sim.ownedCount();
    std::vector<double> mine;
    for (std::size_t i = 0; i < owned; ++i) {
        mine.push_back(1.0);
        mine.push_back(static_cast<double>(p.id[i]));
        for (const Vec3* v : {&p.position[i], &p.velocity[i], &p.omega[i]})
            for (int d = 0; d < 3; ++d) mine.push_back((*v)[d]);
    }
    const auto& offsets = sim.pairList().offsets();
    const auto& neighbors = sim.pairList().neighbors();
    const dem::PairStateView state = sim.pairList().state();
    for (std::size_t i = 0; i < owned; ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const std::size_t j = static_cast<std::size_t>(neighbors[k]);
            if (j >= owned && p.id[j] < p.id[i]) continue;  // the other rank's to report
            dem::PairState s = state[k];
            if (s.bridgeVolume == 0.0 && s.contact.shear.isZero(0.0) && s.contact.rollingAngle.isZero(0.0)) continue;
            const double sign = p.id[i] < p.id[j] ? 1.0 : -1.0;
            mine.push_back(2.0);
            mine.push_back(static_cast<double>(std::min(p.id[i], p.id[j])));
            mine.push_back(static_cast<double>(std::max(p.id[i], p.id[j])));
            mine.push_back(s.bridgeVolume);
            for (int d = 0; d < 3; ++d) mine.push_back(sign * s.contact.shear[d]);
            for (int d = 0; d < 3; ++d) mine.push_back(sign * s.contact.rollingAngle[d]);
        }
    std::size_t walls = 0;
    for (const auto& r : sim.wallContacts().records())
        if (static_cast<std::size_t>(r.particle) < owned) ++walls;
    const std::int64_t wallRecords = comm.sum(static_cast<std::int64_t>(walls));
    const auto all = dem::gatherFromAllRanks(comm, mine);
    if (comm.rank() != 0) return;
    into = RunState();
    into.wallRecords = static_cast<std::size_t>(wallRecords);
    for (const auto& part : all)
        for (std::size_t at = 0; at < part.size();) {
            if (part[at] == 1.0) {
                std::array<double, 9> v;
                std::copy(part.begin() + at + 2, part.begin() + at + 11, v.begin());
                EXPECT_TRUE(into.particles.emplace(static_cast<std::int64_t>(part[at + 1]), v).second)
                    << "particle owned twice";
                at += 11;
            } else {
                std::array<double, 7> v;
                std::copy(part.begin() + at + 3, part.begin() + at + 10, v.begin());
                into.pairs[{static_cast<std::int64_t>(part[at + 1]), static_cast<std::int64_t>(part[at + 2])}] = v;
                at += 10;
            }
        }
}

double largestPositionDifference(const RunState& a, const RunState& b) {
    double largest = 0.0;
    for (const auto& [id, v] : a.particles) {
        const auto it = b.particles.find(id);
        if (it == b.particles.end()) return std::numeric_limits<double>::infinity();
        for (int d = 0; d < 3; ++d) largest = std::max(largest, std::abs(v[d] - it->second[d]));
    }
    return largest;
}

// A wet run with contact history written on N ranks (and by the serial
// engine) continues on M ranks: right after reading, every particle, pair
// history, bridge and wall contact is the written one, bit for bit; continued
// on the same N the run is bitwise the uninterrupted one, on another M it
// follows it to round-off.
TEST(ThreadRanks, RestartWrittenOnNRanksContinuesOnM) {
    OneThread one;
    const Case c = wetGas();
    const long before = 120, after = 120;
    auto decomposedRun = [&](const dem::Communicator& comm) {
        auto sim = std::make_unique<dem::Simulation>(c.make());
        sim->setDecomposition(std::make_shared<dem::GhostExchange>(
            comm, dem::SlabDecomposition::uniform(comm.size(), 0, c.xLower, c.xUpper)));
        return sim;
    };
    for (int writers : {0, 1, 2, 3}) {  // 0: the serial engine writes
        const std::string file = ::testing::TempDir() + "decomposed_restart_" + std::to_string(writers) + ".h5";
        RunState written, uninterrupted;
        auto writeAndGoOn = [&](dem::Simulation& sim, const dem::Communicator& comm) {
            sim.insert(c.particles, 0, Vec3::Zero());
            setMotionById(sim, c);
            sim.setWaterContent(c.waterContent);
            sim.step(before);
            sim.writeRestart(file);
            gatherState(comm, sim, written);
            sim.step(after);
            gatherState(comm, sim, uninterrupted);
        };
        if (writers == 0) {
            dem::Simulation sim = c.make();
            writeAndGoOn(sim, dem::Communicator::serial());
        } else {
            dem::Communicator::runThreadGroup(writers, [&](const dem::Communicator& comm) {
                auto sim = decomposedRun(comm);
                writeAndGoOn(*sim, comm);
            });
        }
        ASSERT_GT(written.pairs.size(), 200u);
        ASSERT_GT(written.wallRecords, 5u);
        for (int readers : {0, 1, 2, 3, 4}) {
            SCOPED_TRACE("written on " + std::to_string(writers) + " ranks, read on " + std::to_string(readers));
            RunState read, continued;
            auto readAndGoOn = [&](dem::Simulation& sim, const dem::Communicator& comm) {
                sim.readRestart(file);
                gatherState(comm, sim, read);
                sim.step(after);
                gatherState(comm, sim, continued);
            };
            if (readers == 0) {
                dem::Simulation sim = c.make();
                readAndGoOn(sim, dem::Communicator::serial());
            } else {
                dem::Communicator::runThreadGroup(readers, [&](const dem::Communicator& comm) {
                    auto sim = decomposedRun(comm);
                    readAndGoOn(*sim, comm);
                });
            }
            EXPECT_EQ(read.particles, written.particles);
            EXPECT_EQ(read.pairs, written.pairs);
            EXPECT_EQ(read.wallRecords, written.wallRecords);
            // One rank and the serial engine are the same run (bitwise, above).
            const bool sameRun = readers == writers || readers + writers == 1;
            if (sameRun)
                EXPECT_TRUE(continued.particles == uninterrupted.particles && continued.pairs == uninterrupted.pairs)
                    << "continued on as many ranks: expected the uninterrupted run bit for bit";
            else
                EXPECT_LE(largestPositionDifference(continued, uninterrupted), 1e-9);
        }
        std::remove(file.c_str());
    }
}

// A restart read on another rank count is cut by particle count over the
// file's particles before they are handed out, so that a bed at rest does not
// stay on the ranks the set-up slabs gave it until its next list build (the
// set-up cut here lies beyond every particle: one rank would own them all).
// Read on as many ranks as wrote it, the file's own cuts are kept.
TEST(ThreadRanks, RestartOnAnotherRankCountStartsBalanced) {
    OneThread one;
    const Case c = wetGas();
    const double width = c.xUpper - c.xLower;
    for (int writers : {0, 2}) {
        const std::string file = ::testing::TempDir() + "balanced_restart_" + std::to_string(writers) + ".h5";
        std::vector<double> writtenCuts;
        auto write = [&](dem::Simulation& sim) {
            sim.insert(c.particles, 0, Vec3::Zero());
            setMotionById(sim, c);
            sim.setWaterContent(c.waterContent);
            sim.step(60);
            sim.writeRestart(file);
        };
        if (writers == 0) {
            dem::Simulation sim = c.make();
            write(sim);
        } else {
            dem::Communicator::runThreadGroup(writers, [&](const dem::Communicator& comm) {
                auto sim = std::make_unique<dem::Simulation>(c.make());
                sim->setDecomposition(std::make_shared<dem::GhostExchange>(
                    comm, dem::SlabDecomposition::uniform(comm.size(), 0, c.xLower, c.xUpper)));
                write(*sim);
                if (comm.rank() == 0) writtenCuts = sim->decomposition()->slabs().interiorCuts();
            });
        }
        dem::Communicator::runThreadGroup(2, [&](const dem::Communicator& comm) {
            SCOPED_TRACE("written on " + std::to_string(writers) + " ranks, read on 2");
            auto sim = std::make_unique<dem::Simulation>(c.make());
            sim->setDecomposition(std::make_shared<dem::GhostExchange>(
                comm, dem::SlabDecomposition::uniform(2, 0, c.xUpper + width, c.xUpper + 3 * width)));
            sim->readRestart(file);
            const dem::GhostExchange& d = *sim->decomposition();
            const std::int64_t owned = static_cast<std::int64_t>(sim->ownedCount());
            const std::int64_t total = comm.sum(owned);
            const double largest = comm.max(static_cast<double>(owned));
            if (comm.rank() != 0) return;
            ASSERT_EQ(total, static_cast<std::int64_t>(c.particles.size()));
            if (writers == 2) {
                EXPECT_EQ(d.recutCount(), 0u) << "read on as many ranks: expected the file's cuts";
                EXPECT_EQ(d.slabs().interiorCuts(), writtenCuts);
                return;
            }
            EXPECT_EQ(d.recutCount(), 1u);
            EXPECT_EQ(d.lastRecut().maxOwned, total) << "before: the set-up slabs gave one rank every particle";
            EXPECT_DOUBLE_EQ(d.lastRecut().imbalance, 2.0);
            EXPECT_LE(largest / (0.5 * static_cast<double>(total)), 1.05);
            EXPECT_DOUBLE_EQ(d.lastRecut().imbalanceAfter, largest / (0.5 * static_cast<double>(total)));
        });
        std::remove(file.c_str());
    }
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
                decomposition_checks::knownSizeExchangeAgrees(c);
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

// The known-size exchange refuses a message of another size than announced,
// naming the rank it came from.
TEST(ThreadRanks, KnownSizeExchangeRefusesAnUnannouncedSize) {
    try {
        dem::Communicator::runThreadGroup(2, [](const dem::Communicator& c) {
            std::vector<std::vector<char>> send(2);
            send[1 - c.rank()].assign(4, 'x');
            const std::vector<std::size_t> sizes = c.rank() == 0 ? std::vector<std::size_t>{0, 5}
                                                                 : std::vector<std::size_t>{4, 0};
            c.exchangeKnownSizesAndAnyTrue(send, sizes, false);
        });
        FAIL() << "expected an error";
    } catch (const dem::RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("rank 1 sent 4 bytes"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("expected 5"), std::string::npos) << e.what();
    }
}

// The communication counters: the bytes sent to other ranks by exchange and
// the reductions, the calls, shared by copies of a communicator, reset to zero;
// a one-rank group counts nothing.
TEST(ThreadRanks, CommunicationCountersCountWhatIsSent) {
    for (int ranks : {2, 3}) {
        dem::Communicator::runThreadGroup(ranks, [&](const dem::Communicator& c) {
            c.resetCounters();
            const dem::Communicator copy = c;
            std::vector<std::vector<char>> send(ranks);
            for (int to = 0; to < ranks; ++to) send[to].assign(to == c.rank() ? 5 : 10 * (c.rank() + 1), 'x');
            c.exchange(send);
            c.sum(1.0);
            copy.max(2.0);
            const dem::CommunicationCounters n = copy.counters();
            EXPECT_EQ(n.exchangeCalls, 1);
            EXPECT_EQ(n.reductionCalls, 2);
            EXPECT_EQ(n.exchangeBytes, std::int64_t{10} * (c.rank() + 1) * (ranks - 1)) << "to itself not counted";
            EXPECT_EQ(n.reductionBytes, std::int64_t{2} * 8 * (ranks - 1));
            EXPECT_GE(n.seconds, 0.0);
            c.sum(0.0);  // everyone has read before the reset
            c.resetCounters();
            EXPECT_EQ(copy.counters().calls(), 0);
        });
    }
    const dem::Communicator one = dem::Communicator::serial();
    one.sum(1.0);
    EXPECT_EQ(one.counters().bytesSent(), 0);
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

TEST(ThreadRanks, PolydisperseWetRunFollowsTheSerialRun) {
    for (int ranks : {2, 3})
        dem::Communicator::runThreadGroup(ranks, decomposition_checks::polydisperseWetRunFollowsTheSerialRun);
}

TEST(ThreadRanks, AGhostGoesAsFarAsItsOwnRadiusAllowsAPair) {
    // Slabs cut at x = 0.5; rank 0 owns a small (r = 0.1) and a large (r = 0.3)
    // particle, both 0.45 from rank 1's slab.  With r_max + skin + reach = 0.3
    // a pair with rank 1 needs a centre within r_i + 0.3 of its slab: the
    // large one (0.6) is a ghost there, the small one (0.4) cannot touch anything.
    dem::Communicator::runThreadGroup(2, [](const dem::Communicator& c) {
        dem::GhostExchange exchange(c, dem::SlabDecomposition(2, 0, {0.5}));
        dem::ParticleStore p;
        if (c.rank() == 0) {
            p.add(1, Vec3(0.05, 0.0, 0.0), Vec3::Zero(), 0.1, 2500.0, 0);
            p.add(2, Vec3(0.05, 1.0, 0.0), Vec3::Zero(), 0.3, 2500.0, 0);
        }
        exchange.appendGhosts(p, 0.3);
        if (c.rank() == 1) {
            ASSERT_EQ(exchange.ghostCount(), 1u);
            EXPECT_EQ(p.id[0], 2);
        } else {
            EXPECT_EQ(exchange.ghostCount(), 0u);
        }
    });
}

}  // namespace
