#include "demLib/particle_wall_broad_search.hpp"

#include "demLib/parallel.hpp"

#include <algorithm>
#include <limits>

namespace dem {

void ParticleWallCandidates::build(const ParticleStore& particles, const std::vector<Wall>& walls, double time,
                                   double reach, double travelAllowance) {
    const int n = static_cast<int>(particles.size());
    moving_.clear();
    movingMeshes_.clear();
    travelAllowance_ = travelAllowance;
    validUntil_ = std::numeric_limits<double>::infinity();
    double largestRadius = 0.0;
    for (double r : particles.radius) largestRadius = std::max(largestRadius, r);
    std::vector<int> listed;         // at rest, or a mesh, until validUntil_
    std::vector<double> extraReach;  // per listed wall: the travel allowance of a moving mesh
    for (int w = 0; w < static_cast<int>(walls.size()); ++w) {
        const Wall& wall = walls[w];
        const WallMotion& motion = wall.motion;
        validUntil_ = std::min(validUntil_, motion.nextChangeAfter(time));
        if (!motion.isMovingAt(time)) {
            listed.push_back(w);
            extraReach.push_back(0.0);
        } else if (wall.isMesh()) {
            listed.push_back(w);
            extraReach.push_back(travelAllowance);
            const BoundingBox box = wall.referenceBoundingBox();
            MovingMesh m;
            m.wall = w;
            m.pose = motion.at(time);
            m.centre = 0.5 * (box.lower + box.upper);
            m.radius = 0.5 * (box.upper - box.lower).norm() + largestRadius + reach + travelAllowance;
            movingMeshes_.push_back(m);
        } else {
            moving_.push_back(w);
        }
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
            for (std::size_t k = 0; k < listed.size(); ++k) {
                const int w = listed[k];
                const Wall& wall = walls[w];
                const double r = particles.radius[i] + reach + extraReach[k];
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

bool ParticleWallCandidates::movedTooFar(const std::vector<Wall>& walls, double time) const {
    // A reference point y moves by (R - R0) y + (c - c0) between the poses; over
    // the sphere |y - centre| <= radius that is at most
    // |(R - R0) centre + c - c0| + ||R - R0|| radius (Frobenius >= spectral norm).
    for (const MovingMesh& m : movingMeshes_) {
        const RigidTransform now = walls[m.wall].motion.at(time);
        const Mat3 turn = now.rotation - m.pose.rotation;
        const double moved = (turn * m.centre + now.translation - m.pose.translation).norm() + turn.norm() * m.radius;
        if (moved > travelAllowance_) return true;
    }
    return false;
}

}  // namespace dem
