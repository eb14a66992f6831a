#include "demLib/particle_wall_broad_search.hpp"

#include "demLib/parallel.hpp"

#include <algorithm>
#include <limits>

namespace dem {

void ParticleWallCandidates::build(const ParticleStore& particles, const std::vector<Wall>& walls, double time,
                                   double reach) {
    const int n = static_cast<int>(particles.size());
    moving_.clear();
    validUntil_ = std::numeric_limits<double>::infinity();
    std::vector<int> fixed;  // at rest until validUntil_
    for (int w = 0; w < static_cast<int>(walls.size()); ++w) {
        const WallMotion& motion = walls[w].motion;
        if (motion.isMovingAt(time)) moving_.push_back(w);
        else fixed.push_back(w);
        validUntil_ = std::min(validUntil_, motion.nextChangeAfter(time));
    }
    std::vector<int> count(n, 0);
    std::vector<unsigned char> near(static_cast<std::size_t>(n) * fixed.size(), 0);
    const int threads = threadsFor(static_cast<std::size_t>(n), lightLoopParticlesPerThread);
#pragma omp parallel num_threads(threads)
    {
        std::vector<WallContact> found;
#pragma omp for schedule(static)
        for (int i = 0; i < n; ++i) {
            for (std::size_t k = 0; k < fixed.size(); ++k) {
                const Wall& wall = walls[fixed[k]];
                const double r = particles.radius[i] + reach;
                if (!wall.boundingBox(time).overlapsSphere(particles.position[i], r)) continue;
                found.clear();
                wall.findContacts(particles.position[i], r, time, found);
                if (!found.empty()) {
                    near[static_cast<std::size_t>(i) * fixed.size() + k] = 1;
                    ++count[i];
                }
            }
        }
    }
    offsets_.assign(n + 1, 0);
    for (int i = 0; i < n; ++i) offsets_[i + 1] = offsets_[i] + count[i];
    walls_.resize(offsets_[n]);
    for (int i = 0; i < n; ++i) {
        int slot = offsets_[i];
        for (std::size_t k = 0; k < fixed.size(); ++k)
            if (near[static_cast<std::size_t>(i) * fixed.size() + k]) walls_[slot++] = fixed[k];
    }
}

}  // namespace dem
