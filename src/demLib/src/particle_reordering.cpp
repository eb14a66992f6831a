#include "demLib/particle_reordering.hpp"

#include "demLib/cell_bins.hpp"

namespace dem {

std::vector<int> spatialOrder(const std::vector<Vec3>& positions, double cellSize) {
    return binIntoCells(positions, cellSize).particles;
}

std::vector<int> inversePermutation(const std::vector<int>& order) {
    std::vector<int> inverse(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) inverse[order[k]] = static_cast<int>(k);
    return inverse;
}

}  // namespace dem
