#pragma once
// Linked-cell binning of particle centres, shared by the neighbour search and
// the spatial sort: cells in z-y-x row-major order, particles grouped by cell
// with ascending index inside each cell (a counting sort, O(N)).
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

}  // namespace dem
