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
    // Each thread lists a contiguous block of particles (static schedule), in
    // thread order: the blocks joined in that order are in particle order.
    struct Listed {
        std::vector<int> particle, wall, triangleCount, triangles;
    };
    const int threads = threadsFor(static_cast<std::size_t>(n), lightLoopParticlesPerThread);
    std::vector<Listed> perThread(static_cast<std::size_t>(std::max(threads, 1)));
#pragma omp parallel num_threads(threads)
    {
        Listed& mine = perThread[static_cast<std::size_t>(threadIndex())];
        std::vector<WallContact> found;
#pragma omp for schedule(static)
        for (int i = 0; i < n; ++i) {
            for (int w : fixed) {
                const Wall& wall = walls[w];
                const double r = particles.radius[i] + reach;
                if (!wall.boundingBox(time).overlapsSphere(particles.position[i], r)) continue;
                const std::size_t before = mine.triangles.size();
                if (wall.isMesh()) {
                    wall.nearTriangles(particles.position[i], r, time, mine.triangles);
                    if (mine.triangles.size() == before) continue;
                } else {
                    found.clear();
                    wall.findContacts(particles.position[i], r, time, found);
                    if (found.empty()) continue;
                }
                mine.particle.push_back(i);
                mine.wall.push_back(w);
                mine.triangleCount.push_back(static_cast<int>(mine.triangles.size() - before));
            }
        }
    }
    offsets_.assign(n + 1, 0);
    walls_.clear();
    triangleOffsets_.assign(1, 0);
    triangles_.clear();
    for (const Listed& block : perThread) {
        for (std::size_t k = 0; k < block.particle.size(); ++k) {
            ++offsets_[block.particle[k] + 1];
            walls_.push_back(block.wall[k]);
            triangleOffsets_.push_back(triangleOffsets_.back() + block.triangleCount[k]);
        }
        triangles_.insert(triangles_.end(), block.triangles.begin(), block.triangles.end());
    }
    for (int i = 0; i < n; ++i) offsets_[i + 1] += offsets_[i];
}

}  // namespace dem
