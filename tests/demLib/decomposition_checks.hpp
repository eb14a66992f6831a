#pragma once
// The domain decomposition against the serial engine, for any communicator:
// MPI ranks (mpi/test_mpi_decomposition.cpp, under mpirun) and thread ranks
// (test_decomposition.cpp, Communicator::runThreadGroup).  Every rank also
// runs the serial reference on the whole bed, so the comparison by global id
// needs no gathering.  Only EXPECTs and collective summaries: a rank that
// stopped early would leave the others waiting.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "decomposition_cases.hpp"
#include "demLib/communicator.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/simulation.hpp"

namespace decomposition_checks {

using dem::Vec3;
using namespace decomposition_cases;

// Reductions and the personalised exchange give every rank the expected values.
inline void collectivesAgree(const dem::Communicator& c) {
    const int rank = c.rank();
    const int size = c.size();
    EXPECT_EQ(c.sum(static_cast<double>(rank + 1)), 0.5 * size * (size + 1));
    EXPECT_EQ(c.sum(std::int64_t{rank}), std::int64_t{size} * (size - 1) / 2);
    EXPECT_EQ(c.min(static_cast<double>(rank)), 0.0);
    EXPECT_EQ(c.max(static_cast<double>(rank)), size - 1.0);
    EXPECT_EQ(c.anyTrue(rank == size - 1), true);
    EXPECT_EQ(c.anyTrue(false), false);
    // Rank r sends r + 1 bytes of value (10 r + destination) to every other
    // rank and nothing to itself but one byte.
    std::vector<std::vector<char>> send(size);
    for (int to = 0; to < size; ++to) send[to].assign(to == rank ? 1 : rank + 1, static_cast<char>(10 * rank + to));
    const auto got = c.exchange(send);
    ASSERT_EQ(static_cast<int>(got.size()), size);
    for (int from = 0; from < size; ++from) {
        const std::size_t expected = from == rank ? 1 : from + 1;
        EXPECT_EQ(got[from].size(), expected) << "from rank " << from;
        for (char b : got[from]) EXPECT_EQ(b, static_cast<char>(10 * from + rank));
    }
}

// The step's round (exchangeKnownSizesAndAnyTrue): rank r sends 3 (r + 1) +
// destination bytes of value (10 r + destination) to every other rank (none
// to rank 0 from the last rank, which rank 0 then expects), each rank knowing
// what it gets; the flag is the logical or over the ranks.
inline void knownSizeExchangeAgrees(const dem::Communicator& c) {
    const int rank = c.rank();
    const int size = c.size();
    auto bytes = [&](int from, int to) -> std::size_t {
        if (from == to) return 0;
        if (from == size - 1 && to == 0) return 0;
        return static_cast<std::size_t>(3 * (from + 1) + to);
    };
    for (int round = 0; round < 3; ++round) {
        std::vector<std::vector<char>> send(size);
        std::vector<std::size_t> sizes(size);
        for (int r = 0; r < size; ++r) {
            send[r].assign(bytes(rank, r), static_cast<char>(10 * rank + r));
            sizes[r] = bytes(r, rank);
        }
        // Round 0: only the last rank raises the flag; round 1: none; round 2: all.
        const bool flag = round == 2 || (round == 0 && rank == size - 1);
        const auto got = c.exchangeKnownSizesAndAnyTrue(send, sizes, flag);
        EXPECT_EQ(got.anyTrue, round != 1) << "round " << round;
        ASSERT_EQ(static_cast<int>(got.received.size()), size);
        for (int from = 0; from < size; ++from) {
            if (from == rank) continue;
            EXPECT_EQ(got.received[from].size(), bytes(from, rank)) << "from rank " << from;
            for (char b : got.received[from]) EXPECT_EQ(b, static_cast<char>(10 * from + rank));
        }
    }
}

struct Runs {
    dem::Simulation serial;
    dem::Simulation decomposed;
    std::shared_ptr<dem::GhostExchange> exchange;
};

// The serial reference and this rank's part of the decomposed run, slabs
// along x cut between the lattice planes (and off them by `shift` lattice
// spacings, so that cuts need not fall where the bed is sparse).
inline std::unique_ptr<Runs> start(const dem::Communicator& comm, const Case& c, double shift) {
    const double span = c.xUpper - c.xLower;
    const double offset = shift * span / 7.0;
    auto exchange = std::make_shared<dem::GhostExchange>(
        comm, dem::SlabDecomposition::uniform(comm.size(), 0, c.xLower + offset, c.xUpper + offset));
    auto runs = std::unique_ptr<Runs>(new Runs{c.make(), c.make(), exchange});
    runs->serial.insert(c.particles, 0, Vec3::Zero());
    setMotionById(runs->serial, c);
    runs->decomposed.setDecomposition(exchange);
    runs->decomposed.insert(c.particles, 0, Vec3::Zero());
    setMotionById(runs->decomposed, c);
    if (c.waterContent > 0.0) {
        runs->serial.setWaterContent(c.waterContent);
        runs->decomposed.setWaterContent(c.waterContent);
    }
    return runs;
}

// Index of each id in the serial run (ids are 0 .. N-1, never reused).
inline std::vector<long> indexById(const dem::ParticleStore& p, std::size_t idCount) {
    std::vector<long> index(idCount, -1);
    for (std::size_t i = 0; i < p.size(); ++i) index[static_cast<std::size_t>(p.id[i])] = static_cast<long>(i);
    return index;
}

// Largest |force| and |torque| of the serial run over all particles.
inline std::pair<double, double> largestLoads(const dem::ParticleStore& p) {
    double f = 0.0, t = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        f = std::max(f, p.force[i].norm());
        t = std::max(t, p.torque[i].norm());
    }
    return {f, t};
}

// Touching pairs of an owned particle with a ghost, i.e. across a slab face.
inline std::size_t straddlingContacts(const dem::Simulation& sim) {
    const dem::ParticleStore& p = sim.particles();
    const auto& offsets = sim.pairList().offsets();
    const auto& neighbors = sim.pairList().neighbors();
    const std::size_t owned = sim.ownedCount();
    std::size_t count = 0;
    for (std::size_t i = 0; i < owned; ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const int j = neighbors[k];
            if (static_cast<std::size_t>(j) >= owned &&
                (p.position[i] - p.position[j]).norm() < p.radius[i] + p.radius[j])
                ++count;
        }
    return count;
}

// Calls visit(i, k) for every owned particle i of the decomposed run whose id
// the serial run holds, k its index there; returns how many owned ids it lacks.
template <class Visit>
std::int64_t forEachOwnedInSerial(const Runs& runs, Visit visit) {
    const dem::ParticleStore& mine = runs.decomposed.particles();
    const std::vector<long> index = indexById(runs.serial.particles(), static_cast<std::size_t>(runs.serial.nextId()));
    std::int64_t missing = 0;
    for (std::size_t i = 0; i < runs.decomposed.ownedCount(); ++i) {
        const long k = index[static_cast<std::size_t>(mine.id[i])];
        if (k < 0)
            ++missing;
        else
            visit(i, static_cast<std::size_t>(k));
    }
    return missing;
}

// Largest force and torque deviation of the owned particles from the serial
// run (by id), over all ranks, relative to the largest force and torque of the
// serial bed.
inline void expectLoadsMatch(const dem::Communicator& comm, const Runs& runs, const char* when) {
    const dem::ParticleStore& ref = runs.serial.particles();
    const dem::ParticleStore& mine = runs.decomposed.particles();
    const auto [fScale, tScale] = largestLoads(ref);
    double fError = 0.0, tError = 0.0;
    const std::int64_t missing = forEachOwnedInSerial(runs, [&](std::size_t i, std::size_t k) {
        fError = std::max(fError, (mine.force[i] - ref.force[k]).norm());
        tError = std::max(tError, (mine.torque[i] - ref.torque[k]).norm());
    });
    fError = comm.max(fError);
    tError = comm.max(tError);
    EXPECT_EQ(comm.sum(missing), 0) << when;
    EXPECT_LE(fError, 1e-12 * fScale) << when << ": force error " << fError << " N, largest force " << fScale;
    EXPECT_LE(tError, 1e-12 * tScale) << when << ": torque error " << tError << " N m, largest " << tScale;
    EXPECT_EQ(comm.sum(static_cast<std::int64_t>(runs.decomposed.ownedCount())),
              static_cast<std::int64_t>(ref.size()))
        << when;
    if (comm.rank() == 0)
        std::printf("[ %s ] force error %.3e of largest %.3e N; torque error %.3e of %.3e N m\n", when, fError,
                    fScale, tError, tScale);
}

// A bed of overlapping spheres with friction and rolling history: every
// owned particle gets the serial run's force and torque to round-off, also
// those whose contacts cross a slab face (computed on both sides).
inline void ghostsGiveTheSerialContactForces(const dem::Communicator& comm) {
    const Case c = overlappingBed();
    const auto runs = start(comm, c, 0.3);
    runs->serial.step(1);
    runs->decomposed.step(1);
    const std::int64_t straddling = comm.sum(static_cast<std::int64_t>(straddlingContacts(runs->decomposed)));
    if (comm.size() > 1) {
        EXPECT_GT(straddling, 50) << "contacts across slab faces";
        EXPECT_GT(comm.sum(static_cast<std::int64_t>(runs->exchange->ghostCount())), 0);
    }
    EXPECT_GT(runs->serial.lastStep().contacts.touchingPairs, 500u);
    expectLoadsMatch(comm, *runs, "after 1 step");
    // With tangential and rolling springs loaded by 40 steps of history.
    runs->serial.step(40);
    runs->decomposed.step(40);
    expectLoadsMatch(comm, *runs, "after 41 steps");
    if (comm.rank() == 0) std::printf("straddling contacts: %ld\n", static_cast<long>(straddling));
}

// Whether the ranks own, together, exactly the serial run's particles: the
// count, the sum of the ids and the sum of their squares agree (a particle
// owned twice or by none changes the count or, swapped for another, the sums).
// Collective; the same answer on every rank.
inline bool ownedOnceEach(const dem::Communicator& comm, const dem::Simulation& serial,
                          const dem::Simulation& decomposed) {
    std::int64_t count = 0, sum = 0, squares = 0;
    for (std::size_t i = 0; i < decomposed.ownedCount(); ++i) {
        const std::int64_t id = decomposed.particles().id[i];
        ++count, sum += id, squares += id * id;
    }
    std::int64_t refCount = 0, refSum = 0, refSquares = 0;
    for (std::int64_t id : serial.particles().id) ++refCount, refSum += id, refSquares += id * id;
    return comm.sum(count) == refCount && comm.sum(sum) == refSum && comm.sum(squares) == refSquares;
}

// A granular gas in a box open at the top: particles cross the slab faces
// (migration with their contact history), some leave the domain; positions
// by id follow the serial run, and no particle is lost or doubled on the way.
inline void multiStepRunFollowsTheSerialRun(const dem::Communicator& comm) {
    const Case c = agitatedGas();
    const auto runs = start(comm, c, 0.0);
    const std::size_t ids = static_cast<std::size_t>(runs->serial.nextId());
    std::vector<int> firstOwner(ids, -1);
    for (std::size_t i = 0; i < runs->serial.particles().size(); ++i)
        firstOwner[runs->serial.particles().id[i]] =
            runs->exchange->slabs().ownerOf(runs->serial.particles().position[i], 0);
    const long steps = 600;
    // Every step: each id the serial run holds is owned by exactly one rank.
    std::int64_t badSteps = 0;
    for (long s = 0; s < steps; ++s) {
        runs->serial.step(1);
        runs->decomposed.step(1);
        if (!ownedOnceEach(comm, runs->serial, runs->decomposed)) ++badSteps;
    }
    EXPECT_EQ(badSteps, 0) << "steps after which some particle was owned by no rank or by two";

    const dem::ParticleStore& ref = runs->serial.particles();
    const dem::ParticleStore& mine = runs->decomposed.particles();
    const std::vector<long> index = indexById(ref, ids);
    double xError = 0.0, vError = 0.0;
    std::int64_t unknown = 0;
    for (std::size_t i = 0; i < runs->decomposed.ownedCount(); ++i) {
        const long k = index[static_cast<std::size_t>(mine.id[i])];
        if (k < 0) {
            ++unknown;  // a particle the serial run lost or never had
            continue;
        }
        xError = std::max(xError, (mine.position[i] - ref.position[k]).norm());
        vError = std::max(vError, (mine.velocity[i] - ref.velocity[k]).norm());
        // Particles migrate at list builds; until the next one they move less
        // than half the skin, so they may be owned that far outside the slab.
        EXPECT_LE(runs->exchange->slabs().distanceToSlab(comm.rank(), mine.position[i]),
                  0.5 * runs->decomposed.pairList().skin())
            << "particle " << mine.id[i] << " owned too far outside its slab";
    }
    xError = comm.max(xError);
    vError = comm.max(vError);
    EXPECT_EQ(comm.sum(unknown), 0);
    EXPECT_LE(xError, 1e-9) << "largest position deviation [m]";
    EXPECT_LE(vError, 1e-6) << "largest velocity deviation [m/s]";

    // Conservation: every id the serial run still has is owned by exactly one rank.
    std::vector<std::vector<char>> send(comm.size());
    for (std::size_t i = 0; i < runs->decomposed.ownedCount(); ++i) {
        const char* b = reinterpret_cast<const char*>(&mine.id[i]);
        send[0].insert(send[0].end(), b, b + sizeof(std::int64_t));
    }
    const auto got = comm.exchange(send);
    if (comm.rank() == 0) {
        std::vector<std::int64_t> all;
        for (const auto& buffer : got)
            for (std::size_t at = 0; at < buffer.size(); at += sizeof(std::int64_t)) {
                std::int64_t id;
                std::memcpy(&id, buffer.data() + at, sizeof id);
                all.push_back(id);
            }
        std::sort(all.begin(), all.end());
        std::vector<std::int64_t> expected(ref.id.begin(), ref.id.end());
        std::sort(expected.begin(), expected.end());
        EXPECT_EQ(all, expected) << "global ids after the run (lost or duplicated particles)";
    }
    EXPECT_EQ(comm.sum(static_cast<std::int64_t>(runs->decomposed.lostCount())),
              static_cast<std::int64_t>(runs->serial.lostCount()));
    EXPECT_GT(runs->serial.lostCount(), 0u) << "the case should lose particles through the open top";

    // The run must have exercised migration: particles now owned by another
    // rank than at the start.
    std::int64_t crossed = 0;
    for (std::size_t k = 0; k < ref.size(); ++k)
        if (runs->exchange->slabs().ownerOf(ref.position[k], 0) != firstOwner[ref.id[k]]) ++crossed;
    const std::int64_t migrations = comm.sum(static_cast<std::int64_t>(runs->exchange->migratedCount()));
    if (comm.size() > 1) {
        EXPECT_GT(migrations, 20) << "particles sent to another rank";
        EXPECT_GT(crossed, 0) << "particles that ended in another slab";
    }
    if (comm.rank() == 0)
        std::printf("600 steps: position error %.3e m, velocity error %.3e m/s, %ld migrations, %ld particles "
                    "ended in another slab, %zu lost, %ld list builds\n",
                    xError, vError, static_cast<long>(migrations), static_cast<long>(crossed),
                    runs->serial.lostCount(), runs->decomposed.pairList().buildCount());
}

// Bridges of an owned particle with a ghost (across a slab face) that hold liquid.
inline std::size_t straddlingBridges(const dem::Simulation& sim) {
    const auto& offsets = sim.pairList().offsets();
    const auto& neighbors = sim.pairList().neighbors();
    const auto& bridge = sim.pairList().bridgeVolume();
    const std::size_t owned = sim.ownedCount();
    std::size_t count = 0;
    for (std::size_t i = 0; i < owned; ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k)
            if (static_cast<std::size_t>(neighbors[k]) >= owned && bridge[k] > 0.0) ++count;
    return count;
}

// A wet granular gas: the water of the whole run is shared over the bridges
// of all ranks by the paper's rule, so the decomposed run has the serial
// run's bridges (count, liquid per weight, hence forces) at every list build,
// conserves the liquid to 1e-12 summed over ranks, and follows the serial
// trajectories through rebuilds, migrations, broken bridges and losses.
// Steps both runs `steps` times; the number of steps after which a particle
// was owned twice or by none, or the bridges and the pool did not hold `total`.
inline std::int64_t wetStepsGoneWrong(const dem::Communicator& comm, Runs& runs, long steps, double total) {
    std::int64_t badSteps = 0;
    for (long s = 0; s < steps; ++s) {
        runs.serial.step(1);
        runs.decomposed.step(1);
        if (!ownedOnceEach(comm, runs.serial, runs.decomposed)) ++badSteps;
        // The water of the run, held by the bridges of all ranks and the pool
        const double held = runs.decomposed.liquidInBridges();
        if (!(std::abs(held + runs.decomposed.liquidOverRanks().poolVolume - total) <= 1e-12 * total)) ++badSteps;
    }
    return badSteps;
}

// The largest distance, over ranks, of an owned particle from the same id in
// the serial run; `unknown` counts owned ids the serial run does not hold.
inline double positionErrorFromSerial(const dem::Communicator& comm, const Runs& runs, std::int64_t& unknown) {
    const dem::ParticleStore& ref = runs.serial.particles();
    const dem::ParticleStore& p = runs.decomposed.particles();
    double xError = 0.0;
    unknown = comm.sum(forEachOwnedInSerial(runs, [&](std::size_t i, std::size_t k) {
        xError = std::max(xError, (p.position[i] - ref.position[k]).norm());
    }));
    return comm.max(xError);
}

inline void wetRunSharesTheSerialLiquid(const dem::Communicator& comm) {
    const Case c = wetGas();
    const auto runs = start(comm, c, 0.3);
    runs->serial.step(1);
    runs->decomposed.step(1);
    const double total = runs->serial.liquid().totalVolume;
    EXPECT_GT(total, 0.0);
    // The same water on every rank (the dry mass summed over ranks: to rounding).
    EXPECT_NEAR(runs->decomposed.liquid().totalVolume, total, 1e-14 * total);
    EXPECT_EQ(comm.max(runs->decomposed.liquid().totalVolume), comm.min(runs->decomposed.liquid().totalVolume));
    const dem::LiquidState serial = runs->serial.liquid();
    const dem::LiquidState mine = runs->decomposed.liquidOverRanks();
    EXPECT_GT(serial.bridgeCount, 300u);
    EXPECT_GT(serial.wallBridgeCount, 10u);
    EXPECT_EQ(mine.bridgeCount, serial.bridgeCount);
    EXPECT_EQ(mine.wallBridgeCount, serial.wallBridgeCount);
    EXPECT_NEAR(runs->decomposed.liquidInBridges(), total, 1e-12 * total);
    const std::int64_t straddling = comm.sum(static_cast<std::int64_t>(straddlingBridges(runs->decomposed)));
    if (comm.size() > 1) {
        EXPECT_GT(straddling, 20) << "bridges across slab faces";
    }
    expectLoadsMatch(comm, *runs, "wet, after 1 step");

    const long steps = 400;
    EXPECT_EQ(wetStepsGoneWrong(comm, *runs, steps, total), 0)
        << "steps after which a particle was owned twice or by none, or the liquid not conserved";
    std::int64_t unknown = 0;
    const double xError = positionErrorFromSerial(comm, *runs, unknown);
    EXPECT_EQ(unknown, 0);
    EXPECT_LE(xError, 1e-9) << "largest position deviation from the serial run [m]";
    const dem::LiquidState serialEnd = runs->serial.liquid();
    const dem::LiquidState mineEnd = runs->decomposed.liquidOverRanks();
    EXPECT_EQ(mineEnd.bridgeCount, serialEnd.bridgeCount);
    const double held = runs->decomposed.liquidInBridges();
    EXPECT_NEAR(held + mineEnd.poolVolume, total, 1e-12 * total) << "bridges + pool = the water added";
    EXPECT_NEAR(mineEnd.poolVolume, serialEnd.poolVolume, 1e-12 * total);
    EXPECT_GT(runs->serial.lostCount(), 0u) << "the case should lose (wet) particles through the open top";
    EXPECT_GT(runs->serial.pairList().buildCount(), 5) << "the liquid is shared again at every list build";
    EXPECT_EQ(comm.sum(static_cast<std::int64_t>(runs->decomposed.lostCount())),
              static_cast<std::int64_t>(runs->serial.lostCount()));
    if (comm.rank() == 0)
        std::printf("wet, %ld steps: position error %.3e m; %zu bridges (%ld across slab faces at step 1), %zu wall "
                    "bridges; liquid in bridges %.17g of %.17g m^3, pool %.3g; %zu lost; %ld list builds\n",
                    steps + 1, xError, mineEnd.bridgeCount, static_cast<long>(straddling), mineEnd.wallBridgeCount,
                    held, total, mineEnd.poolVolume, runs->serial.lostCount(),
                    runs->decomposed.pairList().buildCount());
}

// The wet gas with radii from 0.5 to 1 mm: a ghost is sent out to its own
// radius + r_max + skin + bridge reach from another slab (a small particle
// less far than a large one); the run still follows the serial one, owns each
// particle once, keeps its water and forms the same bridges.
inline void polydisperseWetRunFollowsTheSerialRun(const dem::Communicator& comm) {
    Case c = wetGas();
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> radius(0.5e-3, 1.0e-3);
    for (dem::InsertedParticle& q : c.particles) q.radius = radius(rng);
    const auto runs = start(comm, c, 0.3);
    runs->serial.step(1);
    runs->decomposed.step(1);
    const double total = runs->serial.liquid().totalVolume;
    expectLoadsMatch(comm, *runs, "polydisperse wet, after 1 step");
    EXPECT_EQ(wetStepsGoneWrong(comm, *runs, 400, total), 0)
        << "steps after which a particle was owned twice or by none, or the liquid not conserved";
    std::int64_t unknown = 0;
    const double xError = positionErrorFromSerial(comm, *runs, unknown);
    EXPECT_EQ(unknown, 0);
    EXPECT_LE(xError, 1e-9) << "largest position deviation from the serial run [m]";
    EXPECT_GT(runs->serial.liquid().bridgeCount, 50u);
    EXPECT_EQ(runs->decomposed.liquidOverRanks().bridgeCount, runs->serial.liquid().bridgeCount);
    EXPECT_GT(runs->serial.pairList().buildCount(), 5);
    if (comm.rank() == 0)
        std::printf("polydisperse wet, 401 steps: position error %.3e m; %zu bridges; %ld list builds\n", xError,
                    runs->serial.liquid().bridgeCount, runs->decomposed.pairList().buildCount());
}

}  // namespace decomposition_checks
