#include "demLib/particle_reordering.hpp"

#include <algorithm>
#include <cmath>

namespace dem {

std::vector<int> spatialOrder(const std::vector<Vec3>& positions, double cellSize) {
    const int n = static_cast<int>(positions.size());
    std::vector<int> order(n);
    if (n == 0) return order;
    Vec3 lo = positions[0], hi = positions[0];
    for (const Vec3& x : positions) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    }
    // A few escaping particles must not make the grid huge.
    double cell = cellSize;
    const double maxCells = std::max(64.0, 4.0 * n);
    auto cells = [&](double c) {
        return (std::floor((hi.x() - lo.x()) / c) + 1) * (std::floor((hi.y() - lo.y()) / c) + 1) *
               (std::floor((hi.z() - lo.z()) / c) + 1);
    };
    while (cells(cell) > maxCells) cell *= 1.26;
    const long nx = static_cast<long>((hi.x() - lo.x()) / cell) + 1;
    const long ny = static_cast<long>((hi.y() - lo.y()) / cell) + 1;
    const long nz = static_cast<long>((hi.z() - lo.z()) / cell) + 1;
    std::vector<long> key(n);
    std::vector<int> start(static_cast<std::size_t>(nx * ny * nz) + 1, 0);
    for (int i = 0; i < n; ++i) {
        const Vec3 r = (positions[i] - lo) / cell;
        const long cx = std::min(nx - 1, static_cast<long>(r.x()));
        const long cy = std::min(ny - 1, static_cast<long>(r.y()));
        const long cz = std::min(nz - 1, static_cast<long>(r.z()));
        key[i] = (cz * ny + cy) * nx + cx;
        ++start[key[i] + 1];
    }
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    for (int i = 0; i < n; ++i) order[start[key[i]]++] = i;
    return order;
}

std::vector<int> inversePermutation(const std::vector<int>& order) {
    std::vector<int> inverse(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) inverse[order[k]] = static_cast<int>(k);
    return inverse;
}

}  // namespace dem
