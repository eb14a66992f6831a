#pragma once
// Particle-wall broad search: which walls each particle may touch before the
// next neighbour-list rebuild.  A wall at rest is listed for a particle when the
// particle is within its radius + skin of it at build time (it cannot reach a
// wall farther away before some particle has moved skin/2 and the lists are
// rebuilt).  Walls under way in a motion segment are not listed: they are
// checked for every particle every step (their bounding box first).  "At rest"
// includes a wall with a motion between or after its segments (a die wall
// before it is lowered): the lists hold until validUntil(), the next segment
// start or end, when the caller must build them again.
#include <vector>

#include "demLib/particle_store.hpp"
#include "demLib/wall.hpp"

namespace dem {

class ParticleWallCandidates {
public:
    // reach: the distance beyond contact a wall must be considered (skin plus
    // any cohesion range).
    void build(const ParticleStore& particles, const std::vector<Wall>& walls, double time, double reach);

    // Static walls near particle i: entries [offsets()[i], offsets()[i+1]) of walls().
    const std::vector<int>& offsets() const { return offsets_; }
    const std::vector<int>& walls() const { return walls_; }
    // For entry k of walls() that is a mesh: the triangles within reach of the
    // particle at build time, entries [triangleOffsets()[k], triangleOffsets()[k+1])
    // of triangles() (empty for other shapes).  The step searches only these
    // (a mesh's grid walk was most of the cost of a die made of STL walls).
    const std::vector<int>& triangleOffsets() const { return triangleOffsets_; }
    const std::vector<int>& triangles() const { return triangles_; }
    // Walls under way in a motion segment at build time: checked for every particle.
    const std::vector<int>& movingWalls() const { return moving_; }
    // The first time a wall starts or stops moving after the build.
    double validUntil() const { return validUntil_; }
    bool empty() const { return offsets_.size() <= 1; }

private:
    std::vector<int> offsets_{0};
    std::vector<int> walls_;
    std::vector<int> triangleOffsets_{0};
    std::vector<int> triangles_;
    std::vector<int> moving_;
    double validUntil_ = 0.0;
};

}  // namespace dem
