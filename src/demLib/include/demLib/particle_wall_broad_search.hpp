#pragma once
// Particle-wall broad search: which walls each particle may touch before the
// next neighbour-list rebuild.  A wall at rest is listed for a particle when the
// particle is within its radius + skin of it at build time (it cannot reach a
// wall farther away before some particle has moved skin/2 and the lists are
// rebuilt).  Plane and cylinder walls under way in a motion segment are not
// listed: they are checked for every particle every step (their bounding box
// first).  "At rest" includes a wall with a motion between or after its
// segments (a die wall before it is lowered): the lists hold until
// validUntil(), the next segment start or end, when the caller must build them
// again.
//
// A mesh wall (STL) is listed whether it moves or not, by its triangles, which
// are searched in the wall's own frame.  A moving one (a shoe during its pass,
// a stamp coming down) is listed within a further travel allowance, and the
// lists must be built again once its material may have moved farther than
// that from where it was at the build (movedTooFar()).  Why that suffices: a
// particle moves at most skin/2 between neighbour-list builds, so at most the
// skin from a build of these lists that happened between two of them; the wall
// at most the allowance; the listing reaches radius + skin + allowance.
#include <vector>

#include "demLib/particle_store.hpp"
#include "demLib/wall.hpp"

namespace dem {

class ParticleWallCandidates {
public:
    // reach: the distance beyond contact a wall must be considered (skin plus
    // any cohesion range); travelAllowance: how far a moving mesh wall may move
    // before the lists are built again (the further reach its listing takes).
    void build(const ParticleStore& particles, const std::vector<Wall>& walls, double time, double reach,
               double travelAllowance = 0.0);

    // Static walls near particle i: entries [offsets()[i], offsets()[i+1]) of walls().
    const std::vector<int>& offsets() const { return offsets_; }
    const std::vector<int>& walls() const { return walls_; }
    // For entry k of walls() that is a mesh: the triangles within reach of the
    // particle at build time, entries [triangleOffsets()[k], triangleOffsets()[k+1])
    // of triangles() (empty for other shapes).  The step searches only these
    // (a mesh's grid walk was most of the cost of a die made of STL walls).
    const std::vector<int>& triangleOffsets() const { return triangleOffsets_; }
    const std::vector<int>& triangles() const { return triangles_; }
    // Plane and cylinder walls under way in a motion segment at build time:
    // checked for every particle.
    const std::vector<int>& movingWalls() const { return moving_; }
    // The first time a wall starts or stops moving after the build.
    double validUntil() const { return validUntil_; }
    // Whether a listed moving mesh wall may have moved, at `time`, farther than
    // the travel allowance from its pose at the build (any point of it, or
    // within the listing's reach of it): the lists must be built again.
    bool movedTooFar(const std::vector<Wall>& walls, double time) const;
    bool empty() const { return offsets_.size() <= 1; }

private:
    std::vector<int> offsets_{0};
    std::vector<int> walls_;
    std::vector<int> triangleOffsets_{0};
    std::vector<int> triangles_;
    std::vector<int> moving_;
    double validUntil_ = 0.0;
    // A mesh wall listed while it moves: its pose at the build and a sphere
    // enclosing it and the listing's reach around it (its reference frame).
    struct MovingMesh {
        int wall = 0;
        RigidTransform pose;
        Vec3 centre = Vec3::Zero();
        double radius = 0.0;
    };
    std::vector<MovingMesh> movingMeshes_;
    double travelAllowance_ = 0.0;
};

}  // namespace dem
