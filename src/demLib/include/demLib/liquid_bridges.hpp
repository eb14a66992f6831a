#pragma once
// Distribution of the added water over pendular liquid bridges (paper §5,
// after Richefeu, El Youssoufi & Radjaï, Phys. Rev. E 73, 051304, 2006):
// the volume of a bridge is proportional to the particle diameters and the
// intercentre distance, and all bridges together hold exactly the added water.
//
// Rule (docs/capillary-model.md): V_k = V_water · w_k / Σ_{bonded} w, with the
// weight w_k = d_i d_j ℓ_k (default) or (d_i + d_j) ℓ_k.  A pair is bonded when
// its gap does not exceed the debonding distance (eq 5) of ITS OWN volume,
// which depends on the bonded set.  Writing λ = V_water / Σ w (liquid per unit
// weight), pair k is stable iff λ ≥ λ*_k = (max(gap_k, 0)/(1+θ/2))³ / w_k, so the
// pairs are ranked by λ*.  The bonded set is the largest stability-ranked prefix
// in which every bridge is stable; it is found exactly in one sorted pass (no
// open-ended iteration) and is independent of the order of the candidates.
//
// Liquid is conserved: Σ V_k equals the total to rounding (compensated sums),
// and when no pair can hold a bridge all of it sits in the free-liquid pool,
// which the next update distributes again.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dem {

// Which pairs may hold a bridge.
enum class BridgeFormation {
    WithinDebondingDistance,  // paper §5: every candidate pair closer than its δmax
    ContactThenPersist        // forms at contact (gap ≤ 0), lives until its gap exceeds δmax
};

// How the liquid is shared among bonded pairs (both ∝ diameters and ℓ).
enum class BridgeVolumeWeight {
    DiameterProductTimesDistance,  // w = d_i d_j ℓ_ij (a volume; default)
    DiameterSumTimesDistance       // w = (d_i + d_j) ℓ_ij
};

struct LiquidBridgeSettings {
    double contactAngle = 0.0;  // θ [rad], enters δmax (eq 5)
    BridgeFormation formation = BridgeFormation::WithinDebondingDistance;
    BridgeVolumeWeight weight = BridgeVolumeWeight::DiameterProductTimesDistance;
};

// Candidate pairs (e.g. the neighbour list), one entry per pair, structure of
// arrays.  wasBonded is the bridge state from the previous update; it is only
// read for ContactThenPersist and may be left empty otherwise.
struct BridgeCandidates {
    std::vector<double> radiusA;
    std::vector<double> radiusB;
    std::vector<double> centreDistance;
    std::vector<std::uint8_t> wasBonded;

    std::size_t size() const { return centreDistance.size(); }
    void clear();
    void reserve(std::size_t pairCount);
    void add(double radiusOfA, double radiusOfB, double distanceOfCentres, bool bondedBefore = false);
};

struct BridgeDistribution {
    std::vector<double> volume;         // per candidate [m³]; 0 when not bonded
    std::vector<std::uint8_t> bonded;   // per candidate
    std::size_t bondCount = 0;
    double bondedLiquid = 0.0;  // Σ volume, compensated sum
    double freeLiquid = 0.0;    // the pool: everything when no pair is bonded, else 0
    double liquidPerWeight = 0.0;  // λ = V / Σ_bonded w (0: nothing bonded); V_k = λ w_k
    double totalLiquid() const { return bondedLiquid + freeLiquid; }
};

// Volume of the added water: w · m_dry / ρ_water.  Throws InputError (naming
// `source` and the keyword) for a negative or non-finite water content or mass.
double waterVolumeFromContent(double waterContent, double drySolidMass, double waterDensity = 1000.0,
                              const std::string& source = "liquid bridges");

// z = 2 · (#bonds) / N.
double liquidCoordinationNumber(std::size_t bondCount, std::size_t particleCount);

// The sharing weight w_k of one pair.
double bridgeVolumeWeight(double radiusOfA, double radiusOfB, double distanceOfCentres,
                          BridgeVolumeWeight weight);

// λ*_k of a pair: the liquid per unit weight at which its bridge would just
// reach its debonding distance, (max(gap, 0)/(1+θ/2))³ / w_k; a bridge holds
// between the pair at liquid per weight λ iff λ ≥ λ*_k.
double bridgeStabilityThreshold(double radiusOfA, double radiusOfB, double distanceOfCentres,
                                const LiquidBridgeSettings& settings);
// The same from the pair's gap and its weight w_k, when the caller has them.
double bridgeStabilityThreshold(double gap, double weight, double contactAngle);

// The rule every distribution applies to a candidate (LiquidBridgeNetwork::update
// and distributeLiquidOverRanks): requireConsistentCandidates throws
// RuntimeError for arrays of different lengths (and no wasBonded flags under
// ContactThenPersist); bridgeCandidateRank throws RuntimeError for a
// non-positive radius or centre distance and returns whether pair k may hold a
// bridge (under ContactThenPersist: touching or bonded before), with its
// weight w_k and stability threshold λ*_k when it may.
void requireConsistentCandidates(const BridgeCandidates& candidates, const LiquidBridgeSettings& settings);
bool bridgeCandidateRank(const BridgeCandidates& candidates, std::size_t k, const LiquidBridgeSettings& settings,
                         double& weight, double& threshold);

// Holds the total liquid of the sample and re-distributes it each time the
// engine updates its contact list.  Scratch storage is kept between updates,
// so a steady-state update does not allocate.
class LiquidBridgeNetwork {
public:
    // Throws InputError for a negative/non-finite liquid volume or a contact
    // angle outside [0, π/2).
    LiquidBridgeNetwork(double totalLiquidVolume, const LiquidBridgeSettings& settings);

    // Assigns bridges and volumes to `candidates`.  Throws RuntimeError for a
    // candidate with a non-positive radius or centre distance, or a wasBonded
    // array of the wrong length in ContactThenPersist mode.
    const BridgeDistribution& update(const BridgeCandidates& candidates);

    const BridgeDistribution& distribution() const { return distribution_; }
    double totalLiquid() const { return totalLiquid_; }
    double freeLiquid() const { return distribution_.freeLiquid; }
    const LiquidBridgeSettings& settings() const { return settings_; }

private:
    double totalLiquid_;
    LiquidBridgeSettings settings_;
    BridgeDistribution distribution_;
    // scratch, reused between updates
    std::vector<std::size_t> rankedPairs_;
    std::vector<std::pair<double, std::size_t>> separatedPairs_;  // (λ*, index) of candidates with a gap
    std::vector<double> weight_;
    std::vector<double> stabilityThreshold_;
};

}  // namespace dem
