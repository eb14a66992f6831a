#pragma once
// Particle-wall contacts with their history.  The list is rebuilt every step in
// particle order (then wall, then feature), so the history of a contact is found
// again by binary search and the list is identical for any thread count.
#include <cstdint>
#include <vector>

#include "demLib/contact_law.hpp"

namespace dem {

struct WallContactRecord {
    int particle = 0;
    int wall = 0;
    int feature = 0;
    ContactHistory history;
    double bridgeVolume = 0.0;

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

    std::vector<WallContactRecord>& records() { return records_; }
    const std::vector<WallContactRecord>& records() const { return records_; }

    // Particles were reordered or removed (see ParticleStore::compact/permute).
    void remap(const std::vector<int>& oldToNew);

private:
    std::vector<WallContactRecord> records_;
};

}  // namespace dem
