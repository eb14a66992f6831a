#pragma once
// Geometry of an MPI domain decomposition into slabs along one axis: rank r
// owns the particles whose centre coordinate c along the axis satisfies
// cuts[r-1] <= c < cuts[r] (the first and last slabs are open to -inf / +inf,
// so every finite position has exactly one owner).  Pure geometry, no
// communication: the exchanges live in ghost_exchange.
#include <string>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

class SlabDecomposition {
public:
    // interiorCuts: ranks - 1 ascending coordinates along `axis` (0 = x, 1 = y,
    // 2 = z).  Throws InputError on a wrong count, a wrong axis, unsorted or
    // non-finite cuts.
    SlabDecomposition(int ranks, int axis, std::vector<double> interiorCuts);
    // `ranks` equal slabs over [lower, upper] along `axis`.
    static SlabDecomposition uniform(int ranks, int axis, double lower, double upper);

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
