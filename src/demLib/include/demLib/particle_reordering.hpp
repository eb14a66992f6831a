#pragma once
// Spatial ordering of the particles: particles close in space get close
// indices, so the force loop's accesses to neighbour j stay in cache (LAMMPS'
// atom_modify sort).  Without it the insertion order survives and the cost
// per particle grows with N.
#include <vector>

#include "demLib/particle_store.hpp"

namespace dem {

// The permutation that sorts the particles by the cell (of the given size) that
// holds their centre, cells in row-major order with the axis of most cells
// slowest and that of fewest fastest (ties: z before y before x); stable
// within a cell.
// order[k] is the old index of the particle that goes to index k.
std::vector<int> spatialOrder(const std::vector<Vec3>& positions, double cellSize);

// oldToNew[order[k]] = k.
std::vector<int> inversePermutation(const std::vector<int>& order);

}  // namespace dem
