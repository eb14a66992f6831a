#include "demLib/particle_reordering.hpp"

#include <algorithm>
#include <array>

#include "demLib/cell_bins.hpp"

namespace dem {

std::vector<int> spatialOrder(const std::vector<Vec3>& positions, double cellSize) {
    CellBins bins = binIntoCells(positions, cellSize);
    // The force loop reads the neighbours j > i of row i up to one slab of
    // cells ahead (the slab across the slowest axis).  With the longest axis
    // slowest that slab is the smallest one and stays in cache: in a bed wider
    // than deep, z-slowest order put a whole layer (>1 MB at 200k particles)
    // between a particle and its neighbours above.
    const std::array<int, 3> cells = {bins.nx, bins.ny, bins.nz};
    std::array<int, 3> slowestFirst = {2, 1, 0};  // ties keep the grid's z-y-x order
    std::stable_sort(slowestFirst.begin(), slowestFirst.end(),
                     [&](int a, int b) { return cells[a] > cells[b]; });
    if (slowestFirst == std::array<int, 3>{2, 1, 0}) return std::move(bins.particles);

    const int n = static_cast<int>(positions.size());
    const int a0 = slowestFirst[0], a1 = slowestFirst[1], a2 = slowestFirst[2];
    std::vector<int> key(n);
    for (int i = 0; i < n; ++i) {
        const int c = bins.cellOf[i];
        const std::array<int, 3> xyz = {c % bins.nx, (c / bins.nx) % bins.ny, c / (bins.nx * bins.ny)};
        key[i] = (xyz[a0] * cells[a1] + xyz[a1]) * cells[a2] + xyz[a2];
    }
    // Counting sort by key, ascending index within a cell (stable).
    std::vector<int> start(bins.cellStart.size(), 0);
    for (int i = 0; i < n; ++i) ++start[key[i] + 1];
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    std::vector<int> order(n);
    for (int i = 0; i < n; ++i) order[start[key[i]]++] = i;
    return order;
}

std::vector<int> inversePermutation(const std::vector<int>& order) {
    std::vector<int> inverse(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) inverse[order[k]] = static_cast<int>(k);
    return inverse;
}

}  // namespace dem
