#pragma once
// Particle-wall contacts with their history.  The list is rebuilt every step in
// particle order (then wall, then feature), so the history of a contact is found
// again by binary search and the list is identical for any thread count.
//
// With capillary wall bridges the list also holds walls that do not touch the
// particle but lie within the bridge reach of its surface (gap <= reach): they
// may hold a liquid bridge (bridgeVolume) and are candidates of the liquid
// distribution.  Without wall bridges the reach is 0 and only touching walls
// are listed.
#include <cstdint>
#include <utility>
#include <vector>

#include "demLib/contact_law.hpp"
#include "demLib/particle_wall_broad_search.hpp"
#include "demLib/wall.hpp"

namespace dem {

struct WallContactRecord {
    int particle = 0;
    int wall = 0;
    int feature = 0;
    ContactHistory history;
    double bridgeVolume = 0.0;  // liquid held by a particle-wall bridge (0: none)
    // Force of the wall on the particle in the last step (contact and bridge);
    // the particle pushes the wall with -force (Simulation::wallForces).
    Vec3 force = Vec3::Zero();

    bool sameKey(const WallContactRecord& o) const {
        return particle == o.particle && wall == o.wall && feature == o.feature;
    }
    bool operator<(const WallContactRecord& o) const {
        if (particle != o.particle) return particle < o.particle;
        if (wall != o.wall) return wall < o.wall;
        return feature < o.feature;
    }
};

class ParticleWallContacts {
public:
    // History of (particle, wall, feature) from the previous step, or null.
    const WallContactRecord* find(int particle, int wall, int feature) const;
    // Index range [first, second) of the records of one particle.
    std::pair<std::size_t, std::size_t> rangeOf(int particle) const;

    // find() for particles visited in increasing order (the wall loop): the
    // records are walked forward once instead of searched per contact.
    class Cursor {
    public:
        Cursor(const ParticleWallContacts& contacts, int firstParticle);
        const WallContactRecord* find(int particle, int wall, int feature);

    private:
        const std::vector<WallContactRecord>& records_;
        std::size_t at_;  // first record of a particle >= the last one asked for
    };

    std::vector<WallContactRecord>& records() { return records_; }
    const std::vector<WallContactRecord>& records() const { return records_; }

    // Distance beyond contact (sphere surface to wall) within which walls are
    // listed: the capillary debonding reach with wall bridges, else 0.
    void setBridgeReach(double reach) { bridgeReach_ = reach; }
    double bridgeReach() const { return bridgeReach_; }

    // Particles were reordered or removed (see ParticleStore::compact/permute).
    void remap(const std::vector<int>& oldToNew);

private:
    std::vector<WallContactRecord> records_;
    double bridgeReach_ = 0.0;
};

// The walls near one sphere at one time.  Caches which walls are active and
// their bounding boxes; forEachNear() reports every wall feature whose surface
// lies within `reach` of the sphere surface, with the TRUE overlap (radius -
// distance; negative = gap).  reach = 0 is the plain contact search.
class WallProximityQuery {
public:
    WallProximityQuery(const std::vector<Wall>& walls, double time);

    // visit(int wallIndex, const WallContact& contact) for each feature, walls in
    // index order, features in the order the wall reports them.
    template <class Visit>
    void forEachNear(const Vec3& centre, double radius, double reach, Visit&& visit) {
        for (int w = 0; w < static_cast<int>(walls_.size()); ++w) visitWall(w, centre, radius, reach, visit);
    }

    // The same over the walls listed near particle i at the last build (its
    // static candidates, a mesh searched over its listed triangles only) and
    // the moving walls, in index order.
    template <class Visit>
    void forEachNearIn(const ParticleWallCandidates& candidates, int i, const Vec3& centre, double radius,
                       double reach, Visit&& visit) {
        int k = candidates.offsets()[i];
        const int last = candidates.offsets()[i + 1];
        const std::vector<int>& moving = candidates.movingWalls();
        auto m = moving.begin();
        while (k != last || m != moving.end()) {
            if (m == moving.end() || (k != last && candidates.walls()[k] < *m)) {
                const int first = candidates.triangleOffsets()[k];
                visitWall(candidates.walls()[k], centre, radius, reach, visit, candidates.triangles().data() + first,
                          candidates.triangleOffsets()[k + 1] - first);
                ++k;
            } else {
                visitWall(*m++, centre, radius, reach, visit);
            }
        }
    }

private:
    // triangles: a mesh wall's listed triangles (count of them), or null to
    // search the whole wall.
    template <class Visit>
    void visitWall(int w, const Vec3& centre, double radius, double reach, Visit& visit,
                   const int* triangles = nullptr, int count = 0) {
        const double searchRadius = radius + reach;
        if (!active_[w] || !boxes_[w].overlapsSphere(centre, searchRadius)) return;
        found_.clear();
        if (triangles) walls_[w].findContactsAmong(centre, searchRadius, time_, poses_[w], triangles, count, found_);
        else walls_[w].findContacts(centre, searchRadius, time_, poses_[w], found_);
        for (WallContact& c : found_) {
            if (reach != 0.0) c.overlap -= reach;
            visit(w, c);
        }
    }

    const std::vector<Wall>& walls_;
    double time_;
    std::vector<char> active_;
    std::vector<BoundingBox> boxes_;
    std::vector<RigidTransform> poses_;  // of the active walls at time_
    std::vector<WallContact> found_;
};

}  // namespace dem
