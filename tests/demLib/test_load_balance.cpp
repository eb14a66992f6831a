// Dynamic load balancing of the slab decomposition: balanced cuts from the
// owned coordinates of every rank (SlabDecomposition::balanced, no positions
// gathered), the axis helper, and GhostExchange::rebalanceIfNeeded followed
// by migrate, on 1 to 4 thread ranks.  The bound checked is the one
// domain_decomposition.hpp states: for unit weights at distinct coordinates
// max/mean owned <= 1.01 + 2/mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "demLib/communicator.hpp"
#include "demLib/domain_decomposition.hpp"
#include "demLib/error.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/particle_store.hpp"
#include "demLib/simulation.hpp"
#include "sand_without_gravity.hpp"

namespace {

using dem::Communicator;
using dem::SlabDecomposition;
using dem::Vec3;

// The bound of SlabDecomposition::balanced for unit weights.
double allowedMaxOverMean(double mean) { return 1.0 + 2.0 * SlabDecomposition::balanceTolerance + 2.0 / mean; }

// Global particle i of a bed of n: a coordinate in [0, 1), 95 % of them in
// [0.90, 0.91) (a settled bed in the last of four equal slabs) when clustered.
double coordinateOf(std::int64_t i, bool clustered) {
    std::mt19937_64 rng(0x5eed0000ULL + static_cast<std::uint64_t>(i));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double a = u(rng), b = u(rng);
    if (clustered && a < 0.95) return 0.90 + 0.01 * b;
    return b;
}

// The coordinates of the global particles i with i % ranks == rank (a
// distribution that has nothing to do with any slabs).
std::vector<double> roundRobinShare(const Communicator& c, std::int64_t n, bool clustered) {
    std::vector<double> mine;
    for (std::int64_t i = c.rank(); i < n; i += c.size()) mine.push_back(coordinateOf(i, clustered));
    return mine;
}

// Summed weight per slab over all ranks (unit weights when `weights` is empty).
std::vector<double> slabLoads(const Communicator& c, const SlabDecomposition& slabs, const std::vector<double>& x,
                              const std::vector<double>& weights = {}) {
    std::vector<double> load(slabs.ranks(), 0.0);
    for (std::size_t i = 0; i < x.size(); ++i) {
        Vec3 p = Vec3::Zero();
        p[slabs.axis()] = x[i];
        load[slabs.ownerOf(p, c.rank())] += weights.empty() ? 1.0 : weights[i];
    }
    return dem::sumOverRanksInRankOrder(c, load);
}

double maxOverMean(const std::vector<double>& loads) {
    double total = 0.0, largest = 0.0;
    for (double l : loads) {
        total += l;
        largest = std::max(largest, l);
    }
    return largest / (total / loads.size());
}

// Every rank holds the same bits (min and max over the ranks agree).
void expectSameOnAllRanks(const Communicator& c, const std::vector<double>& values) {
    const std::int64_t count = static_cast<std::int64_t>(values.size());
    ASSERT_EQ(c.sum(count), count * c.size());
    for (double v : values) {
        const double low = c.min(v), high = c.max(v);
        std::uint64_t a, b;
        std::memcpy(&a, &low, sizeof a);
        std::memcpy(&b, &high, sizeof b);
        EXPECT_EQ(a, b) << "rank " << c.rank() << " holds " << v;
    }
}

void expectStrictlyIncreasing(const std::vector<double>& cuts) {
    for (std::size_t k = 0; k < cuts.size(); ++k) {
        EXPECT_TRUE(std::isfinite(cuts[k])) << "cut " << k;
        if (k > 0) { EXPECT_GT(cuts[k], cuts[k - 1]) << "cut " << k; }
    }
}

TEST(SumOverRanks, AddsInRankOrderAndGivesEveryRankTheSameBits) {
    for (int ranks = 1; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            // 1e16 + 1 + 1 ... depends on the order of the additions: rank
            // order gives exactly what a sequential loop gives.
            for (std::size_t length : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{10}}) {
                std::vector<double> mine(length);
                for (std::size_t i = 0; i < length; ++i) mine[i] = c.rank() == 0 ? 1e16 : 1.0 + 0.1 * i;
                const std::vector<double> sums = dem::sumOverRanksInRankOrder(c, mine);
                ASSERT_EQ(sums.size(), length);
                for (std::size_t i = 0; i < length; ++i) {
                    double expected = 0.0;
                    for (int r = 0; r < ranks; ++r) expected += r == 0 ? 1e16 : 1.0 + 0.1 * i;
                    EXPECT_EQ(sums[i], expected) << "entry " << i;
                }
                expectSameOnAllRanks(c, sums);
            }
        });
    }
}

TEST(BalancedCuts, UniformCoordinatesGiveEqualCountsAtTheQuantiles) {
    const std::int64_t n = 20000;
    for (int ranks = 1; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const std::vector<double> x = roundRobinShare(c, n, false);
            const SlabDecomposition s = SlabDecomposition::balanced(c, 0, x);
            ASSERT_EQ(s.ranks(), ranks);
            ASSERT_EQ(s.interiorCuts().size(), static_cast<std::size_t>(ranks - 1));
            expectStrictlyIncreasing(s.interiorCuts());
            expectSameOnAllRanks(c, s.interiorCuts());
            for (int k = 1; k < ranks; ++k)  // uniform coordinates: cut k near k/P
                EXPECT_NEAR(s.interiorCuts()[k - 1], static_cast<double>(k) / ranks, 0.02);
            const std::vector<double> loads = slabLoads(c, s, x);
            const double mean = static_cast<double>(n) / ranks;
            EXPECT_LE(maxOverMean(loads), allowedMaxOverMean(mean));
            for (double l : loads) EXPECT_GE(l, mean * (1.0 - 0.02) - 2.0);
        });
    }
}

// The die filling's end state: most of the powder in a small region.  Equal
// slabs put 95 % on one rank; balanced cuts must split the bed itself.
TEST(BalancedCuts, ASettledBedIsSplitIntoEqualShares) {
    const std::int64_t n = 40000;
    for (int ranks = 2; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const std::vector<double> x = roundRobinShare(c, n, true);
            const double equalSlabs = maxOverMean(slabLoads(c, SlabDecomposition::uniform(ranks, 0, 0.0, 1.0), x));
            EXPECT_GT(equalSlabs, 0.9 * ranks) << "the case must be badly balanced by equal slabs";
            const SlabDecomposition s = SlabDecomposition::balanced(c, 0, x);
            expectStrictlyIncreasing(s.interiorCuts());
            expectSameOnAllRanks(c, s.interiorCuts());
            const double imbalance = maxOverMean(slabLoads(c, s, x));
            EXPECT_LE(imbalance, allowedMaxOverMean(static_cast<double>(n) / ranks));
            // The interior cuts of 3 and 4 ranks lie inside the 1 %-wide bed.
            for (std::size_t k = 1; k < s.interiorCuts().size(); ++k) {
                EXPECT_GT(s.interiorCuts()[k], 0.90);
                EXPECT_LT(s.interiorCuts()[k], 0.91);
            }
        });
    }
}

TEST(BalancedCuts, AllParticlesAtOneCoordinateGoToOneRankWithDistinctCuts) {
    for (int ranks = 2; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const std::vector<double> x(100 + 10 * c.rank(), 0.25);
            const SlabDecomposition s = SlabDecomposition::balanced(c, 2, x);
            EXPECT_EQ(s.axis(), 2);
            expectStrictlyIncreasing(s.interiorCuts());
            expectSameOnAllRanks(c, s.interiorCuts());
            for (double cut : s.interiorCuts()) EXPECT_NEAR(cut, 0.25, 1e-15);
            const std::vector<double> loads = slabLoads(c, s, x);
            int holding = 0;
            for (double l : loads) holding += l > 0.0;
            EXPECT_EQ(holding, 1);
            EXPECT_EQ(*std::max_element(loads.begin(), loads.end()), 100.0 * ranks + 10.0 * ranks * (ranks - 1) / 2);
        });
    }
}

// Half the weight at exactly 0, where doubles are densest: the middle cut
// falls inside the point mass, which stays on one rank whole.
TEST(BalancedCuts, APointMassAtZeroStaysWhole) {
    Communicator::runThreadGroup(4, [](const Communicator& c) {
        std::vector<double> x(250, 0.0);
        for (int i = 0; i < 250; ++i) x.push_back(-1.0 + (i + 0.5) / 125.0 + c.rank() * 1e-3);
        const SlabDecomposition s = SlabDecomposition::balanced(c, 0, x);
        expectStrictlyIncreasing(s.interiorCuts());
        expectSameOnAllRanks(c, s.interiorCuts());
        const std::vector<double> loads = slabLoads(c, s, x);
        // 500 below 0, 1000 at 0, 500 above: the point mass takes two shares,
        // so one slab stays empty and the others hold their share.
        EXPECT_EQ(std::count(loads.begin(), loads.end(), 0.0), 1);
        for (double l : loads) EXPECT_TRUE(l == 0.0 || l >= 500.0 - 2 * 0.005 * 500.0 - 2.0) << l;
        // The slab holding the 1000 at 0 holds at most one cut tolerance more.
        EXPECT_GE(*std::max_element(loads.begin(), loads.end()), 1000.0);
        EXPECT_LE(*std::max_element(loads.begin(), loads.end()), 1000.0 + 2 * 0.005 * 500.0 + 2.0);
    });
}

TEST(BalancedCuts, FewerParticlesThanRanksGiveAtMostOnePerSlab) {
    Communicator::runThreadGroup(4, [](const Communicator& c) {
        for (int count = 0; count < 4; ++count) {
            // `count` particles at 0, 1, 2, all on rank 1; the others hold none.
            std::vector<double> x;
            if (c.rank() == 1)
                for (int i = 0; i < count; ++i) x.push_back(i);
            const SlabDecomposition s = SlabDecomposition::balanced(c, 0, x);
            expectStrictlyIncreasing(s.interiorCuts());
            expectSameOnAllRanks(c, s.interiorCuts());
            const std::vector<double> loads = slabLoads(c, s, x);
            for (double l : loads) EXPECT_LE(l, 1.0) << count << " particles";
            if (count == 0) { EXPECT_EQ(s.interiorCuts(), SlabDecomposition::uniform(4, 0, -1.0, 1.0).interiorCuts()); }
        }
    });
}

// Ranks with no particle take part in every collective and get the same cuts.
TEST(BalancedCuts, EmptyRanksTakePart) {
    const std::int64_t n = 9000;
    for (int ranks = 2; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            std::vector<double> x;  // all particles on the last rank
            if (c.rank() == c.size() - 1)
                for (std::int64_t i = 0; i < n; ++i) x.push_back(coordinateOf(i, true));
            const SlabDecomposition s = SlabDecomposition::balanced(c, 1, x);
            expectStrictlyIncreasing(s.interiorCuts());
            expectSameOnAllRanks(c, s.interiorCuts());
            EXPECT_LE(maxOverMean(slabLoads(c, s, x)), allowedMaxOverMean(static_cast<double>(n) / ranks));
        });
    }
}

// Weight 3 for x < 0.5, 1 above: with 2 ranks the cut must fall where a third
// of the range holds half the weight, x = 1/3 (unit weights would give 0.5).
TEST(BalancedCuts, WeightsMoveTheCuts) {
    const std::int64_t n = 30000;
    for (int ranks = 2; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const std::vector<double> x = roundRobinShare(c, n, false);
            std::vector<double> w;
            for (double xi : x) w.push_back(xi < 0.5 ? 3.0 : 1.0);
            const SlabDecomposition s = SlabDecomposition::balanced(c, 0, x, w);
            expectSameOnAllRanks(c, s.interiorCuts());
            if (ranks == 2) { EXPECT_NEAR(s.interiorCuts()[0], 1.0 / 3.0, 0.01); }
            const std::vector<double> loads = slabLoads(c, s, x, w);
            // Weighted bound: W/P + 2 max(0.005 W/P, w_max/2) + w_max.
            double mean = 0.0;
            for (double l : loads) mean += l / ranks;
            EXPECT_LE(*std::max_element(loads.begin(), loads.end()), 1.01 * mean + 3.0);
            EXPECT_GT(maxOverMean(slabLoads(c, s, x)), 1.2) << "the counts, unweighted, are not balanced";
        });
    }
}

TEST(BalancedCuts, RejectsBadInput) {
    const Communicator serial = Communicator::serial();
    EXPECT_THROW(SlabDecomposition::balanced(serial, 3, {0.0}), dem::InputError);
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        // Checked before any collective, so each rank throws alone.
        EXPECT_THROW(SlabDecomposition::balanced(c, 0, {0.0, 1.0}, {1.0}), dem::InputError);
        EXPECT_THROW(SlabDecomposition::balanced(c, 0, {0.0}, {-1.0}), dem::InputError);
        EXPECT_THROW(SlabDecomposition::balanced(c, 0, {0.0}, {std::nan("")}), dem::InputError);
    });
    // One rank: one slab, nothing to cut.
    EXPECT_TRUE(SlabDecomposition::balanced(serial, 0, {1.0, 2.0}).interiorCuts().empty());
}

TEST(BalancedCuts, AxisOfLargestExtentIsGlobal) {
    Communicator::runThreadGroup(3, [](const Communicator& c) {
        // Each rank alone spans most in x; together the ranks span most in y.
        std::vector<Vec3> p{Vec3(0.0, 0.5 * c.rank(), 0.0), Vec3(0.4, 0.5 * c.rank(), 0.1),
                            Vec3(1.0, 2.0, 99.0)};  // not owned: ignored
        EXPECT_EQ(SlabDecomposition::axisOfLargestExtent(c, p, 2), 1);
        EXPECT_EQ(SlabDecomposition::axisOfLargestExtent(c, p, 0), 0);  // no particles
        EXPECT_EQ(SlabDecomposition::axisOfLargestExtent(c, p, c.rank() == 2 ? 3 : 2), 2);
    });
    EXPECT_THROW(SlabDecomposition::axisOfLargestExtent(Communicator::serial(), {Vec3::Zero()}, 2), dem::InputError);
}

// --- GhostExchange::rebalanceIfNeeded, then migrate ---

// The particles of a bed of n (ids 0..n-1, x from coordinateOf) that `slabs` give this rank.
dem::ParticleStore ownedParticles(const Communicator& c, const SlabDecomposition& slabs, std::int64_t n,
                                  bool clustered) {
    dem::ParticleStore p;
    for (std::int64_t i = 0; i < n; ++i) {
        const Vec3 x(coordinateOf(i, clustered), 0.001 * (i % 7), 0.0);
        if (slabs.ownerOf(x, 0) == c.rank()) p.add(i, x, Vec3::Zero(), 1e-4, 2500.0, 0);
    }
    return p;
}

// Every id 0..n-1 owned by exactly one rank, each by the rank its slab names.
void expectEachIdOwnedOnce(const Communicator& c, const dem::GhostExchange& exchange, const dem::ParticleStore& p,
                           std::int64_t n) {
    std::vector<double> owners(static_cast<std::size_t>(n), 0.0);
    std::int64_t misplaced = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        owners[static_cast<std::size_t>(p.id[i])] += 1.0;
        misplaced += exchange.slabs().ownerOf(p.position[i], -1) != c.rank();
    }
    const std::vector<double> total = dem::sumOverRanksInRankOrder(c, owners);
    const auto wrong = std::count_if(total.begin(), total.end(), [](double k) { return k != 1.0; });
    EXPECT_EQ(wrong, 0) << "ids not owned exactly once";
    EXPECT_EQ(c.sum(misplaced), 0);
}

TEST(Rebalance, ASettledBedOnOneRankIsSpreadOverAll) {
    const std::int64_t n = 6000;
    for (int ranks = 1; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const SlabDecomposition equal = SlabDecomposition::uniform(ranks, 0, 0.0, 1.0);
            dem::GhostExchange exchange(c, equal);
            dem::ParticleStore p = ownedParticles(c, equal, n, true);
            const std::int64_t before = c.sum(static_cast<std::int64_t>(p.size()));
            ASSERT_EQ(before, n);
            const dem::GhostExchange::RebalanceReport report = exchange.rebalanceIfNeeded(p);
            const double mean = static_cast<double>(n) / ranks;
            EXPECT_EQ(report.meanOwned, mean);
            EXPECT_EQ(report.maxOwned, static_cast<std::int64_t>(c.max(static_cast<double>(p.size()))));
            EXPECT_EQ(report.imbalance, report.maxOwned / mean);
            EXPECT_EQ(report.recut, ranks > 1) << "one rank is always balanced";
            EXPECT_EQ(exchange.recutCount(), ranks > 1 ? 1u : 0u);
            EXPECT_EQ(report.cuts, exchange.slabs().interiorCuts());
            EXPECT_EQ(exchange.lastRebalance().cuts, report.cuts);
            expectSameOnAllRanks(c, report.cuts);
            exchange.migrate(p);
            const double owned = static_cast<double>(p.size());
            EXPECT_EQ(c.sum(static_cast<std::int64_t>(p.size())), n) << "particles conserved";
            EXPECT_LE(c.max(owned) / mean, allowedMaxOverMean(mean));
            EXPECT_GE(c.min(owned), mean * (1.0 - 2.0 * SlabDecomposition::balanceTolerance) - 2.0);
            expectEachIdOwnedOnce(c, exchange, p, n);
            // Balanced now: the next call measures and does nothing more.
            const auto again = exchange.rebalanceIfNeeded(p);
            EXPECT_FALSE(again.recut);
            EXPECT_LE(again.imbalance, allowedMaxOverMean(mean));
            EXPECT_EQ(exchange.recutCount(), ranks > 1 ? 1u : 0u);
            EXPECT_EQ(exchange.migrate(p), 0u);
        });
    }
}

// All particles on the last rank, the others empty: the empty ranks take part.
TEST(Rebalance, EmptyRanksReceiveTheirShare) {
    const std::int64_t n = 5000;
    for (int ranks = 2; ranks <= 4; ++ranks) {
        Communicator::runThreadGroup(ranks, [&](const Communicator& c) {
            const SlabDecomposition far = SlabDecomposition::uniform(ranks, 0, -3.0, -2.0);  // all x >= -2
            dem::GhostExchange exchange(c, far);
            dem::ParticleStore p = ownedParticles(c, far, n, false);
            EXPECT_EQ(p.size(), c.rank() == ranks - 1 ? static_cast<std::size_t>(n) : 0u);
            const auto report = exchange.rebalanceIfNeeded(p);
            EXPECT_TRUE(report.recut);
            EXPECT_EQ(report.maxOwned, n);
            EXPECT_DOUBLE_EQ(report.imbalance, static_cast<double>(ranks));
            exchange.migrate(p);
            const double mean = static_cast<double>(n) / ranks;
            EXPECT_LE(c.max(static_cast<double>(p.size())) / mean, allowedMaxOverMean(mean));
            expectEachIdOwnedOnce(c, exchange, p, n);
        });
    }
}

// 2 ranks holding 1080 and 920 particles: max/mean 1.08.
TEST(Rebalance, NoRecutBelowTheThreshold) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        const SlabDecomposition slabs(2, 0, {0.54});
        dem::ParticleStore p;
        const int n = 2000;
        for (int i = 0; i < n; ++i) {
            const Vec3 x((i + 0.5) / n, 0.0, 0.0);
            if (slabs.ownerOf(x, 0) == c.rank()) p.add(i, x, Vec3::Zero(), 1e-4, 2500.0, 0);
        }
        ASSERT_EQ(p.size(), c.rank() == 0 ? 1080u : 920u);
        dem::GhostExchange exchange(c, slabs);
        EXPECT_EQ(exchange.rebalanceThreshold(), dem::GhostExchange::defaultRebalanceThreshold);
        auto report = exchange.rebalanceIfNeeded(p);
        EXPECT_FALSE(report.recut);
        EXPECT_DOUBLE_EQ(report.imbalance, 1.08);
        EXPECT_EQ(report.maxOwned, 1080);
        EXPECT_EQ(exchange.slabs().interiorCuts(), std::vector<double>{0.54});
        EXPECT_EQ(exchange.recutCount(), 0u);
        // Disabled: nothing measured, nothing moved.
        for (double off : {0.0, std::numeric_limits<double>::infinity()}) {
            exchange.setRebalanceThreshold(off);
            report = exchange.rebalanceIfNeeded(p);
            EXPECT_FALSE(report.recut);
            EXPECT_EQ(report.maxOwned, 0);
        }
        // A lower threshold re-cuts at the median, 0.5.
        exchange.setRebalanceThreshold(1.05);
        report = exchange.rebalanceIfNeeded(p);
        EXPECT_TRUE(report.recut);
        ASSERT_EQ(report.cuts.size(), 1u);
        EXPECT_NEAR(report.cuts[0], 0.5, 6.0 / n);  // within the tolerance, 5 particles
        exchange.migrate(p);
        EXPECT_LE(std::abs(static_cast<double>(p.size()) - 1000.0), 1.0 + 1000 * 2 * SlabDecomposition::balanceTolerance);
        for (double bad : {0.5, -1.0, std::nan("")})
            EXPECT_THROW(exchange.setRebalanceThreshold(bad), dem::InputError);
        EXPECT_THROW(dem::GhostExchange(c, slabs, 0.9), dem::InputError);
    });
}

// Equal counts, unequal work: weights 4 on rank 0's particles, 1 on rank 1's.
TEST(Rebalance, WeightsDecideTheLoad) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        const SlabDecomposition slabs(2, 0, {0.5});
        dem::ParticleStore p;
        const int n = 4000;
        std::vector<double> w;
        for (int i = 0; i < n; ++i) {
            const Vec3 x((i + 0.5) / n, 0.0, 0.0);
            if (slabs.ownerOf(x, 0) != c.rank()) continue;
            p.add(i, x, Vec3::Zero(), 1e-4, 2500.0, 0);
            w.push_back(x.x() < 0.5 ? 4.0 : 1.0);
        }
        dem::GhostExchange exchange(c, slabs);
        EXPECT_FALSE(exchange.rebalanceIfNeeded(p).recut) << "equal counts";
        const auto report = exchange.rebalanceByWeight(p, w);
        EXPECT_TRUE(report.recut);
        EXPECT_DOUBLE_EQ(report.imbalance, 1.6);  // 4 / 2.5
        // Half the weight, 5000, lies below x = 5000 / (4 n) = 0.3125.
        EXPECT_NEAR(report.cuts[0], 0.3125, 2e-3);  // within the tolerance, 25 of 10000
        exchange.migrate(p);
        double load = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) load += p.position[i].x() < 0.5 ? 4.0 : 1.0;
        EXPECT_LE(c.max(load), 1.01 * 5000.0 + 3 * 4.0);
        EXPECT_THROW(exchange.rebalanceByWeight(p, {1.0}), dem::InputError);
    });
}

// --- The Simulation's re-cut: by particles or by work ---

// A block of 10 x 10 x 10 touching spheres (a simple cubic packing: up to 6
// listed neighbours each, work about 3.7) at x < 0.02 m and 1000 spheres far
// apart (no pairs, work 1) on a line out to x = 1 m, on 2 thread ranks that
// start with equal slabs.  The first list build balances counts (no pairs are
// known yet): one rank ends up with the block, the other with the line.  An
// insertion makes the lists build again: weighted by work the slabs are
// re-cut through the block, by particles they stay.
void blockAndLine(dem::LoadBalanceWeight weight, const Communicator& c, std::size_t& recuts,
                  dem::GhostExchange::RebalanceReport& lastRecut, double& ownedMaxOverMean, long stepsBetween = 0) {
    const double r = 5e-4;
    dem::SimulationSettings s;
    s.loadBalanceWeight = weight;
    dem::Simulation sim = sandWithoutGravity({}, s);
    sim.setDecomposition(std::make_shared<dem::GhostExchange>(c, SlabDecomposition::uniform(2, 0, 0.0, 1.0),
                                                              s.loadBalanceThreshold));
    std::vector<dem::InsertedParticle> spheres;
    const double spacing = 2.0 * r * (1.0 - 1e-4);
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
            for (int k = 0; k < 10; ++k)  // (staggered in x by up to 1e-5 m: a cut may split a layer)
                spheres.push_back({Vec3(r + i * spacing + (10 * j + k) * 1e-7, j * spacing, k * spacing), r});
    for (int i = 0; i < 1000; ++i) spheres.push_back({Vec3(0.03 + i * 9e-4, 0.05 + (i % 2) * 2e-3, 0.0), r});
    sim.insert(spheres, 0, Vec3::Zero());
    sim.step(1);
    EXPECT_EQ(sim.decomposition()->recutCount(), 1u);
    sim.step(stepsBetween);
    sim.insert({{Vec3(0.5, -0.05, 0.0), r}}, 0, Vec3::Zero());
    sim.step(1);
    recuts = sim.decomposition()->recutCount();
    lastRecut = sim.decomposition()->lastRecut();
    const double owned = static_cast<double>(sim.ownedCount());
    ownedMaxOverMean = c.max(owned) / (c.sum(owned) / c.size());
    EXPECT_EQ(c.sum(static_cast<std::int64_t>(sim.ownedCount())), 2001);
}

TEST(Rebalance, SimulationBalancesWorkWhenAsked) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        std::size_t recuts = 0;
        dem::GhostExchange::RebalanceReport report;
        double owned = 0.0;
        blockAndLine(dem::LoadBalanceWeight::Work, c, recuts, report, owned);
        EXPECT_EQ(recuts, 2u);
        EXPECT_TRUE(report.weighted);
        // Work before: the block's rank about 1000 x 3.7 against 1001 x 1.
        EXPECT_GT(report.imbalance, 1.4);
        EXPECT_LT(report.imbalance, 1.7);
        EXPECT_LE(report.loadImbalanceAfter, 1.03);
        ASSERT_EQ(report.cuts.size(), 1u);
        EXPECT_LT(report.cuts[0], 0.02) << "cut through the block";
        EXPECT_GT(owned, 1.2) << "equal work is not equal counts here";

        blockAndLine(dem::LoadBalanceWeight::Particles, c, recuts, report, owned);
        EXPECT_EQ(recuts, 1u) << "equal counts: no second re-cut";
        EXPECT_FALSE(report.weighted);
        EXPECT_LE(owned, 1.01);
    });
}

// By busy time: the first build (nothing timed yet) balances counts, as by
// work; after 1500 steps the block's rank has been busier than the line's
// (its pairs), and the insertion's build re-cuts through the block.
TEST(Rebalance, SimulationBalancesBusyTimeWhenAsked) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        std::size_t recuts = 0;
        dem::GhostExchange::RebalanceReport report;
        double owned = 0.0;
        blockAndLine(dem::LoadBalanceWeight::Time, c, recuts, report, owned, 1500);
        EXPECT_GE(recuts, 2u);
        EXPECT_TRUE(report.weighted);
        EXPECT_GT(report.imbalance, 1.1) << "busy time before: the block's rank the busier";
        ASSERT_EQ(report.cuts.size(), 1u);
        EXPECT_LT(report.cuts[0], 0.02) << "cut through the block";
        EXPECT_GT(owned, 1.1) << "equal busy time is not equal counts here";
    });
}

// Weighted on every rank, one of which owns nothing (the die filling's start): the
// empty rank takes the same collectives (an empty weight list there is no weights).
TEST(Rebalance, WeightsWithAnEmptyRank) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        const SlabDecomposition slabs(2, 0, {0.5});
        dem::ParticleStore p;
        std::vector<double> w;
        for (int i = 0; i < 1000; ++i) {
            const Vec3 x(0.6 + 0.3 * i / 1000.0, 0.0, 0.0);
            if (slabs.ownerOf(x, 0) != c.rank()) continue;
            p.add(i, x, Vec3::Zero(), 1e-4, 2500.0, 0);
            w.push_back(i < 500 ? 3.0 : 1.0);
        }
        ASSERT_EQ(p.size(), c.rank() == 1 ? 1000u : 0u);
        dem::GhostExchange exchange(c, slabs);
        const auto report = exchange.rebalanceByWeight(p, w);
        EXPECT_TRUE(report.weighted);
        EXPECT_TRUE(report.recut);
        EXPECT_DOUBLE_EQ(report.imbalance, 2.0);
        EXPECT_LE(report.loadImbalanceAfter, 1.02);
        EXPECT_NEAR(report.cuts[0], 0.6 + 0.3 * (1000.0 / 3.0) / 1000.0, 0.01);  // half of 2000 below it
    });
}

TEST(Rebalance, SlabsChangeOnlyWithoutGhosts) {
    Communicator::runThreadGroup(2, [](const Communicator& c) {
        const SlabDecomposition slabs(2, 0, {0.5});
        dem::GhostExchange exchange(c, slabs);
        dem::ParticleStore p;
        p.add(c.rank(), Vec3(c.rank() == 0 ? 0.49 : 0.51, 0, 0), Vec3::Zero(), 1e-4, 2500.0, 0);
        EXPECT_THROW(exchange.setSlabs(SlabDecomposition(3, 0, {0.1, 0.2})), dem::InputError);
        exchange.setSlabs(SlabDecomposition(2, 1, {0.0}));  // a new axis is allowed
        EXPECT_EQ(exchange.slabs().axis(), 1);
        exchange.setSlabs(slabs);
        exchange.appendGhosts(p, 0.1);
        ASSERT_EQ(exchange.ghostCount(), 1u);
        EXPECT_THROW(exchange.setSlabs(slabs), dem::RuntimeError);
        EXPECT_THROW(exchange.rebalanceIfNeeded(p), dem::RuntimeError);
    });
}

}  // namespace
