#include "demLib/cell_bins.hpp"

#include <algorithm>
#include <cmath>

namespace dem {

CellBins binIntoCells(const std::vector<Vec3>& positions, double minCellSize) {
    CellBins b;
    const int n = static_cast<int>(positions.size());
    if (n == 0) return b;
    Vec3 lo = positions[0], hi = positions[0];
    for (const Vec3& x : positions) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    }
    double cell = minCellSize;
    const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(cell));
    const double maxCells = std::max(64.0, 4.0 * n);
    while ((std::floor(extent.x() / cell) + 1) * (std::floor(extent.y() / cell) + 1) *
               (std::floor(extent.z() / cell) + 1) > maxCells)
        cell *= 1.26;
    b.lower = lo;
    b.cellSize = cell;
    b.nx = static_cast<int>(extent.x() / cell) + 1;
    b.ny = static_cast<int>(extent.y() / cell) + 1;
    b.nz = static_cast<int>(extent.z() / cell) + 1;
    const double invCell = 1.0 / cell;

    b.cellOf.resize(n);
    b.cellStart.assign(static_cast<std::size_t>(b.nx) * b.ny * b.nz + 1, 0);
    for (int i = 0; i < n; ++i) {
        const Vec3 r = (positions[i] - lo) * invCell;
        const int cx = std::min(b.nx - 1, static_cast<int>(r.x()));
        const int cy = std::min(b.ny - 1, static_cast<int>(r.y()));
        const int cz = std::min(b.nz - 1, static_cast<int>(r.z()));
        b.cellOf[i] = (cz * b.ny + cy) * b.nx + cx;
        ++b.cellStart[b.cellOf[i] + 1];
    }
    for (std::size_t c = 1; c < b.cellStart.size(); ++c) b.cellStart[c] += b.cellStart[c - 1];
    b.particles.resize(n);
    std::vector<int> fill(b.cellStart.begin(), b.cellStart.end() - 1);
    for (int i = 0; i < n; ++i) b.particles[fill[b.cellOf[i]]++] = i;  // ascending i per cell
    return b;
}

}  // namespace dem
