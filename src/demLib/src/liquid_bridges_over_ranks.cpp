#include "demLib/liquid_bridges_over_ranks.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#ifdef _OPENMP
#include <parallel/algorithm>
#endif

#include "demLib/communicator.hpp"
#include "demLib/compensated_sum.hpp"
#include "demLib/error.hpp"

namespace dem {

namespace {

// Quantiles each rank proposes per round, and the most pivots tested at once.
constexpr std::size_t proposalsPerRank = 8;
constexpr std::size_t maxPivots = 32;

}  // namespace

std::vector<std::vector<double>> gatherFromAllRanks(const Communicator& communicator,
                                                    const std::vector<double>& mine) {
    std::vector<char> bytes(mine.size() * sizeof(double));
    if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
    const std::vector<std::vector<char>> received =
        communicator.exchange(std::vector<std::vector<char>>(communicator.size(), bytes));
    std::vector<std::vector<double>> all(received.size());
    for (std::size_t r = 0; r < received.size(); ++r) {
        if (received[r].size() % sizeof(double) != 0)
            throw RuntimeError("demLib: rank " + std::to_string(r) + " sent a message of the wrong size");
        all[r].resize(received[r].size() / sizeof(double));
        if (!all[r].empty()) std::memcpy(all[r].data(), received[r].data(), received[r].size());
    }
    return all;
}

BridgeDistribution distributeLiquidOverRanks(const BridgeCandidates& candidates,
                                             const std::vector<std::uint8_t>& counted, double totalLiquid,
                                             const LiquidBridgeSettings& settings, const Communicator& communicator) {
    const std::size_t pairCount = candidates.size();
    requireConsistentCandidates(candidates, settings);
    if (counted.size() != pairCount)
        throw RuntimeError("liquid bridges over ranks: candidate arrays and counted flags differ in length");

    BridgeDistribution d;
    d.volume.assign(pairCount, 0.0);
    d.bonded.assign(pairCount, 0);
    std::vector<double> weight(pairCount, 0.0), threshold(pairCount, 0.0);
    std::vector<std::uint8_t> eligible(pairCount, 0);
    std::vector<std::pair<double, std::size_t>> ranked;  // (λ*, index) of the counted eligible pairs
    ranked.reserve(pairCount);
    for (std::size_t k = 0; k < pairCount; ++k) {
        eligible[k] = bridgeCandidateRank(candidates, k, settings, weight[k], threshold[k]);
        if (eligible[k] && counted[k]) ranked.emplace_back(threshold[k], k);
    }
#ifdef _OPENMP
    __gnu_parallel::sort(ranked.begin(), ranked.end());
#else
    std::sort(ranked.begin(), ranked.end());
#endif
    // prefix[m]: the weight of the first m ranked pairs.
    std::vector<CompensatedSum> prefix(ranked.size() + 1);
    for (std::size_t m = 0; m < ranked.size(); ++m) {
        prefix[m + 1] = prefix[m];
        prefix[m + 1].add(weight[ranked[m].second]);
    }
    auto firstAbove = [&](double t) {  // first ranked pair with λ* > t
        return static_cast<std::size_t>(
            std::upper_bound(ranked.begin(), ranked.end(), t,
                             [](double value, const std::pair<double, std::size_t>& e) { return value < e.first; }) -
            ranked.begin());
    };
    auto firstAtOrAbove = [&](double t) {  // first ranked pair with λ* >= t
        return static_cast<std::size_t>(
            std::lower_bound(ranked.begin(), ranked.end(), t,
                             [](const std::pair<double, std::size_t>& e, double value) { return e.first < value; }) -
            ranked.begin());
    };

    // Search for t*: lo is the largest threshold known to hold (λ* W(λ*) <= V),
    // hi the smallest known not to; the thresholds strictly between are open.
    constexpr double infinity = std::numeric_limits<double>::infinity();
    double lo = -infinity, hi = infinity;
    double acceptedWeight = 0.0;
    while (totalLiquid > 0.0) {
        const std::size_t begin = firstAbove(lo), end = std::max(begin, firstAtOrAbove(hi));
        const std::size_t open = end - begin;
        std::vector<double> proposal{static_cast<double>(open)};
        const std::size_t q = std::min(open, proposalsPerRank);
        for (std::size_t j = 0; j < q; ++j) proposal.push_back(ranked[begin + (2 * j + 1) * open / (2 * q)].first);
        const std::vector<std::vector<double>> proposals = gatherFromAllRanks(communicator, proposal);
        double openOverRanks = 0.0;
        std::vector<double> pivots;
        for (const std::vector<double>& p : proposals) {
            if (p.empty()) throw RuntimeError("liquid bridges over ranks: empty proposal");
            openOverRanks += p[0];
            pivots.insert(pivots.end(), p.begin() + 1, p.end());
        }
        if (openOverRanks == 0.0) break;
        std::sort(pivots.begin(), pivots.end());
        pivots.erase(std::unique(pivots.begin(), pivots.end()), pivots.end());
        if (pivots.size() > maxPivots) {
            std::vector<double> kept;
            for (std::size_t j = 0; j < maxPivots; ++j) kept.push_back(pivots[(2 * j + 1) * pivots.size() / (2 * maxPivots)]);
            kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
            pivots.swap(kept);
        }
        std::vector<double> below;  // this rank's W(pivot): sum and compensation per pivot
        for (double t : pivots) {
            const CompensatedSum& w = prefix[firstAbove(t)];
            below.push_back(w.sum());
            below.push_back(w.compensation());
        }
        const std::vector<std::vector<double>> belowOverRanks = gatherFromAllRanks(communicator, below);
        for (std::size_t j = 0; j < pivots.size(); ++j) {
            CompensatedSum w;  // in rank order: the same bits on every rank
            for (const std::vector<double>& b : belowOverRanks) {
                w.add(b[2 * j]);
                w.add(b[2 * j + 1]);
            }
            // λ* W(λ*) rises with λ*: the pivots that hold come first.
            if (pivots[j] * w.value() <= totalLiquid) {
                lo = pivots[j];
                acceptedWeight = w.value();
            } else {
                hi = std::min(hi, pivots[j]);
                break;
            }
        }
    }

    CompensatedSum bonded;
    const bool anyBonded = lo > -infinity;
    const double liquidPerWeight = anyBonded ? totalLiquid / acceptedWeight : 0.0;
    if (anyBonded)
        for (std::size_t k = 0; k < pairCount; ++k) {
            if (!eligible[k] || threshold[k] > lo) continue;
            d.volume[k] = liquidPerWeight * weight[k];
            d.bonded[k] = 1;
            if (!counted[k]) continue;
            ++d.bondCount;
            bonded.add(d.volume[k]);
        }
    d.bondedLiquid = bonded.value();
    d.freeLiquid = anyBonded ? 0.0 : totalLiquid;
    d.liquidPerWeight = liquidPerWeight;
    return d;
}

}  // namespace dem
