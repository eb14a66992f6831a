#pragma once
// Geometry of an MPI domain decomposition into slabs along one axis: rank r
// owns the particles whose centre coordinate c along the axis satisfies
// cuts[r-1] <= c < cuts[r] (the first and last slabs are open to -inf / +inf,
// so every finite position has exactly one owner).  Geometry; the only
// collectives here are the ones that choose cuts from the particles
// (balanced, axisOfLargestExtent).  The exchanges live in ghost_exchange.
#include <cstddef>
#include <string>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

class Communicator;

// Entry-wise sum of `values` over all ranks (same length on every rank), the
// ranks' values added in rank order, so every rank gets the same bits (an
// MPI_Allreduce may combine in a different order on different ranks, and cut
// choices must not differ by a rounding).  A reduce-scatter then an
// all-gather over Communicator::exchange: each rank sends and receives about
// 2 values.size() doubles.  Collective.
std::vector<double> sumOverRanksInRankOrder(const Communicator& communicator, const std::vector<double>& values);

class SlabDecomposition {
public:
    // interiorCuts: ranks - 1 ascending coordinates along `axis` (0 = x, 1 = y,
    // 2 = z).  Throws InputError on a wrong count, a wrong axis, unsorted or
    // non-finite cuts.
    SlabDecomposition(int ranks, int axis, std::vector<double> interiorCuts);
    // `ranks` equal slabs over [lower, upper] along `axis`.
    static SlabDecomposition uniform(int ranks, int axis, double lower, double upper);

    // Cuts along `axis` that give every rank of `communicator` about the same
    // weight of particles, from each rank's owned particle centre coordinates
    // along the axis (`weights`: one per coordinate, >= 0 and finite; empty:
    // 1 each; non-finite coordinates are ignored).  No positions travel: the
    // cuts are found by histogram refinement, each round summing per-rank
    // counts below (ranks - 1) x (balanceBins - 1) trial positions over the
    // ranks (sumOverRanksInRankOrder), so memory and traffic per rank do not
    // grow with the particle count.  Every rank computes the same cuts, bit
    // for bit.  Collective.
    //
    // Bound: with W the total weight, P the ranks and w_max the largest single
    // weight, every cut k leaves within max(balanceTolerance W/P, w_max/2) of
    // k W/P below it, unless more than that weight sits at one coordinate
    // (then within half of that weight; coordinates closer than 1e-12 times
    // the largest |coordinate| count as one); so a slab holds at most
    // W/P + 2 max(balanceTolerance W/P, w_max/2) + w_max, i.e. for unit
    // weights at distinct coordinates max/mean owned <= 1.01 + 2/mean.
    // Cuts increase strictly: coinciding ones (all particles at one
    // coordinate, more weight at a point than W/P) are moved up by one ulp
    // each, leaving empty slabs.  Fewer particles than ranks: at most one per
    // slab.  No particle (or zero total weight) on any rank: equal slabs over
    // the particles' extent, or over [-1, 1] when there is no extent.
    static SlabDecomposition balanced(const Communicator& communicator, int axis,
                                      const std::vector<double>& ownedCoordinates,
                                      const std::vector<double>& weights = {});
    // Allowed error of each balanced cut, as a fraction of W/P.
    static constexpr double balanceTolerance = 0.005;
    // Trial positions per cut and refinement round (a power of two: exact j/B).
    static constexpr int balanceBins = 64;

    // The axis (0, 1, 2) along which the first `ownedCount` positions of all
    // ranks have the largest extent (the lowest such axis on a tie; 0 without
    // particles): the axis to cut slabs across.  Six min/max reductions.
    // Collective.
    static int axisOfLargestExtent(const Communicator& communicator, const std::vector<Vec3>& positions,
                                   std::size_t ownedCount);

    int ranks() const { return ranks_; }
    int axis() const { return axis_; }
    const std::vector<double>& interiorCuts() const { return cuts_; }

    // The rank owning position x (a non-finite coordinate: `fallback`).
    int ownerOf(const Vec3& x, int fallback) const;
    // Distance along the axis from x to the slab of `rank` (0 inside it).
    double distanceToSlab(int rank, const Vec3& x) const;
    // Slab bounds of `rank` along the axis (+-inf for the outer faces).
    double lowerOf(int rank) const;
    double upperOf(int rank) const;

private:
    int ranks_;
    int axis_;
    std::vector<double> cuts_;
};

}  // namespace dem
