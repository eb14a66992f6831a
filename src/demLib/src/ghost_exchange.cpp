#include "demLib/ghost_exchange.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <string>

#include "demLib/byte_buffer.hpp"
#include "demLib/config.hpp"
#include "demLib/error.hpp"
#include "demLib/exchange_trace.hpp"
#include "demLib/particle_message.hpp"

namespace dem {

namespace {

// A ghost update per particle: position, velocity, spin.
constexpr std::size_t ghostUpdateBytes = 3 * sizeof(Vec3);
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a ghost update is 9 doubles: Vec3 must hold 3 doubles, unpadded");

void packHistory(ByteWriter& w, const ContactHistory& h) {
    w.put(h.shear);
    w.put(h.rollingAngle);
}

ContactHistory unpackHistory(ByteReader& r) {
    ContactHistory h;
    h.shear = r.vec();
    h.rollingAngle = r.vec();
    return h;
}

bool isBlank(const ContactHistory& h) { return h.shear.isZero(0.0) && h.rollingAngle.isZero(0.0); }

// History vectors are defined for the first particle of a pair: seen from the
// other one they change sign (as in ParticleParticleNeighborList::remap).
PairState seenFromOther(PairState s) {
    s.contact.shear = -s.contact.shear;
    s.contact.rollingAngle = -s.contact.rollingAngle;
    return s;
}

bool pairKeyLess(const GhostExchange::PairRecord& a, const GhostExchange::PairRecord& b) {
    return a.first != b.first ? a.first < b.first : a.second < b.second;
}

bool wallKeyLess(const GhostExchange::WallRecord& a, const GhostExchange::WallRecord& b) {
    if (a.particle != b.particle) return a.particle < b.particle;
    if (a.wall != b.wall) return a.wall < b.wall;
    return a.feature < b.feature;
}

// The largest and the total over the slabs of the load the slabs give: the
// first n particles at `positions` with `weights` (1 each when empty), each
// to its slab's rank (`fallback` for one on a cut), added over the ranks in
// rank order, so every rank gets the same bits.
struct SlabLoad {
    double largest = 0.0, total = 0.0;
};
SlabLoad loadOverSlabs(const Communicator& communicator, const SlabDecomposition& slabs,
                       const std::vector<Vec3>& positions, std::size_t n, const std::vector<double>& weights,
                       int fallback) {
    std::vector<double> load(communicator.size(), 0.0);
    for (std::size_t i = 0; i < n; ++i) load[slabs.ownerOf(positions[i], fallback)] += weights.empty() ? 1.0 : weights[i];
    SlabLoad result;
    for (double l : sumOverRanksInRankOrder(communicator, load)) {
        result.largest = std::max(result.largest, l);
        result.total += l;
    }
    return result;
}

}  // namespace

GhostExchange::GhostExchange(Communicator communicator, SlabDecomposition slabs, double rebalanceThreshold)
    : communicator_(std::move(communicator)), slabs_(std::move(slabs)) {
    if (slabs_.ranks() != communicator_.size())
        throw InputError("demLib domain decomposition: " + std::to_string(slabs_.ranks()) + " slabs for " +
                         std::to_string(communicator_.size()) + " ranks; expected one slab per rank");
    setRebalanceThreshold(rebalanceThreshold);
    sendList_.assign(communicator_.size(), {});
    receiveCount_.assign(communicator_.size(), 0);
    updateSendBytes_.assign(communicator_.size(), 0);
    updateReceiveBytes_.assign(communicator_.size(), 0);
}

void GhostExchange::setSlabs(SlabDecomposition slabs) {
    if (ghostCount_ != 0) throw RuntimeError("demLib ghost exchange: setSlabs() called with ghosts present");
    if (slabs.ranks() != communicator_.size())
        throw InputError("demLib domain decomposition: " + std::to_string(slabs.ranks()) + " slabs for " +
                         std::to_string(communicator_.size()) + " ranks; expected one slab per rank");
    slabs_ = std::move(slabs);
}

void GhostExchange::setRebalanceThreshold(double threshold) {
    if (!(threshold == 0.0 || threshold >= 1.0))  // NaN fails too
        throw InputError("demLib domain decomposition: rebalance threshold " + std::to_string(threshold) +
                         "; expected max/mean owned >= 1 to re-cut at, or 0 (or infinity) for no balancing");
    rebalanceThreshold_ = threshold;
}

void GhostExchange::cutBalanced(const std::vector<Vec3>& positions, std::size_t n, const std::vector<double>& weights) {
    const int axis = slabs_.axis();
    std::vector<double> coordinates(n);
    for (std::size_t i = 0; i < n; ++i) coordinates[i] = positions[i][axis];
    setSlabs(SlabDecomposition::balanced(communicator_, axis, coordinates, weights));
    ++recuts_;
}

GhostExchange::RebalanceReport GhostExchange::rebalanceIfNeeded(const ParticleStore& p) {
    return rebalance(p, {}, false);
}

GhostExchange::RebalanceReport GhostExchange::rebalanceByWeight(const ParticleStore& p,
                                                                const std::vector<double>& weights) {
    return rebalance(p, weights, true);
}

GhostExchange::RebalanceReport GhostExchange::rebalance(const ParticleStore& p, const std::vector<double>& weights,
                                                        bool weighted) {
    if (ghostCount_ != 0) throw RuntimeError("demLib ghost exchange: rebalanceIfNeeded() called with ghosts present");
    RebalanceReport report;
    if (!balancingEnabled()) {
        report.cuts = slabs_.interiorCuts();
        lastRebalance_ = report;
        return report;
    }
    const std::size_t owned = p.size();
    if (weighted && weights.size() != owned)
        throw InputError("demLib ghost exchange: " + std::to_string(weights.size()) + " load weights for " +
                         std::to_string(owned) + " owned particles; expected one each (or none)");
    const int ranks = communicator_.size();
    // Integer sum and max: exact, so every rank takes the same decision.
    const std::int64_t total = communicator_.sum(static_cast<std::int64_t>(owned));
    report.maxOwned = static_cast<std::int64_t>(communicator_.max(static_cast<double>(owned)));
    report.meanOwned = static_cast<double>(total) / ranks;
    bool recut = false;
    if (!weighted) {
        report.imbalance = total > 0 ? report.maxOwned / report.meanOwned : 0.0;
        recut = total > 0 && report.imbalance > rebalanceThreshold_;
    } else {
        double load = 0.0;
        for (double w : weights) load += w;
        const double maxLoad = communicator_.max(load);
        const double meanLoad = communicator_.sum(load) / ranks;
        report.imbalance = meanLoad > 0.0 ? maxLoad / meanLoad : 0.0;
        // A floating-point sum may differ by a rounding between ranks: one
        // vote decides for all.
        recut = communicator_.anyTrue(meanLoad > 0.0 && report.imbalance > rebalanceThreshold_);
    }
    if (recut) {
        // (On a rank without particles `weights` is empty and reads as unit weights: none.)
        cutBalanced(p.position, owned, weights);
        if (weighted) {
            // The load each rank will hold: the weights by their new owner.
            const SlabLoad after = loadOverSlabs(communicator_, slabs_, p.position, owned, weights, rank());
            report.loadImbalanceAfter = after.total > 0.0 ? after.largest / (after.total / ranks) : 1.0;
        }
    }
    report.weighted = weighted;
    report.recut = recut;
    report.cuts = slabs_.interiorCuts();
    lastRebalance_ = report;
    if (recut) lastRecut_ = report;
    return report;
}

GhostExchange::RebalanceReport GhostExchange::balanceUndistributed(const std::vector<Vec3>& positions) {
    if (ghostCount_ != 0) throw RuntimeError("demLib ghost exchange: balanceUndistributed() called with ghosts present");
    RebalanceReport report;
    const int ranks = communicator_.size();
    if (balancingEnabled() && ranks > 1) {
        // The counts the current slabs would give.
        const SlabLoad counts = loadOverSlabs(communicator_, slabs_, positions, positions.size(), {}, 0);
        report.maxOwned = static_cast<std::int64_t>(counts.largest);
        report.meanOwned = counts.total / ranks;
        report.imbalance = counts.total > 0.0 ? counts.largest / report.meanOwned : 0.0;
        report.recut = counts.total > 0.0 && report.imbalance > rebalanceThreshold_;
        if (report.recut) cutBalanced(positions, positions.size(), {});
    }
    report.cuts = slabs_.interiorCuts();
    lastRebalance_ = report;
    if (report.recut) lastRecut_ = report;
    return report;
}

void GhostExchange::dropGhosts(ParticleStore& p, ParticleParticleNeighborList& pairs, ParticleWallContacts& walls) {
    const std::size_t owned = ownedCount(p);
    const auto& offsets = pairs.offsets();
    const auto& neighbors = pairs.neighbors();
    const PairStateView state = pairs.state();
    const std::size_t rows = offsets.size() - 1;
    for (std::size_t i = 0; i < rows; ++i) {
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const PairState s = state[k];
            if (isBlank(s.contact) && s.bridgeVolume == 0.0) continue;  // nothing to remember
            const std::int64_t a = p.id[i], b = p.id[neighbors[k]];
            if (a < b)
                pairStash_.push_back({a, b, s});
            else
                pairStash_.push_back({b, a, seenFromOther(s)});
        }
    }
    for (const WallContactRecord& r : walls.records()) {
        if (static_cast<std::size_t>(r.particle) >= owned) continue;  // a ghost's copy: its owner has the original
        if (isBlank(r.history) && r.bridgeVolume == 0.0) continue;
        wallStash_.push_back({p.id[r.particle], r.wall, r.feature, r.history, r.bridgeVolume});
    }
    walls.records().clear();
    pairs.remap(std::vector<int>(rows, -1));  // empties the list (and its build positions)
    if (ghostCount_ > 0) {
        std::vector<char> keep(p.size(), 0);
        std::fill(keep.begin(), keep.begin() + owned, 1);
        p.compact(keep);
        ghostCount_ = 0;
    }
    for (auto& list : sendList_) list.clear();
    std::fill(receiveCount_.begin(), receiveCount_.end(), 0);
}

std::size_t GhostExchange::migrate(ParticleStore& p) {
    if (ghostCount_ != 0) throw RuntimeError("demLib ghost exchange: migrate() called with ghosts present");
    const int ranks = communicator_.size();
    const int me = rank();
    const std::size_t n = p.size();
    std::vector<int> destination(n, me);
    std::vector<std::vector<std::size_t>> leaving(ranks);
    std::vector<std::pair<std::int64_t, int>> leavingIds;  // (id, destination), sorted by id
    std::size_t left = 0;
    for (std::size_t i = 0; i < n; ++i) {
        destination[i] = slabs_.ownerOf(p.position[i], me);
        if (destination[i] == me) continue;
        leaving[destination[i]].push_back(i);
        leavingIds.emplace_back(p.id[i], destination[i]);
        ++left;
    }
    // Every rank takes part, even with nothing to send.
    std::sort(leavingIds.begin(), leavingIds.end());
    auto destinationOfId = [&](std::int64_t id) {
        const auto it = std::lower_bound(leavingIds.begin(), leavingIds.end(), std::make_pair(id, -1));
        return it != leavingIds.end() && it->first == id ? it->second : me;
    };
    // Per destination: the particles, then the stashed history involving them
    // (a copy: this rank may still compute the pair with a ghost).
    std::vector<std::vector<PairRecord>> pairsTo(ranks);
    for (const PairRecord& rec : pairStash_) {
        const int da = destinationOfId(rec.first), db = destinationOfId(rec.second);
        if (da != me) pairsTo[da].push_back(rec);
        if (db != me && db != da) pairsTo[db].push_back(rec);
    }
    std::vector<std::vector<WallRecord>> wallsTo(ranks);
    for (const WallRecord& rec : wallStash_) {
        const int d = destinationOfId(rec.particle);
        if (d != me) wallsTo[d].push_back(rec);
    }
    std::vector<std::vector<char>> send(ranks);
    for (int r = 0; r < ranks; ++r) {
        if (r == me || (leaving[r].empty() && pairsTo[r].empty() && wallsTo[r].empty())) continue;
        ByteWriter w{send[r]};
        w.put(static_cast<std::uint64_t>(leaving[r].size()));
        for (std::size_t i : leaving[r]) packParticle(w, p, i);
        w.put(static_cast<std::uint64_t>(pairsTo[r].size()));
        for (const PairRecord& rec : pairsTo[r]) {
            w.put(rec.first);
            w.put(rec.second);
            packHistory(w, rec.state.contact);
            w.put(rec.state.bridgeVolume);
        }
        w.put(static_cast<std::uint64_t>(wallsTo[r].size()));
        for (const WallRecord& rec : wallsTo[r]) {
            w.put(rec.particle);
            w.put(rec.wall);
            w.put(rec.feature);
            packHistory(w, rec.history);
            w.put(rec.bridgeVolume);
        }
    }
    const std::vector<std::vector<char>> received = communicator_.exchange(send);
    if (left > 0) {
        std::vector<char> keep(n);
        for (std::size_t i = 0; i < n; ++i) keep[i] = destination[i] == me;
        p.compact(keep);
    }
    // Received in rank order after this rank's own entries: restoreHistory
    // keeps the first record of a key, so a rank's own copy of a pair wins.
    for (int r = 0; r < ranks; ++r) {
        if (r == me || received[r].empty()) continue;
        ByteReader in{received[r]};
        const auto particles = in.get<std::uint64_t>();
        for (std::uint64_t k = 0; k < particles; ++k) unpackParticle(in, p);
        const auto pairRecords = in.get<std::uint64_t>();
        for (std::uint64_t k = 0; k < pairRecords; ++k) {
            PairRecord rec;
            rec.first = in.get<std::int64_t>();
            rec.second = in.get<std::int64_t>();
            rec.state.contact = unpackHistory(in);
            rec.state.bridgeVolume = in.get<double>();
            pairStash_.push_back(rec);
        }
        const auto wallRecords = in.get<std::uint64_t>();
        for (std::uint64_t k = 0; k < wallRecords; ++k) {
            WallRecord rec;
            rec.particle = in.get<std::int64_t>();
            rec.wall = in.get<int>();
            rec.feature = in.get<int>();
            rec.history = unpackHistory(in);
            rec.bridgeVolume = in.get<double>();
            wallStash_.push_back(rec);
        }
        if (!in.done()) throw RuntimeError("demLib ghost exchange: malformed migration message");
    }
    migrated_ += left;
    return left;
}

void GhostExchange::appendGhosts(ParticleStore& p, double reachBeyondRadius) {
    if (ghostCount_ != 0) throw RuntimeError("demLib ghost exchange: appendGhosts() called with ghosts present");
    const int ranks = communicator_.size();
    const int me = rank();
    const std::size_t owned = p.size();
    // A pair i-j is closer than r_i + r_j + skin + extra <= r_i + reachBeyondRadius
    // (= r_max + skin + extra), so i lies that close to j's slab; a small
    // particle need not go as far as a large one.  The margin only adds ghosts.
    std::vector<std::vector<char>> send(ranks);
    for (int r = 0; r < ranks; ++r) {
        sendList_[r].clear();
        if (r == me) continue;
        for (std::size_t i = 0; i < owned; ++i)
            if (slabs_.distanceToSlab(r, p.position[i]) < (p.radius[i] + reachBeyondRadius) * (1.0 + 1e-9))
                sendList_[r].push_back(static_cast<int>(i));
        ByteWriter w{send[r]};
        for (int i : sendList_[r]) packParticle(w, p, static_cast<std::size_t>(i));
    }
    const std::vector<std::vector<char>> received = communicator_.exchange(send);
    for (int r = 0; r < ranks; ++r) {
        receiveCount_[r] = 0;
        if (r == me) continue;
        ByteReader in{received[r]};
        while (!in.done()) {
            unpackParticle(in, p);
            ++receiveCount_[r];
        }
    }
    ghostCount_ = p.size() - owned;
    for (int r = 0; r < ranks; ++r) {
        updateSendBytes_[r] = r == me ? 0 : sendList_[r].size() * ghostUpdateBytes;
        updateReceiveBytes_[r] = r == me ? 0 : receiveCount_[r] * ghostUpdateBytes;
    }
}

std::vector<std::vector<char>> GhostExchange::packGhostUpdates(const ParticleStore& p) const {
    const int ranks = communicator_.size();
    const int me = rank();
    std::vector<std::vector<char>> send(ranks);
    for (int r = 0; r < ranks; ++r) {
        if (r == me || sendList_[r].empty()) continue;
        // Sized once and copied vector by vector (every step: a write per
        // double cost ~5 us a step on the quick die filling's ~400 ghosts).
        // The bytes are those of ByteWriter::put(Vec3) x 3.
        send[r].resize(sendList_[r].size() * ghostUpdateBytes);
        char* out = send[r].data();
        for (int i : sendList_[r]) {
            std::memcpy(out, p.position[i].data(), sizeof(Vec3));
            std::memcpy(out + sizeof(Vec3), p.velocity[i].data(), sizeof(Vec3));
            std::memcpy(out + 2 * sizeof(Vec3), p.omega[i].data(), sizeof(Vec3));
            out += ghostUpdateBytes;
        }
    }
    return send;
}

void GhostExchange::unpackGhostUpdates(ParticleStore& p, const std::vector<std::vector<char>>& received) const {
    const int ranks = communicator_.size();
    const int me = rank();
    std::size_t g = ownedCount(p);
    for (int r = 0; r < ranks; ++r) {
        if (r == me) continue;
        if (received[r].size() != receiveCount_[r] * ghostUpdateBytes)
            throw RuntimeError("demLib ghost exchange: rank " + std::to_string(r) +
                               " sent a ghost update of the wrong size");
        const char* in = received[r].data();
        for (std::size_t k = 0; k < receiveCount_[r]; ++k, ++g, in += ghostUpdateBytes) {
            std::memcpy(p.position[g].data(), in, sizeof(Vec3));
            std::memcpy(p.velocity[g].data(), in + sizeof(Vec3), sizeof(Vec3));
            std::memcpy(p.omega[g].data(), in + 2 * sizeof(Vec3), sizeof(Vec3));
        }
    }
}

void GhostExchange::updateGhosts(ParticleStore& p) const {
    unpackGhostUpdates(p, communicator_.exchange(packGhostUpdates(p)));
}

bool GhostExchange::updateGhostsUnlessRebuild(ParticleStore& p, bool rebuildHere) const {
    // The update travels even when a rebuild follows (then it is dropped): the
    // flag and the messages share one wait, and a rebuild is rare.  Every rank
    // sends and expects the sizes of the last ghost build (appendGhosts, all
    // ranks together); a rank that has dropped its ghosts since (a particle
    // lost) needs a rebuild and sends zeros of those sizes.
    std::vector<std::vector<char>> send = packGhostUpdates(p);
    for (int r = 0; r < communicator_.size(); ++r) {
        if (send[r].size() == updateSendBytes_[r]) continue;
        if (!rebuildHere)
            throw RuntimeError("demLib ghost exchange: the ghost lists changed since the last build without a rebuild");
        send[r].assign(updateSendBytes_[r], 0);
    }
#if DEMLIB_EXCHANGE_TRACE
    const auto start = std::chrono::steady_clock::now();
#endif
    const Communicator::ExchangeAndFlag round =
        communicator_.exchangeKnownSizesAndAnyTrue(send, updateReceiveBytes_, rebuildHere);
#if DEMLIB_EXCHANGE_TRACE
    // One process's rounds (thread ranks would share the record).
    if (communicator_.usesMpi() && !communicator_.usesThreads()) {
        const auto end = std::chrono::steady_clock::now();
        std::size_t bytes = 0;
        for (const auto& m : send) bytes += m.size();
        ExchangeTrace& trace = ExchangeTrace::process();
        trace.setRank(communicator_.rank());
        trace.record(std::chrono::duration<double>(start.time_since_epoch()).count(),
                     std::chrono::duration<double>(end.time_since_epoch()).count(), static_cast<double>(bytes));
    }
#endif
    if (!round.anyTrue) unpackGhostUpdates(p, round.received);
    return round.anyTrue;
}

void GhostExchange::restoreHistory(const ParticleStore& p, ParticleParticleNeighborList& pairs,
                                   ParticleWallContacts& walls) {
    // Stable: of two records of one key the first (this rank's own) is kept.
    std::stable_sort(pairStash_.begin(), pairStash_.end(), pairKeyLess);
    pairStash_.erase(std::unique(pairStash_.begin(), pairStash_.end(),
                                 [](const PairRecord& a, const PairRecord& b) {
                                     return a.first == b.first && a.second == b.second;
                                 }),
                     pairStash_.end());
    const auto& offsets = pairs.offsets();
    const auto& neighbors = pairs.neighbors();
    if (!pairStash_.empty()) {
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i) {
            for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
                const std::int64_t a = p.id[i], b = p.id[neighbors[k]];
                const PairRecord key{std::min(a, b), std::max(a, b), PairState{}};
                const auto it = std::lower_bound(pairStash_.begin(), pairStash_.end(), key, pairKeyLess);
                if (it == pairStash_.end() || it->first != key.first || it->second != key.second) continue;
                pairs.setStateAt(static_cast<std::size_t>(k), a < b ? it->state : seenFromOther(it->state));
            }
        }
    }
    std::stable_sort(wallStash_.begin(), wallStash_.end(), wallKeyLess);
    wallStash_.erase(std::unique(wallStash_.begin(), wallStash_.end(),
                                 [](const WallRecord& a, const WallRecord& b) {
                                     return a.particle == b.particle && a.wall == b.wall && a.feature == b.feature;
                                 }),
                     wallStash_.end());
    auto& records = walls.records();
    records.clear();
    if (!wallStash_.empty()) {
        const std::size_t owned = ownedCount(p);
        for (std::size_t i = 0; i < owned; ++i) {
            WallRecord key{p.id[i], std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), ContactHistory{}, 0.0};
            auto it = std::lower_bound(wallStash_.begin(), wallStash_.end(), key, wallKeyLess);
            for (; it != wallStash_.end() && it->particle == p.id[i]; ++it) {
                WallContactRecord rec;
                rec.particle = static_cast<int>(i);
                rec.wall = it->wall;
                rec.feature = it->feature;
                rec.history = it->history;
                rec.bridgeVolume = it->bridgeVolume;
                records.push_back(rec);  // particle, then (wall, feature) order: sorted
            }
        }
    }
    pairStash_.clear();
    wallStash_.clear();
}

void GhostExchange::noteBalanceAfterMigration(const ParticleStore& particles) {
    const double owned = static_cast<double>(ownedCount(particles));
    const double largest = communicator_.max(owned);
    const double mean = communicator_.sum(owned) / communicator_.size();
    lastRecut_.imbalanceAfter = mean > 0.0 ? largest / mean : 1.0;
}

}  // namespace dem
