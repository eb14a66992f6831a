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

ParticleWallContacts::Cursor::Cursor(const ParticleWallContacts& contacts, int firstParticle)
    : records_(contacts.records_), at_(contacts.rangeOf(firstParticle).first) {}

const WallContactRecord* ParticleWallContacts::Cursor::find(int particle, int wall, int feature) {
    while (at_ < records_.size() && records_[at_].particle < particle) ++at_;
    for (std::size_t k = at_; k < records_.size() && records_[k].particle == particle; ++k)
        if (records_[k].wall == wall && records_[k].feature == feature) return &records_[k];
    return nullptr;
}

std::pair<std::size_t, std::size_t> ParticleWallContacts::rangeOf(int particle) const {
    const auto byParticle = [](const WallContactRecord& r, int p) { return r.particle < p; };
    const auto first = std::lower_bound(records_.begin(), records_.end(), particle, byParticle);
    auto last = first;
    while (last != records_.end() && last->particle == particle) ++last;
    return {static_cast<std::size_t>(first - records_.begin()), static_cast<std::size_t>(last - records_.begin())};
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

WallProximityQuery::WallProximityQuery(const std::vector<Wall>& walls, double time)
    : walls_(walls), time_(time), active_(walls.size()), boxes_(walls.size()), poses_(walls.size()) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
        active_[w] = walls[w].isActive(time);
        if (!active_[w]) continue;
        boxes_[w] = walls[w].boundingBox(time);
        if (!walls[w].motion.isStatic()) poses_[w] = walls[w].motion.at(time);
    }
}

}  // namespace dem
