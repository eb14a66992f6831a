#include "demLib/particle_wall_contacts.hpp"

#include <algorithm>

namespace dem {

const WallContactRecord* ParticleWallContacts::find(int particle, int wall, int feature) const {
    WallContactRecord key;
    key.particle = particle;
    key.wall = wall;
    key.feature = feature;
    const auto it = std::lower_bound(records_.begin(), records_.end(), key);
    if (it == records_.end() || !it->sameKey(key)) return nullptr;
    return &*it;
}

void ParticleWallContacts::remap(const std::vector<int>& oldToNew) {
    std::vector<WallContactRecord> kept;
    kept.reserve(records_.size());
    for (WallContactRecord r : records_) {
        if (oldToNew[r.particle] < 0) continue;
        r.particle = oldToNew[r.particle];
        kept.push_back(r);
    }
    std::sort(kept.begin(), kept.end());
    records_.swap(kept);
}

}  // namespace dem
