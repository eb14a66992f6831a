#pragma once
// Linked-cell binning of particle centres, shared by the neighbour search and
// the spatial sort: cells in z-y-x row-major order, particles grouped by cell
// with ascending index inside each cell (a counting sort, O(N)).
#include <algorithm>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

struct CellBins {
    Vec3 lower = Vec3::Zero();  // corner of cell (0, 0, 0)
    double cellSize = 0.0;
    int nx = 0, ny = 0, nz = 0;
    std::vector<int> cellOf;     // cell of each particle
    std::vector<int> cellStart;  // cell c holds particles[cellStart[c] .. cellStart[c+1])
    std::vector<int> particles;  // particle indices grouped by cell
};

// Cells at least minCellSize wide over the positions' bounding box.  The cell
// count is capped at max(64, 4 N) by growing the cells, so that a few particles
// flying off cannot make the grid huge.
CellBins binIntoCells(const std::vector<Vec3>& positions, double minCellSize);

// Calls visit(j) for every particle j (the particle itself included) in the
// cell of `particle` and the cells around it, cells in z-y-x order and
// particles in ascending order within each cell.  With cells at least as wide
// as the largest diameter these hold every particle that can touch it.
template <class Visit>
void forEachInNeighbouringCells(const CellBins& bins, int particle, Visit&& visit) {
    const int cell = bins.cellOf[particle];
    const int cx = cell % bins.nx, cy = (cell / bins.nx) % bins.ny, cz = cell / (bins.nx * bins.ny);
    for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, bins.nz - 1); ++z)
        for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, bins.ny - 1); ++y)
            for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, bins.nx - 1); ++x) {
                const int neighbour = (z * bins.ny + y) * bins.nx + x;
                for (int e = bins.cellStart[neighbour]; e < bins.cellStart[neighbour + 1]; ++e)
                    visit(bins.particles[e]);
            }
}

}  // namespace dem
