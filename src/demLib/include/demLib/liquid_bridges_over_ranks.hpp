#pragma once
// The liquid bridge distribution of liquid_bridges.hpp over a domain
// decomposition: each rank holds the candidate pairs of its own particles
// (a pair across a slab face is listed on both of its ranks), and the water of
// the whole run is shared over the candidates of all ranks by the same rule as
// LiquidBridgeNetwork::update: the bonded set is the largest prefix, ranked by
// the stability threshold λ*, whose bridges all hold at λ = V / Σ_bonded w.
//
// Nothing is gathered: the threshold t* that ends the bonded prefix (the
// largest λ* with λ* · W(λ*) <= V, W(t) the weight of all pairs with λ* <= t)
// is found by a search over the ranks' sorted thresholds.  Each round every
// rank contributes a few quantiles of its thresholds still in the open range
// and the weights below the proposed pivots (messages sized by the rank
// count, never by the particle count); a round narrows the range by about the
// number of pivots, so a list build needs a handful of rounds.
#include <cstdint>
#include <vector>

#include "demLib/liquid_bridges.hpp"

namespace dem {

class Communicator;

// candidates: this rank's pairs; counted[k] = 1 for exactly one of the ranks
// listing pair k (e.g. the rank owning the particle of the smaller global id).
// Collective.  Returns the distribution of this rank's candidates (volumes
// for counted and uncounted ones alike); bondCount and bondedLiquid sum the
// counted ones of this rank only, freeLiquid and liquidPerWeight are global.
BridgeDistribution distributeLiquidOverRanks(const BridgeCandidates& candidates,
                                             const std::vector<std::uint8_t>& counted, double totalLiquid,
                                             const LiquidBridgeSettings& settings, const Communicator& communicator);

// Every rank's values, in rank order (an allgather over Communicator::exchange).
std::vector<std::vector<double>> gatherFromAllRanks(const Communicator& communicator,
                                                    const std::vector<double>& mine);

}  // namespace dem
