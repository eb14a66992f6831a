// The liquid bridge distribution over ranks (liquid_bridges_over_ranks.hpp)
// against the serial LiquidBridgeNetwork::update on the same candidates,
// split over 1-4 thread ranks with pairs listed on two ranks (counted on one):
// the same bonded set, the same liquid per weight to rounding, the water
// conserved, for every formation rule, with ties of λ* and without liquid.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <random>
#include <vector>

#include "demLib/communicator.hpp"
#include "demLib/liquid_bridges.hpp"
#include "demLib/liquid_bridges_over_ranks.hpp"

namespace {

struct Pairs {
    dem::BridgeCandidates all;
    std::vector<int> home;       // the rank that counts pair k
    std::vector<int> alsoListed;  // a second rank that lists it (-1: none)
};

// n pairs of radius 0.5-1 mm at gaps from overlap to 0.6 mm; every fifth
// pair duplicated exactly (a tie of λ*); ranks picked at random.
Pairs randomPairs(std::size_t n, int ranks, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> radius(0.5e-3, 1e-3), gap(-0.05e-3, 0.6e-3), u(0.0, 1.0);
    Pairs p;
    for (std::size_t k = 0; k < n; ++k) {
        double a = radius(rng), b = radius(rng), g = gap(rng);
        if (k % 5 == 4) {  // the previous pair again
            a = p.all.radiusA.back();
            b = p.all.radiusB.back();
            g = p.all.centreDistance.back() - a - b;
        }
        p.all.add(a, b, a + b + g, u(rng) < 0.5);
        p.home.push_back(static_cast<int>(rng() % ranks));
        p.alsoListed.push_back(ranks > 1 && u(rng) < 0.3 ? static_cast<int>((p.home.back() + 1) % ranks) : -1);
    }
    return p;
}

void expectSameAsSerial(const Pairs& p, int ranks, double water, const dem::LiquidBridgeSettings& settings) {
    dem::LiquidBridgeNetwork serialNetwork(water, settings);
    const dem::BridgeDistribution serial = serialNetwork.update(p.all);
    std::mutex lock;
    std::vector<double> volume(p.all.size(), -1.0);
    double bonded = 0.0;
    std::size_t bondCount = 0;
    std::vector<double> lambdas;
    dem::Communicator::runThreadGroup(ranks, [&](const dem::Communicator& comm) {
        dem::BridgeCandidates mine;
        std::vector<std::uint8_t> counted;
        std::vector<std::size_t> source;
        for (std::size_t k = 0; k < p.all.size(); ++k) {
            const bool home = p.home[k] == comm.rank();
            if (!home && p.alsoListed[k] != comm.rank()) continue;
            mine.add(p.all.radiusA[k], p.all.radiusB[k], p.all.centreDistance[k], p.all.wasBonded[k] != 0);
            counted.push_back(home ? 1 : 0);
            source.push_back(k);
        }
        const dem::BridgeDistribution d = dem::distributeLiquidOverRanks(mine, counted, water, settings, comm);
        std::lock_guard<std::mutex> guard(lock);
        for (std::size_t m = 0; m < source.size(); ++m) {
            // A pair listed on two ranks gets the same volume on both.
            if (volume[source[m]] >= 0.0) {
                EXPECT_EQ(volume[source[m]], d.volume[m]);
            }
            volume[source[m]] = d.volume[m];
        }
        bonded += d.bondedLiquid;
        bondCount += d.bondCount;
        lambdas.push_back(d.liquidPerWeight);
        EXPECT_EQ(d.freeLiquid, serial.freeLiquid);
    });
    for (double l : lambdas) EXPECT_EQ(l, lambdas.front()) << "every rank the same λ";
    EXPECT_NEAR(lambdas.front(), serial.liquidPerWeight, 1e-14 * serial.liquidPerWeight);
    EXPECT_EQ(bondCount, serial.bondCount);
    std::size_t differentSet = 0;
    double largestError = 0.0;
    for (std::size_t k = 0; k < p.all.size(); ++k) {
        if ((volume[k] > 0.0) != (serial.volume[k] > 0.0)) ++differentSet;
        largestError = std::max(largestError, std::abs(volume[k] - serial.volume[k]));
    }
    EXPECT_EQ(differentSet, 0u) << "pairs bonded in one distribution only";
    const double largest = *std::max_element(serial.volume.begin(), serial.volume.end());
    EXPECT_LE(largestError, 1e-14 * largest);
    EXPECT_NEAR(bonded + serial.freeLiquid, water, 1e-13 * water) << "the water, summed over ranks";
}

TEST(LiquidBridgesOverRanks, MatchTheSerialDistribution) {
    dem::LiquidBridgeSettings settings;
    for (int ranks = 1; ranks <= 4; ++ranks)
        for (double water : {2e-10, 3e-9, 1e-7}) {  // few, many, all pairs bonded
            SCOPED_TRACE(std::to_string(ranks) + " ranks, water " + std::to_string(water));
            const Pairs p = randomPairs(3000, ranks, 7u + ranks);
            expectSameAsSerial(p, ranks, water, settings);
        }
}

TEST(LiquidBridgesOverRanks, OtherRulesAndNoLiquid) {
    dem::LiquidBridgeSettings persist;
    persist.formation = dem::BridgeFormation::ContactThenPersist;
    persist.weight = dem::BridgeVolumeWeight::DiameterSumTimesDistance;
    persist.contactAngle = 0.3;
    for (int ranks : {2, 3}) {
        const Pairs p = randomPairs(2000, ranks, 99u);
        expectSameAsSerial(p, ranks, 3e-9, persist);
        expectSameAsSerial(p, ranks, 0.0, dem::LiquidBridgeSettings{});
    }
}

// A rank with no candidates at all still takes part in every round.
TEST(LiquidBridgesOverRanks, RanksWithoutPairs) {
    Pairs p = randomPairs(500, 3, 5u);
    for (std::size_t k = 0; k < p.home.size(); ++k) {
        if (p.home[k] == 2) p.home[k] = 0;
        if (p.alsoListed[k] == 2) p.alsoListed[k] = -1;
    }
    expectSameAsSerial(p, 3, 1e-9, dem::LiquidBridgeSettings{});
}

}  // namespace
