#include "demLib/liquid_bridges.hpp"

#include <algorithm>
#include <cmath>
#ifdef _OPENMP
#include <parallel/algorithm>
#endif

#include "demLib/capillary_force.hpp"
#include "demLib/compensated_sum.hpp"
#include "demLib/error.hpp"

namespace dem {

void BridgeCandidates::clear() {
    radiusA.clear();
    radiusB.clear();
    centreDistance.clear();
    wasBonded.clear();
}

void BridgeCandidates::reserve(std::size_t pairCount) {
    radiusA.reserve(pairCount);
    radiusB.reserve(pairCount);
    centreDistance.reserve(pairCount);
    wasBonded.reserve(pairCount);
}

void BridgeCandidates::add(double radiusOfA, double radiusOfB, double distanceOfCentres, bool bondedBefore) {
    radiusA.push_back(radiusOfA);
    radiusB.push_back(radiusOfB);
    centreDistance.push_back(distanceOfCentres);
    wasBonded.push_back(bondedBefore ? 1 : 0);
}

double waterVolumeFromContent(double waterContent, double drySolidMass, double waterDensity,
                              const std::string& source) {
    if (!(waterContent >= 0.0) || !std::isfinite(waterContent))
        throw InputError(source + ": keyword 'waterContent' expects a finite mass ratio >= 0 (water/dry solid), got " +
                         std::to_string(waterContent));
    if (!(drySolidMass >= 0.0) || !std::isfinite(drySolidMass))
        throw InputError(source + ": dry solid mass must be a finite number >= 0 [kg], got " +
                         std::to_string(drySolidMass));
    if (!(waterDensity > 0.0) || !std::isfinite(waterDensity))
        throw InputError(source + ": keyword 'waterDensity' expects a finite number > 0 [kg/m^3], got " +
                         std::to_string(waterDensity));
    return waterContent * drySolidMass / waterDensity;
}

double liquidCoordinationNumber(std::size_t bondCount, std::size_t particleCount) {
    if (particleCount == 0) return 0.0;
    return 2.0 * static_cast<double>(bondCount) / static_cast<double>(particleCount);
}

double bridgeVolumeWeight(double radiusOfA, double radiusOfB, double distanceOfCentres, BridgeVolumeWeight weight) {
    const double diameterA = 2.0 * radiusOfA;
    const double diameterB = 2.0 * radiusOfB;
    switch (weight) {
        case BridgeVolumeWeight::DiameterProductTimesDistance:
            return diameterA * diameterB * distanceOfCentres;
        case BridgeVolumeWeight::DiameterSumTimesDistance:
            return (diameterA + diameterB) * distanceOfCentres;
    }
    return 0.0;  // unreachable: every enumerator is handled above
}

double bridgeStabilityThreshold(double gap, double weight, double contactAngle) {
    const double scaledGap = std::max(gap, 0.0) / (1.0 + 0.5 * contactAngle);
    return scaledGap * scaledGap * scaledGap / weight;
}

double bridgeStabilityThreshold(double radiusOfA, double radiusOfB, double distanceOfCentres,
                                const LiquidBridgeSettings& settings) {
    return bridgeStabilityThreshold(distanceOfCentres - (radiusOfA + radiusOfB),
                                    bridgeVolumeWeight(radiusOfA, radiusOfB, distanceOfCentres, settings.weight),
                                    settings.contactAngle);
}

LiquidBridgeNetwork::LiquidBridgeNetwork(double totalLiquidVolume, const LiquidBridgeSettings& settings)
    : totalLiquid_(totalLiquidVolume), settings_(settings) {
    if (!(totalLiquidVolume >= 0.0) || !std::isfinite(totalLiquidVolume))
        throw InputError("liquid bridges: total liquid volume must be a finite number >= 0 [m^3], got " +
                         std::to_string(totalLiquidVolume));
    CapillaryParameters angleOnly;
    angleOnly.contactAngle = settings.contactAngle;
    validateCapillaryParameters(angleOnly, "liquid bridges");
    distribution_.freeLiquid = totalLiquid_;  // nothing bonded before the first update
}

void requireConsistentCandidates(const BridgeCandidates& candidates, const LiquidBridgeSettings& settings) {
    const std::size_t pairCount = candidates.size();
    if (candidates.radiusA.size() != pairCount || candidates.radiusB.size() != pairCount)
        throw RuntimeError("liquid bridges: radius arrays and centre distances differ in length");
    if (settings.formation == BridgeFormation::ContactThenPersist && candidates.wasBonded.size() != pairCount)
        throw RuntimeError("liquid bridges: ContactThenPersist needs one wasBonded flag per candidate pair");
}

bool bridgeCandidateRank(const BridgeCandidates& candidates, std::size_t k, const LiquidBridgeSettings& settings,
                         double& weight, double& threshold) {
    const double ra = candidates.radiusA[k];
    const double rb = candidates.radiusB[k];
    const double distance = candidates.centreDistance[k];
    if (!(ra > 0.0) || !(rb > 0.0) || !(distance > 0.0))
        throw RuntimeError("liquid bridges: candidate pair " + std::to_string(k) +
                           " has a non-positive radius or centre distance");
    // (ra + rb) first: the gap, and so λ*, is the same bits whichever particle
    // is A (a pair across a slab face is a candidate on both ranks, each with
    // its own particle first, and the cut of the ranking must treat both alike).
    const double gap = distance - (ra + rb);
    if (settings.formation == BridgeFormation::ContactThenPersist && gap > 0.0 && !candidates.wasBonded[k])
        return false;  // no contact, no bridge yet
    weight = bridgeVolumeWeight(ra, rb, distance, settings.weight);
    threshold = bridgeStabilityThreshold(gap, weight, settings.contactAngle);
    return true;
}

const BridgeDistribution& LiquidBridgeNetwork::update(const BridgeCandidates& candidates) {
    const std::size_t pairCount = candidates.size();
    requireConsistentCandidates(candidates, settings_);

    distribution_.volume.assign(pairCount, 0.0);
    distribution_.bonded.assign(pairCount, 0);
    distribution_.bondCount = 0;
    weight_.resize(pairCount);
    stabilityThreshold_.resize(pairCount);
    rankedPairs_.clear();
    separatedPairs_.clear();

    // λ*_k: the liquid per unit weight at which pair k's own bridge reaches its
    // debonding distance, gap_k = (1+θ/2)(λ w_k)^(1/3).  Overlapping pairs: 0.
    for (std::size_t k = 0; k < pairCount; ++k) {
        if (!bridgeCandidateRank(candidates, k, settings_, weight_[k], stabilityThreshold_[k])) continue;
        if (stabilityThreshold_[k] > 0.0)
            separatedPairs_.emplace_back(stabilityThreshold_[k], k);
        else
            rankedPairs_.push_back(k);
    }

    // Rank by stability (ties by index, so the result is deterministic).  The
    // touching pairs (λ* = 0) come first, already in index order; the separated
    // ones are sorted as (λ*, index) keys held together (no indirect compares).
    // The keys are unique (the index breaks ties), so every sort gives this one
    // order: libstdc++'s parallel sort on the OpenMP threads (the sort was 1-2 %
    // of the full die-filling run, serial, at each list build).
#ifdef _OPENMP
    __gnu_parallel::sort(separatedPairs_.begin(), separatedPairs_.end());
#else
    std::sort(separatedPairs_.begin(), separatedPairs_.end());
#endif
    for (const auto& key : separatedPairs_) rankedPairs_.push_back(key.second);

    // Accept whole groups of equal λ* while the group's own bridges stay stable
    // with the liquid shared over everything accepted so far: λ* · W ≤ V.
    // λ* rises and V/W falls along the ranking, so the stable prefixes are an
    // initial run and the first failure ends the scan.
    std::size_t acceptedCount = 0;
    CompensatedSum acceptedWeight;
    if (totalLiquid_ > 0.0) {
        std::size_t groupBegin = 0;
        while (groupBegin < rankedPairs_.size()) {
            const double groupThreshold = stabilityThreshold_[rankedPairs_[groupBegin]];
            std::size_t groupEnd = groupBegin;
            CompensatedSum trialWeight = acceptedWeight;
            while (groupEnd < rankedPairs_.size() && stabilityThreshold_[rankedPairs_[groupEnd]] == groupThreshold)
                trialWeight.add(weight_[rankedPairs_[groupEnd++]]);
            if (groupThreshold * trialWeight.value() > totalLiquid_) break;
            acceptedWeight = trialWeight;
            acceptedCount = groupEnd;
            groupBegin = groupEnd;
        }
    }

    CompensatedSum bondedLiquid;
    const double liquidPerWeight = acceptedCount > 0 ? totalLiquid_ / acceptedWeight.value() : 0.0;
    for (std::size_t rank = 0; rank < acceptedCount; ++rank) {
        const std::size_t k = rankedPairs_[rank];
        distribution_.volume[k] = liquidPerWeight * weight_[k];
        distribution_.bonded[k] = 1;
        bondedLiquid.add(distribution_.volume[k]);
    }
    distribution_.bondCount = acceptedCount;
    distribution_.bondedLiquid = bondedLiquid.value();
    distribution_.freeLiquid = acceptedCount > 0 ? 0.0 : totalLiquid_;
    distribution_.liquidPerWeight = liquidPerWeight;
    return distribution_;
}

}  // namespace dem
