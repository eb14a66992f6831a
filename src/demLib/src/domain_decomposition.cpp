#include "demLib/domain_decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "demLib/error.hpp"

namespace dem {

SlabDecomposition::SlabDecomposition(int ranks, int axis, std::vector<double> interiorCuts)
    : ranks_(ranks), axis_(axis), cuts_(std::move(interiorCuts)) {
    const std::string where = "demLib domain decomposition: ";
    if (ranks_ < 1) throw InputError(where + "rank count " + std::to_string(ranks_) + "; expected at least 1");
    if (axis_ < 0 || axis_ > 2) throw InputError(where + "axis " + std::to_string(axis_) + "; expected 0 (x), 1 (y) or 2 (z)");
    if (static_cast<int>(cuts_.size()) != ranks_ - 1)
        throw InputError(where + std::to_string(cuts_.size()) + " cut positions for " + std::to_string(ranks_) +
                         " ranks; expected ranks - 1 = " + std::to_string(ranks_ - 1));
    for (std::size_t k = 0; k < cuts_.size(); ++k) {
        if (!std::isfinite(cuts_[k])) throw InputError(where + "cut " + std::to_string(k) + " is not finite");
        if (k > 0 && !(cuts_[k] > cuts_[k - 1]))
            throw InputError(where + "cut positions must increase strictly (cut " + std::to_string(k) + ")");
    }
}

SlabDecomposition SlabDecomposition::uniform(int ranks, int axis, double lower, double upper) {
    if (!(upper > lower) || !std::isfinite(lower) || !std::isfinite(upper))
        throw InputError("demLib domain decomposition: uniform slabs need finite lower < upper");
    std::vector<double> cuts;
    for (int r = 1; r < ranks; ++r) cuts.push_back(lower + (upper - lower) * r / ranks);
    return SlabDecomposition(ranks, axis, std::move(cuts));
}

int SlabDecomposition::ownerOf(const Vec3& x, int fallback) const {
    const double c = x[axis_];
    if (!std::isfinite(c)) return fallback;
    // Slab r is [cuts[r-1], cuts[r]): the count of cuts <= c.
    return static_cast<int>(std::upper_bound(cuts_.begin(), cuts_.end(), c) - cuts_.begin());
}

double SlabDecomposition::lowerOf(int rank) const {
    return rank == 0 ? -std::numeric_limits<double>::infinity() : cuts_[rank - 1];
}

double SlabDecomposition::upperOf(int rank) const {
    return rank == ranks_ - 1 ? std::numeric_limits<double>::infinity() : cuts_[rank];
}

double SlabDecomposition::distanceToSlab(int rank, const Vec3& x) const {
    const double c = x[axis_];
    return std::max({0.0, lowerOf(rank) - c, c - upperOf(rank)});
}

}  // namespace dem
