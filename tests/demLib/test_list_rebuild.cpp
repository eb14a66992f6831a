// Neighbour-list rebuild without a second copy of the pair state (issue 7):
// ContactHistoryPool::repack permutes the history records in place, and
// ParticleParticleNeighborList::build merges each new row with the old one
// (history slot and bridge volume carried directly), reusing its per-thread
// buffers between builds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "demLib/contact_history_pool.hpp"
#include "demLib/liquid_bridges.hpp"
#include "demLib/particle_particle_neighbor_list.hpp"
#include "contact_history_testing.hpp"
#include "thread_count.hpp"

namespace {

using dem::Vec3;

using dem_testing::expectHistory;
using dem_testing::history;

TEST(ContactHistoryPool, RepackPermutesTheRecordsInPlaceInListOrder) {
    dem::ContactHistoryPool pool;
    pool.reset(6);
    // Slots taken out of list order (as contacts close during a run), one
    // resting: records 0..4 hold entries 4, 2, 0, 5, 1; entry 5's contact opened.
    for (int k : {4, 2, 0, 5, 1}) pool.set(k, history(k + 1.0, 10.0 * (k + 1)));
    pool.open(5);
    ASSERT_EQ(pool.contactsWithHistory(), 4u);
    ASSERT_EQ(pool.records(), 5u);
    const double* recordsBefore = pool.record(0);

    // New list of 5 entries: old entries 1, 4 and 0 continue (in that order),
    // entry 1 is a new pair already in contact, entry 3 a new pair apart; old
    // entry 2 left the list, old entry 5's resting record is dropped.
    const std::vector<int> oldSlots(pool.slots(), pool.slots() + 6);
    std::vector<int> source{oldSlots[1], dem::ContactHistoryPool::freshRecord, oldSlots[4], -1, oldSlots[0]};
    pool.repack(source);
    EXPECT_EQ(source, oldSlots);  // the old slot array comes back as a buffer
    EXPECT_EQ(pool.entries(), 5u);
    EXPECT_EQ(pool.records(), 4u);
    EXPECT_EQ(pool.record(0), recordsBefore);  // same memory: no second copy of the records
    // Slots in list order, the records moved with them.
    EXPECT_EQ(pool.slots()[0], 0);
    EXPECT_EQ(pool.slots()[1], 1);
    EXPECT_EQ(pool.slots()[2], 2);
    EXPECT_EQ(pool.slots()[3], -1);
    EXPECT_EQ(pool.slots()[4], 3);
    expectHistory(pool.get(0), history(2.0, 20.0));
    expectHistory(pool.get(1), history(0.0, 0.0));
    expectHistory(pool.get(2), history(5.0, 50.0));
    expectHistory(pool.get(3), history(0.0, 0.0));
    expectHistory(pool.get(4), history(1.0, 10.0));

    // More contacts than records: the pool grows, fresh records are zero even
    // where a dropped record's values lay before.
    std::vector<int> grow(8, dem::ContactHistoryPool::freshRecord);
    grow[6] = 2;  // old entry 2 (history 5, 50)
    grow[0] = 0;  // old entry 0 (history 2, 20)
    pool.repack(grow);
    EXPECT_EQ(pool.records(), 8u);
    expectHistory(pool.get(0), history(2.0, 20.0));
    expectHistory(pool.get(6), history(5.0, 50.0));
    for (int k : {1, 2, 3, 4, 5, 7}) expectHistory(pool.get(k), history(0.0, 0.0));
    for (int k = 0; k < 8; ++k) EXPECT_EQ(pool.slots()[k], k);
    // New contacts after the rebuild still get slots.
    pool.set(7, history(9.0, 90.0));
    expectHistory(pool.get(7), history(9.0, 90.0));
}

// A jittered cubic lattice of spheres, some pairs overlapping.
dem::ParticleStore jitteredLattice(int side, double radius, double jitter, unsigned seed) {
    dem::ParticleStore p;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-jitter, jitter);
    int id = 0;
    for (int z = 0; z < side; ++z)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const Vec3 at(2.0 * radius * x + u(rng), 2.0 * radius * y + u(rng), 2.0 * radius * z + u(rng));
                p.add(id, at, Vec3::Zero(), radius * (1.0 + 0.2 * (id % 3)), 2500.0, 0);
                ++id;
            }
    return p;
}

// All pairs (i < j) closer than r_i + r_j + skin, by brute force.
std::vector<std::pair<int, int>> allPairs(const dem::ParticleStore& p, double skin) {
    std::vector<std::pair<int, int>> pairs;
    const int n = static_cast<int>(p.size());
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j) {
            const double range = p.radius[i] + p.radius[j] + skin;
            if ((p.position[j] - p.position[i]).squaredNorm() < range * range) pairs.emplace_back(i, j);
        }
    return pairs;
}

std::vector<std::pair<int, int>> listedPairs(const dem::ParticleParticleNeighborList& list) {
    std::vector<std::pair<int, int>> pairs;
    for (std::size_t i = 0; i + 1 < list.offsets().size(); ++i)
        for (int k = list.offsets()[i]; k < list.offsets()[i + 1]; ++k) pairs.emplace_back(static_cast<int>(i), list.neighbors()[k]);
    return pairs;
}

// Builds, gives every listed pair a history and bridge volume derived from
// (i, j), moves the particles, rebuilds twice; returns the final list's pairs
// with their state.
struct RebuildResult {
    std::vector<std::pair<int, int>> pairs;
    std::vector<dem::PairState> state;
    std::vector<int> slots;
};

RebuildResult rebuildTwice(int threads) {
    ThreadCount scope(threads);
    const double radius = 1e-3, skin = 0.4e-3;
    dem::ParticleStore p = jitteredLattice(14, radius, 0.3e-3, 7);
    dem::ParticleParticleNeighborList list;
    list.setRanges(skin, 0.0);
    list.setStateFields({true, true});
    // Pairs in contact at some build: they got a (zero) record then.
    std::set<std::pair<int, int>> touchedAtABuild;
    auto noteTouching = [&] {
        for (const auto& [i, j] : listedPairs(list)) {
            const double contact = p.radius[i] + p.radius[j];
            if ((p.position[j] - p.position[i]).squaredNorm() < contact * contact) touchedAtABuild.insert({i, j});
        }
    };
    list.build(p);
    EXPECT_EQ(listedPairs(list), allPairs(p, skin));
    noteTouching();
    std::map<std::pair<int, int>, dem::PairState> given;
    for (std::size_t i = 0; i + 1 < list.offsets().size(); ++i)
        for (int k = list.offsets()[i]; k < list.offsets()[i + 1]; ++k) {
            const int j = list.neighbors()[k];
            if ((i + j) % 3 == 0) continue;  // some pairs without history
            dem::PairState s;
            s.contact = history(1e-6 * (i + 1), 1e-9 * (j + 1));
            s.bridgeVolume = 1e-12 * (i + 2 * j);
            list.setStateAt(k, s);
            given[{static_cast<int>(i), j}] = s;
        }
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-0.25e-3, 0.25e-3);
    for (int round = 0; round < 2; ++round) {
        for (Vec3& x : p.position) x += Vec3(u(rng), u(rng), u(rng));
        list.build(p);
        EXPECT_EQ(listedPairs(list), allPairs(p, skin));
        noteTouching();
        // A pair that left the list has lost its state for good.
        const std::vector<std::pair<int, int>> now = listedPairs(list);
        for (auto it = given.begin(); it != given.end();)
            it = std::binary_search(now.begin(), now.end(), it->first) ? std::next(it) : given.erase(it);
    }
    EXPECT_GT(list.buildBufferBytes(), 0u);

    RebuildResult r;
    r.pairs = listedPairs(list);
    for (std::size_t k = 0; k < r.pairs.size(); ++k) {
        r.state.push_back(list.state()[k]);
        r.slots.push_back(list.history().slots()[k]);
        const auto [i, j] = r.pairs[k];
        const auto it = given.find({i, j});
        const dem::PairState s = list.state()[k];
        if (it != given.end()) {
            // Listed all along (else it would have lost its state): carried over.
            expectHistory(s.contact, it->second.contact);
            EXPECT_EQ(s.bridgeVolume, it->second.bridgeVolume);
        } else {
            expectHistory(s.contact, history(0.0, 0.0));
            EXPECT_EQ(s.bridgeVolume, 0.0);
        }
        // A pair in contact at the build has a record (zero if new); one that
        // was given no history and touched at no build has none.
        const double contact = p.radius[i] + p.radius[j];
        const bool touching = (p.position[j] - p.position[i]).squaredNorm() < contact * contact;
        if (touching) {
            EXPECT_GE(list.history().slots()[k], 0) << i << ' ' << j;
        } else if (it == given.end() && !touchedAtABuild.count({i, j})) {
            EXPECT_EQ(list.history().slots()[k], -1) << i << ' ' << j;
        }
    }
    // Records in list order after a build.
    int last = -1;
    for (int s : r.slots)
        if (s >= 0) {
            EXPECT_EQ(s, last + 1);
            last = s;
        }
    return r;
}

TEST(ParticleParticleNeighborList, RebuildCarriesPairStateAndDoesNotDependOnThreads) {
    const RebuildResult one = rebuildTwice(1);
    const RebuildResult two = rebuildTwice(2);
    ASSERT_GT(one.pairs.size(), 5000u);
    // Some pairs survived with their state, some were dropped or are new.
    std::size_t carried = 0;
    for (const dem::PairState& s : one.state) carried += s.bridgeVolume > 0.0;
    EXPECT_GT(carried, one.pairs.size() / 4);
    EXPECT_LT(carried, one.pairs.size());
    EXPECT_EQ(one.pairs, two.pairs);
    EXPECT_EQ(one.slots, two.slots);
    ASSERT_EQ(one.state.size(), two.state.size());
    for (std::size_t k = 0; k < one.state.size(); ++k) {
        expectHistory(one.state[k].contact, two.state[k].contact);
        EXPECT_EQ(one.state[k].bridgeVolume, two.state[k].bridgeVolume);
    }
}

// The pairs in contact at the build, per row (the force loop's cost estimate
// for its thread split), against brute force; the same with 1 and 2 threads;
// gone after a remap until the next build.
TEST(ParticleParticleNeighborList, CountsTouchingPairsPerRowAtTheBuild) {
    const dem::ParticleStore p = jitteredLattice(14, 0.5e-3, 0.08e-3, 11);
    const int n = static_cast<int>(p.size());
    std::vector<int> expected(n + 1, 0);
    for (const auto& [i, j] : allPairs(p, 0.0)) ++expected[i + 1];
    for (int i = 0; i < n; ++i) expected[i + 1] += expected[i];
    ASSERT_GT(expected[n], n / 2);  // many contacts ...
    ASSERT_LT(expected[n], static_cast<int>(allPairs(p, 0.2e-3).size()));  // ... fewer than listed pairs
    for (int threads : {1, 2}) {
        ThreadCount scope(threads);
        dem::ParticleParticleNeighborList list;
        list.setRanges(0.2e-3, 0.0);
        list.build(p);
        EXPECT_EQ(list.touchingOffsets(), expected) << threads << " thread(s)";
        std::vector<int> identity(n);
        for (int i = 0; i < n; ++i) identity[i] = i;
        list.remap(identity);
        EXPECT_TRUE(list.touchingOffsets().empty());
    }
}

// With a bridge listing limit λ_max, a pair beyond touching reach (gap >=
// skin) but within the extra range is listed iff a bridge could hold between
// its particles at λ_max (λ*_k <= λ_max), against brute force; pairs within
// touching reach are always listed.  Polydisperse jittered lattice (radii
// 0.5, 0.6, 0.7 mm).
TEST(ParticleParticleNeighborList, ListsPairsBeyondTouchingReachOnlyWhereABridgeCanHold) {
    const dem::ParticleStore p = jitteredLattice(12, 0.5e-3, 0.1e-3, 5);
    const double skin = 0.05e-3, extra = 0.6e-3;
    dem::LiquidBridgeSettings bridges;
    bridges.contactAngle = 0.3;
    // λ* of a pair 0.2 mm apart with radii 0.5 and 0.6 mm: pairs closer or
    // smaller-gapped per weight pass, the wider ones (up to 0.65 mm) do not.
    const double limit = dem::bridgeStabilityThreshold(0.5e-3, 0.6e-3, 1.3e-3, bridges);
    std::vector<std::pair<int, int>> expected;
    std::size_t beyondTouching = 0, withinRange = 0;
    for (const auto& [i, j] : allPairs(p, skin + extra)) {
        ++withinRange;
        const double distance = (p.position[j] - p.position[i]).norm();
        const double touchingReach = p.radius[i] + p.radius[j] + skin;
        if (distance < touchingReach) {
            expected.emplace_back(i, j);
        } else if (dem::bridgeStabilityThreshold(p.radius[i], p.radius[j], distance, bridges) <= limit) {
            expected.emplace_back(i, j);
            ++beyondTouching;
        }
    }
    // The limit must cut: some pairs beyond touching reach in, many out.
    ASSERT_GT(beyondTouching, 100u);
    ASSERT_LT(expected.size() + 1000, withinRange);
    for (int threads : {1, 2}) {
        ThreadCount scope(threads);
        dem::ParticleParticleNeighborList list;
        list.setRanges(skin, extra);
        list.setBridgeListing(bridges, limit);
        list.build(p);
        EXPECT_EQ(listedPairs(list), expected) << threads << " thread(s)";
        // No limit: the whole range again, from the same build positions.
        list.setBridgeListing(bridges, std::numeric_limits<double>::infinity());
        list.relistAtBuildPositions(p);
        EXPECT_EQ(listedPairs(list), allPairs(p, skin + extra)) << threads << " thread(s)";
        EXPECT_EQ(list.buildCount(), 1);
    }
}

// A bed with a size ratio of 6 (the coarse-grained F32 sand has 5.6) at
// random positions, with an extra range: the build skips the cells beyond each
// particle's own reach (its radius + the largest + skin + extra), and must
// still list every pair that brute force finds, small-large pairs across cell
// faces included, and count the touching ones.  1 and 2 threads.
TEST(ParticleParticleNeighborList, ListsEveryPairOfAWidelyPolydisperseBed) {
    dem::ParticleStore p;
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double smallest = 0.2e-3, largest = 1.2e-3, side = 0.012;
    for (int id = 0; id < 4000; ++id) {
        // Log-uniform radii: most particles small, as by number in a sieve distribution.
        const double r = smallest * std::pow(largest / smallest, u(rng));
        p.add(id, Vec3(side * u(rng), side * u(rng), 0.5 * side * u(rng)), Vec3::Zero(), r, 2500.0, 0);
    }
    const double skin = 0.25e-3, extra = 0.15e-3;
    const std::vector<std::pair<int, int>> expected = allPairs(p, skin + extra);
    std::vector<int> touching(p.size() + 1, 0);
    for (const auto& [i, j] : allPairs(p, 0.0)) ++touching[i + 1];
    for (std::size_t i = 0; i < p.size(); ++i) touching[i + 1] += touching[i];
    std::size_t smallLarge = 0;
    for (const auto& [i, j] : expected)
        smallLarge += std::max(p.radius[i], p.radius[j]) > 3.0 * std::min(p.radius[i], p.radius[j]);
    ASSERT_GT(expected.size(), 10000u);
    ASSERT_GT(smallLarge, 1000u) << "pairs of a small and a large particle";
    ASSERT_GT(touching.back(), 1000);
    for (int threads : {1, 2}) {
        ThreadCount scope(threads);
        dem::ParticleParticleNeighborList list;
        list.setRanges(skin, extra);
        list.build(p);
        EXPECT_EQ(listedPairs(list), expected) << threads << " thread(s)";
        EXPECT_EQ(list.touchingOffsets(), touching) << threads << " thread(s)";
    }
}

// A bed whose pair count creeps up by a little at every build (a settling bed
// over a few thousand steps) keeps its list's memory: the build buffers, which
// trade places with the list's arrays on one thread, are replaced only when
// they hold less than the old pairs and a sixteenth.  They were replaced at
// every build whose count exceeded the one two builds before (+1.5 MB per
// other build on the 50k bench bed, docs/performance-log.md, round 13).
TEST(ParticleParticleNeighborList, MemoryStaysPutWhileThePairCountCreepsUp) {
    ThreadCount scope(1);
    const double radius = 1e-3, skin = 0.4e-3;
    dem::ParticleStore p = jitteredLattice(14, radius, 0.3e-3, 7);
    dem::ParticleParticleNeighborList list;
    list.setRanges(skin, 0.0);
    list.build(p);
    list.build(p);  // both sets of buffers exist from here on
    // The pair-sized arrays the list and its build buffers hold (the slot
    // array, which also trades places with a buffer, is counted with the
    // history records, which grow with the contacts by their own rule): the
    // two sets alternate, so the figure repeats every second build.
    const auto pairArrayBytes = [&] { return list.neighbors().capacity() * sizeof(int) + list.buildBufferBytes(); };
    std::vector<std::size_t> bytes{pairArrayBytes()};
    const std::size_t pairsAtStart = list.pairCount();
    Vec3 centre = Vec3::Zero();
    for (const Vec3& x : p.position) centre += x;
    centre /= static_cast<double>(p.size());
    for (int round = 0; round < 8; ++round) {
        const std::size_t before = list.pairCount();
        for (Vec3& x : p.position) x = centre + (x - centre) * (1.0 - 4e-4);
        list.build(p);
        ASSERT_GT(list.pairCount(), before) << "round " << round << ": the test needs a growing pair count";
        bytes.push_back(pairArrayBytes());
        if (bytes.size() > 2) {
            EXPECT_EQ(bytes.back(), bytes[bytes.size() - 3]) << "round " << round << ": " << list.pairCount() << " pairs";
        }
    }
    EXPECT_LT(list.pairCount(), pairsAtStart + pairsAtStart / 16);
}

}  // namespace
