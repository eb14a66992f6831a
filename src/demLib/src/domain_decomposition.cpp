#include "demLib/domain_decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <utility>

#include "demLib/communicator.hpp"
#include "demLib/error.hpp"

namespace dem {

namespace {

std::vector<char> bytesOf(const double* values, std::size_t count) {
    std::vector<char> bytes(count * sizeof(double));
    if (count > 0) std::memcpy(bytes.data(), values, bytes.size());
    return bytes;
}

void checkSize(const std::vector<char>& bytes, std::size_t count, int fromRank) {
    if (bytes.size() != count * sizeof(double))
        throw RuntimeError("demLib domain decomposition: rank " + std::to_string(fromRank) + " sent " +
                           std::to_string(bytes.size()) + " bytes to a sum over ranks; expected " +
                           std::to_string(count * sizeof(double)) +
                           " (every rank must sum vectors of the same length)");
}

// Interior cuts for `ranks` slabs that all start at x: x, x + 1 ulp, ...
std::vector<double> cutsAtOnePoint(int ranks, double x) {
    std::vector<double> cuts;
    for (int k = 1; k < ranks; ++k) {
        cuts.push_back(x);
        x = std::nextafter(x, std::numeric_limits<double>::infinity());
    }
    return cuts;
}

}  // namespace

std::vector<double> sumOverRanksInRankOrder(const Communicator& communicator, const std::vector<double>& values) {
    const int ranks = communicator.size();
    if (ranks == 1) return values;
    const int me = communicator.rank();
    const std::size_t count = values.size();
    // Rank r adds up entries [sliceBegin(r), sliceBegin(r + 1)) of all ranks.
    auto sliceBegin = [&](int r) { return count * static_cast<std::size_t>(r) / static_cast<std::size_t>(ranks); };
    std::vector<std::vector<char>> slices(ranks);
    for (int r = 0; r < ranks; ++r) slices[r] = bytesOf(values.data() + sliceBegin(r), sliceBegin(r + 1) - sliceBegin(r));
    const std::vector<std::vector<char>> parts = communicator.exchange(slices);
    const std::size_t myCount = sliceBegin(me + 1) - sliceBegin(me);
    std::vector<double> mySums(myCount, 0.0);
    for (int r = 0; r < ranks; ++r) {  // rank order: the same additions whichever rank does them
        checkSize(parts[r], myCount, r);
        for (std::size_t i = 0; i < myCount; ++i) {
            double v;
            std::memcpy(&v, parts[r].data() + i * sizeof(double), sizeof(double));
            mySums[i] += v;
        }
    }
    const std::vector<std::vector<char>> sums =
        communicator.exchange(std::vector<std::vector<char>>(ranks, bytesOf(mySums.data(), myCount)));
    std::vector<double> result(count);
    for (int r = 0; r < ranks; ++r) {
        const std::size_t begin = sliceBegin(r), n = sliceBegin(r + 1) - begin;
        checkSize(sums[r], n, r);
        if (n > 0) std::memcpy(result.data() + begin, sums[r].data(), n * sizeof(double));
    }
    return result;
}

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

SlabDecomposition SlabDecomposition::balanced(const Communicator& communicator, int axis,
                                              const std::vector<double>& ownedCoordinates,
                                              const std::vector<double>& weights) {
    const std::string where = "demLib domain decomposition, balanced cuts: ";
    const int ranks = communicator.size();
    if (axis < 0 || axis > 2) throw InputError(where + "axis " + std::to_string(axis) + "; expected 0 (x), 1 (y) or 2 (z)");
    if (!weights.empty() && weights.size() != ownedCoordinates.size())
        throw InputError(where + std::to_string(weights.size()) + " weights for " +
                         std::to_string(ownedCoordinates.size()) + " coordinates; expected one each (or none)");
    if (ranks == 1) return SlabDecomposition(1, axis, {});

    // This rank's finite coordinates, sorted, with the running weight below
    // each: the weight below any trial position is then one binary search.
    std::vector<std::pair<double, double>> local;
    local.reserve(ownedCoordinates.size());
    double localLargestWeight = 0.0;
    for (std::size_t i = 0; i < ownedCoordinates.size(); ++i) {
        const double w = weights.empty() ? 1.0 : weights[i];
        if (!std::isfinite(w) || w < 0.0)
            throw InputError(where + "weight " + std::to_string(i) + " is " + std::to_string(w) +
                             "; expected a finite value >= 0");
        if (!std::isfinite(ownedCoordinates[i])) continue;  // ownerOf keeps such a particle where it is
        local.emplace_back(ownedCoordinates[i], w);
        localLargestWeight = std::max(localLargestWeight, w);
    }
    std::sort(local.begin(), local.end());
    std::vector<double> sortedCoordinates(local.size());
    std::vector<double> weightBelow(local.size() + 1, 0.0);
    for (std::size_t i = 0; i < local.size(); ++i) {
        sortedCoordinates[i] = local[i].first;
        weightBelow[i + 1] = weightBelow[i] + local[i].second;
    }
    // Weight of this rank's particles with coordinate < x (the owner rule puts
    // a particle at a cut into the slab above it).
    auto localWeightBelow = [&](double x) {
        return weightBelow[std::lower_bound(sortedCoordinates.begin(), sortedCoordinates.end(), x) -
                           sortedCoordinates.begin()];
    };

    const double inf = std::numeric_limits<double>::infinity();
    const double lowest = communicator.min(local.empty() ? inf : sortedCoordinates.front());
    const double highest = communicator.max(local.empty() ? -inf : sortedCoordinates.back());
    const double largestWeight = communicator.max(localLargestWeight);
    const double total = sumOverRanksInRankOrder(communicator, {weightBelow.back()})[0];
    if (!(lowest <= highest)) return uniform(ranks, axis, -1.0, 1.0);  // no particle anywhere
    if (!(total > 0.0))
        return lowest < highest ? uniform(ranks, axis, lowest, highest)
                                : SlabDecomposition(ranks, axis, cutsAtOnePoint(ranks, lowest));

    // Refinement: cut k is searched in a bracket [lower, upper) with
    // W(< lower) < target_k <= W(< upper), W(< x) the global weight below x.
    // Each round cuts every open bracket into balanceBins bins, sums the
    // weight below the bin edges over the ranks and keeps the bin holding the
    // target.  A cut is done when a bracket end is within `tolerance` of its
    // target, or when the bracket holds a single coordinate value.
    struct Bracket {
        double lower, upper, weightBelowLower, weightBelowUpper, target;
        bool done = false;
        double cut = 0.0;
    };
    const double tolerance = std::max(balanceTolerance * total / ranks, 0.5 * largestWeight);
    std::vector<Bracket> brackets;
    for (int k = 1; k < ranks; ++k)
        brackets.push_back({lowest, std::nextafter(highest, inf), 0.0, total, total * k / ranks});
    // Coordinates closer than this count as one: it bounds the rounds (to
    // ~7) where doubles are dense, near 0 (a bracket could otherwise narrow
    // towards a point mass at 0 down to the denormals, ~180 rounds).
    const double resolution = 1e-12 * std::max(std::abs(lowest), std::abs(highest));
    auto settle = [&](Bracket& b, bool force) {
        const double errorLower = b.target - b.weightBelowLower, errorUpper = b.weightBelowUpper - b.target;
        const bool singleValue = !(std::nextafter(b.lower, b.upper) < b.upper) || b.upper - b.lower <= resolution;
        if (force || singleValue || std::min(errorLower, errorUpper) <= tolerance) {
            b.done = true;
            b.cut = errorLower <= errorUpper ? b.lower : b.upper;
        }
    };
    for (Bracket& b : brackets) settle(b, false);
    const int maxRounds = 100;  // a guard only: the resolution ends the refinement after ~7
    for (int round = 0; round < maxRounds; ++round) {
        std::vector<std::size_t> open;
        for (std::size_t k = 0; k < brackets.size(); ++k)
            if (!brackets[k].done) open.push_back(k);
        if (open.empty()) break;  // the same on every rank: all decisions come from summed values  // the same on every rank: all decisions come from summed values
        const int B = balanceBins;
        std::vector<double> edges(open.size() * (B - 1)), below(edges.size());
        for (std::size_t o = 0; o < open.size(); ++o) {
            const Bracket& b = brackets[open[o]];
            for (int j = 1; j < B; ++j) {
                const double edge = std::clamp(b.lower + (b.upper - b.lower) * (static_cast<double>(j) / B),
                                               b.lower, b.upper);
                edges[o * (B - 1) + j - 1] = edge;
                below[o * (B - 1) + j - 1] = localWeightBelow(edge);
            }
        }
        const std::vector<double> globalBelow = sumOverRanksInRankOrder(communicator, below);
        for (std::size_t o = 0; o < open.size(); ++o) {
            Bracket& b = brackets[open[o]];
            // First edge with W(< edge) >= target (the upper end if none);
            // the bin before it starts below the target.
            int j = 1;
            while (j < B && globalBelow[o * (B - 1) + j - 1] < b.target) ++j;
            if (j > 1) {
                b.lower = edges[o * (B - 1) + j - 2];
                b.weightBelowLower = globalBelow[o * (B - 1) + j - 2];
            }
            if (j < B) {
                b.upper = edges[o * (B - 1) + j - 1];
                b.weightBelowUpper = globalBelow[o * (B - 1) + j - 1];
            }
            settle(b, round + 1 == maxRounds);
        }
    }
    // Coinciding cuts (weight concentrated at one coordinate) move up by one
    // ulp each: strictly increasing, the slabs between them empty.
    std::vector<double> cuts;
    for (const Bracket& b : brackets) {
        double cut = b.cut;
        if (!cuts.empty() && !(cut > cuts.back())) cut = std::nextafter(cuts.back(), inf);
        cuts.push_back(cut);
    }
    return SlabDecomposition(ranks, axis, std::move(cuts));
}

int SlabDecomposition::axisOfLargestExtent(const Communicator& communicator, const std::vector<Vec3>& positions,
                                           std::size_t ownedCount) {
    if (ownedCount > positions.size())
        throw InputError("demLib domain decomposition: " + std::to_string(ownedCount) + " owned particles of " +
                         std::to_string(positions.size()) + " positions");
    const double inf = std::numeric_limits<double>::infinity();
    int best = 0;
    double bestExtent = -inf;
    for (int axis = 0; axis < 3; ++axis) {
        double low = inf, high = -inf;
        for (std::size_t i = 0; i < ownedCount; ++i) {
            const double c = positions[i][axis];
            if (!std::isfinite(c)) continue;
            low = std::min(low, c);
            high = std::max(high, c);
        }
        low = communicator.min(low);
        high = communicator.max(high);
        const double extent = high >= low ? high - low : -inf;
        if (extent > bestExtent) {
            best = axis;
            bestExtent = extent;
        }
    }
    return best;
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
