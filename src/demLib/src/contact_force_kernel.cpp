#include "demLib/contact_force_kernel.hpp"

#include "demLib/contact_law_batch.hpp"

#include "demLib/parallel.hpp"
#include "demLib/spin_barrier.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dem {

namespace {

// Cost of a pair in contact in units of a listed pair's touching test (the
// split of the rows between threads; see compute()).
constexpr long touchingPairCost = 3;

// Where one thread's pair loop adds forces and torques: straight into the
// particle arrays for the particles of its own rows [begin, end), which no other
// thread writes during the loop, and into the thread's own buffer for the
// others (neighbours just beyond its block), added by their owners afterwards.
struct ForceSink {
    Vec3* force;
    Vec3* torque;
    Vec3* bufferedForce;   // null with one thread
    Vec3* bufferedTorque;
    int begin, end;
    int lowestBuffered = std::numeric_limits<int>::max();
    int highestBuffered = -1;

    DEM_ALWAYS_INLINE bool owns(int j) const noexcept { return j >= begin && j < end; }
    // force[j] -= f, here or in the buffer (whose written range grows to j).
    DEM_ALWAYS_INLINE void forceOnOther(int j, const Vec3& f) noexcept {
        if (owns(j)) {
            force[j] -= f;
        } else {
            bufferedForce[j] -= f;
            lowestBuffered = std::min(lowestBuffered, j);
            highestBuffered = std::max(highestBuffered, j);
        }
    }
    // force[j] -= f and torque[j] += t.
    DEM_ALWAYS_INLINE void onOther(int j, const Vec3& f, const Vec3& t) noexcept {
        forceOnOther(j, f);
        (owns(j) ? torque : bufferedTorque)[j] += t;
    }
};

// A bridge's fit and what it was made for: the volume and the list version
// (ParticleParticleNeighborList::version(); -1: none yet).  Comparing both
// spares clearing the whole cache at every list build.
struct CachedBridgeFit {
    double volume = -1.0;
    long listVersion = -1;
    CapillaryBridgeFit fit;
};

template <RollingModel Rolling, CohesionModel Cohesion>
class ContactForceKernelImpl final : public ContactForceKernel {
public:
    using Law = ContactLaw<Rolling>;
    explicit ContactForceKernelImpl(const ForceFieldSettings& s) : ContactForceKernel(s) {}

    ContactStatistics compute(ParticleStore& p, ParticleParticleNeighborList& pairs,
                              ParticleWallContacts& wallContacts, const std::vector<Wall>& walls,
                              const ParticleWallCandidates& wallCandidates,
                              const InteractionTable& interactions, double time, double dt) override {
        // The list must keep the pair-state parts this law uses (the owner
        // normally configured it so; this only adds missing ones).
        const PairStateFields need = PairStateFields::forModels(Rolling, Cohesion == CohesionModel::Capillary);
        const PairStateFields have = pairs.stateFields();
        if ((need.rollingSpring && !have.rollingSpring) || (need.bridgeVolume && !have.bridgeVolume))
            pairs.setStateFields({have.rollingSpring || need.rollingSpring, have.bridgeVolume || need.bridgeVolume});
        const int n = static_cast<int>(p.size());
        const int threads = threadsFor(n, heavyLoopParticlesPerThread);
        // Each thread adds into the particle arrays for its own rows and into its
        // own buffer for other threads' particles; after a barrier every thread
        // adds, for its own rows, the other threads' buffers in thread order and
        // clears them.  The sums, and so the results, are the same in every run
        // with the same thread count.  The buffers are kept zero between steps.
        buffers_.resize(threads > 1 ? threads : 0);
        for (auto& buffer : buffers_) {
            if (buffer.force.size() != static_cast<std::size_t>(n)) {
                buffer.force.assign(n, Vec3::Zero());
                buffer.torque.assign(n, Vec3::Zero());
            }
        }
        bufferedRanges_.assign(threads, {0, 0});
        std::vector<ContactStatistics> stats(threads);
        changes_.resize(threads);
        for (auto& c : changes_) c.clear();
        while (static_cast<int>(batches_.size()) < threads) batches_.push_back(std::make_unique<ContactBatch>());
        newWall_.resize(threads);
        for (auto& w : newWall_) w.clear();
        auto& newWall = newWall_;
        // Rows are split at equal estimated cost, not at equal numbers of
        // particles: a listed pair costs its touching test, a pair in contact
        // about three times more (gathering its inputs, the law, the sums;
        // session 4 measured 4 % more pair-loop time on a block with 6.7 % more
        // touching pairs).  Touching is counted at the list build (positions
        // at build, restored exactly by a restart), so the split stays fixed
        // between builds and results depend only on the thread count.
        const int* offsets = pairs.offsets().data();
        const int* touchingPrefix =
            pairs.touchingOffsets().size() == static_cast<std::size_t>(n) + 1 ? pairs.touchingOffsets().data() : nullptr;
        auto rowCost = [&](int i) -> long {
            return offsets[i] + (touchingPrefix ? touchingPairCost * static_cast<long>(touchingPrefix[i]) : 0L);
        };
        const long totalCost = rowCost(n);
        auto rowSplit = [&](int t) {
            if (t == 0) return 0;
            if (t == threads) return n;
            const long target = totalCost * t / threads;
            int lo = 0, hi = n;  // the first row i with rowCost(i) >= target
            while (lo < hi) {
                const int mid = lo + (hi - lo) / 2;
                if (rowCost(mid) < target)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            return lo;
        };

        // Bridge fits per list entry (stale ones carry an older list version).
        CachedBridgeFit* fits = nullptr;
        if constexpr (Cohesion == CohesionModel::Capillary) {
            if (bridgeFits_.size() < pairs.pairCount()) bridgeFits_.resize(pairs.pairCount());
            fits = bridgeFits_.data();
        }
        const long listVersion = pairs.version();

        SpinBarrier teamBarrier;
#pragma omp parallel num_threads(threads)
        {
            const int t = threadIndex();
            const int begin = rowSplit(t);
            const int end = rowSplit(t + 1);
            ForceSink sink{p.force.data(), p.torque.data(), threads > 1 ? buffers_[t].force.data() : nullptr,
                           threads > 1 ? buffers_[t].torque.data() : nullptr, begin, end};
            // Counters, the history changes and the wall records live on this
            // thread's stack while it works: their slots in the per-thread
            // vectors share cache lines, and a counter or vector header written
            // there at every contact made the two cores fight over those lines
            // (the wall loop did not scale with the thread count at all).
            ContactStatistics localStats;
            ContactHistoryPool::Changes changes = std::move(changes_[t]);
            std::vector<WallContactRecord> wallRecords = std::move(newWall[t]);
            if (settings_.vectorizedPairLaw)
                pairForcesBatched(p, pairs, interactions, dt, sink, localStats, changes, *batches_[t], fits, listVersion);
            else
                pairForces(p, pairs, interactions, dt, sink, localStats, changes, fits, listVersion);
            wallForces(p, wallContacts, walls, wallCandidates, interactions, time, dt, begin, end, p.force.data(),
                       p.torque.data(), wallRecords, localStats);
            stats[t] = localStats;
            changes_[t] = std::move(changes);
            newWall[t] = std::move(wallRecords);
            if (threads > 1) {
                bufferedRanges_[t] = {sink.lowestBuffered, sink.highestBuffered + 1};
                teamBarrier.arriveAndWait(teamSize());
                // The other threads' contributions to this thread's rows, in thread order.
                for (int u = 0; u < threads; ++u) {
                    if (u == t) continue;
                    const int from = std::max(begin, bufferedRanges_[u].first);
                    const int to = std::min(end, bufferedRanges_[u].second);
                    Vec3* otherForce = buffers_[u].force.data();
                    Vec3* otherTorque = buffers_[u].torque.data();
                    for (int i = from; i < to; ++i) {
                        p.force[i] += otherForce[i];
                        p.torque[i] += otherTorque[i];
                        otherForce[i].setZero();
                        otherTorque[i].setZero();
                    }
                }
                // Meet here rather than at the region's end, where GOMP puts an
                // early thread to sleep (SpinBarrier).
                teamBarrier.arriveAndWait(teamSize());
            }
        }

        pairs.history().commit(changes_);

        ContactStatistics total;
        std::size_t wallCount = 0;
        for (int t = 0; t < threads; ++t) {
            total.touchingPairs += stats[t].touchingPairs;
            total.wallContacts += stats[t].wallContacts;
            total.bridges += stats[t].bridges;
            total.wallBridges += stats[t].wallBridges;
            total.releasedLiquid += stats[t].releasedLiquid;
            wallCount += newWall[t].size();
        }
        auto& records = wallContacts.records();
        records.clear();
        records.reserve(wallCount);
        for (auto& block : newWall) records.insert(records.end(), block.begin(), block.end());
        return total;
    }

private:
    struct Buffer {
        std::vector<Vec3> force;
        std::vector<Vec3> torque;
    };
    std::vector<Buffer> buffers_;
    std::vector<std::pair<int, int>> bufferedRanges_;  // per thread: [lowest, highest + 1) buffered
    std::vector<ContactHistoryPool::Changes> changes_;  // per thread, reused
    std::vector<std::unique_ptr<ContactBatch>> batches_;  // per thread, reused (45 kB each)
    std::vector<std::vector<WallContactRecord>> newWall_;  // per thread, reused
    std::vector<CachedBridgeFit> bridgeFits_;  // per list entry (capillary only)

    // The pair list's arrays as the pair loops read and write them.
    struct PairListArrays {
        const int* offsets;
        const int* neighbors;
        int* slot;          // history slot per listed pair (-1: none)
        double* records;    // history records; slots are only handed out after the loop
        std::size_t stride;  // doubles per record
        double* bridge;     // bridge volume per listed pair (capillary only, else null)
    };
    static PairListArrays arraysOf(ParticleParticleNeighborList& pairs) {
        ContactHistoryPool& pool = pairs.history();
        return {pairs.offsets().data(), pairs.neighbors().data(), pool.slots(), pool.record(0), pool.stride(),
                Cohesion == CohesionModel::Capillary ? pairs.bridgeVolume().data() : nullptr};
    }

    // A contact that opens forgets its springs (LIGGGHTS surfacesClose): its
    // record rests until the next list build, and the pair takes it back if it
    // touches again (ContactHistoryPool).
    static DEM_ALWAYS_INLINE void forgetSprings(int* slot, int k) { ContactHistoryPool::rest(slot[k]); }
    // The record the history of a touching contact goes to (a resting one is
    // taken back), or null (a new contact: its history goes to the pool's new
    // records after the loop).
    static DEM_ALWAYS_INLINE double* recordToWrite(int* slot, int k, double* records, std::size_t stride) {
        const int s = ContactHistoryPool::wake(slot[k]);
        return s >= 0 ? records + s * stride : nullptr;
    }

    // The capillary force of a bridge between spheres of radii r1, r2 (a wall:
    // wallEquivalentRadius twice), 0 without liquid.  A bridge whose gap exceeds
    // its debonding distance (eq 5) breaks: volume is set to 0 and its liquid
    // goes back to the free pool (releasedLiquid); a bridge that holds counts
    // in `holding`.
    double bridgeForce(double& volume, double overlap, double r1, double r2, std::size_t& holding,
                       double& releasedLiquid) const {
        if (!(volume > 0.0)) return 0.0;
        CachedBridgeFit cached;
        return pairBridgeForce(volume, cached, -1, overlap, r1, r2, holding, releasedLiquid);
    }

    // The same for a listed pair, whose fit of eqs 2-5 is kept with the list
    // entry while its volume and the list version (the key) stay: the
    // logarithm, the power and the cube root once per bridge and list build,
    // not at every step.
    double pairBridgeForce(double& volume, CachedBridgeFit& cached, long listVersion, double overlap, double r1,
                           double r2, std::size_t& holding, double& releasedLiquid) const {
        if (!(volume > 0.0)) return 0.0;
        if (cached.volume != volume || cached.listVersion != listVersion)
            cached = {volume, listVersion, capillaryBridgeFit(r1, r2, volume, settings_.capillary)};
        const double gap = -overlap;
        if (gap > cached.fit.debonding) {
            releasedLiquid += volume;  // back to the free liquid
            volume = 0.0;
            return 0.0;
        }
        ++holding;
        return settings_.capillaryForceScale * capillaryForceOfFit(cached.fit, gap);
    }

    // rowsFromLastToFirst: both pair loops walk the list from its last entry to
    // its first (the rows, and the pairs of each row, backwards).  The list
    // holds each pair once, as (i, j > i), and the particles are sorted by
    // cell; so, walking backwards, a row's partners were rows a moment ago and
    // their data is still in cache, and the only particle data new to the step
    // is the row's own, which arrives in one sequential stream that the
    // prefetcher follows.  The per-pair arrays (neighbours, history slots and
    // records, bridge volumes and fits) are read as descending streams too,
    // not as short runs that jump back at each row.  Walking forwards, the
    // partners ahead were where a particle's data was first touched in the
    // step: scattered misses that go to memory once the bed outgrows the
    // last-level cache (docs/performance-log.md, round 9).

    // The scalar pair loop (settings_.vectorizedPairLaw = false): one contact
    // after the other through ContactLaw::evaluate; the reference of pairForcesBatched.
    void pairForces(ParticleStore& p, ParticleParticleNeighborList& pairs,
                    const InteractionTable& interactions, double dt, ForceSink& sink, ContactStatistics& stats,
                    ContactHistoryPool::Changes& changes, CachedBridgeFit* fits, long listVersion) const {
        const int begin = sink.begin;
        const int end = sink.end;
        constexpr bool keepsRolling = Rolling == RollingModel::EPSD || Rolling == RollingModel::EPSD2;
        const auto [offsets, neighbors, slot, records, stride, bridge] = arraysOf(pairs);
        std::size_t touchingPairs = 0;  // a register, not a store per contact
        // List entries from last to first (see rowsFromLastToFirst).
        for (int i = end - 1; i >= begin; --i) {
            const Vec3 xi = p.position[i];
            const double ri = p.radius[i];
            Vec3 fi = Vec3::Zero();
            Vec3 ti = Vec3::Zero();
            for (int k = offsets[i + 1] - 1; k >= offsets[i]; --k) {
                const int j = neighbors[k];
                const Vec3 d = xi - p.position[j];
                const double rj = p.radius[j];
                const double radiusSum = ri + rj;
                const double dist2 = d.squaredNorm();
                if constexpr (Cohesion == CohesionModel::None) {
                    if (dist2 >= radiusSum * radiusSum) {
                        forgetSprings(slot, k);
                        continue;
                    }
                }
                const double dist = std::sqrt(dist2);
                const Vec3 normal = d * (1.0 / dist);  // one division, not three
                const double overlap = radiusSum - dist;

                double cohesiveForce = 0.0;
                if constexpr (Cohesion == CohesionModel::Capillary) {
                    cohesiveForce = pairBridgeForce(bridge[k], fits[k], listVersion, overlap, ri, rj, stats.bridges,
                                                    stats.releasedLiquid);
                    if (overlap <= 0.0) {
                        forgetSprings(slot, k);
                        if (cohesiveForce != 0.0) {
                            const Vec3 f = cohesiveForce * normal;
                            fi += f;
                            sink.forceOnOther(j, f);
                        }
                        continue;
                    }
                }
                ++touchingPairs;
                // Lever arms to the contact point, as LIGGGHTS (radius − δ/2).
                const double ci = ri - 0.5 * overlap;
                const double cj = rj - 0.5 * overlap;
                ContactKinematics kin;
                kin.normal = normal;
                kin.overlap = overlap;
                // R* = ri rj / (ri + rj) and m* = mi mj / (mi + mj) with one division.
                const double mi = p.mass[i];
                const double mj = p.mass[j];
                const double massSum = mi + mj;
                const double inverseSums = 1.0 / (radiusSum * massSum);
                kin.radiusEff = ri * rj * massSum * inverseSums;
                kin.massEff = mi * mj * radiusSum * inverseSums;
                kin.relVelocity = p.velocity[i] - p.velocity[j] - (ci * p.omega[i] + cj * p.omega[j]).cross(normal);
                kin.relOmega = p.omega[i] - p.omega[j];
                kin.dt = dt;
                if constexpr (Rolling == RollingModel::EPSD)
                    kin.rollingInertiaEff = rollingInertiaEff(p.mass[i], ri, p.mass[j], rj);
                // A contact without a slot is new: its springs start from zero
                // and get a slot after the loop.
                const int s = slot[k];
                ContactHistory history;
                double* record = s >= 0 ? records + s * stride : nullptr;
                if (record) {
                    history.shear = Vec3::Map(record);
                    if constexpr (keepsRolling) history.rollingAngle = Vec3::Map(record + 3);
                }
                const ContactForces f =
                    Law::evaluate(kin, interactions(p.material[i], p.material[j]), history, cohesiveForce);
                if (double* out = recordToWrite(slot, k, records, stride)) {
                    Vec3::Map(out) = history.shear;
                    if constexpr (keepsRolling) Vec3::Map(out + 3) = history.rollingAngle;
                } else {
                    changes.opened.push_back({k, history});
                }
                fi += f.force;
                const Vec3 nxFt = normal.cross(f.tangentialForce);
                ti += -ci * nxFt + f.rollingTorque;
                sink.onOther(j, f.force, -cj * nxFt - f.rollingTorque);
            }
            sink.force[i] += fi;
            sink.torque[i] += ti;
        }
        stats.touchingPairs += touchingPairs;
    }

    // pairForces in three passes over batches of touching pairs (and, with
    // cohesion, of bridges beyond contact): the touching test (pairs that opened
    // forget their springs; bridges are updated as in pairForces) gathers the
    // pairs' inputs into a ContactBatch; evaluateContactBatch runs
    // the law over the batch in vector lanes; the forces and torques are added
    // in the loop's order.  A row may span batches (its sums are carried over).
    // The results are bitwise those of pairForces (same operations, same sums).
    void pairForcesBatched(ParticleStore& p, ParticleParticleNeighborList& pairs,
                           const InteractionTable& interactions, double dt, ForceSink& sink,
                           ContactStatistics& stats, ContactHistoryPool::Changes& changes, ContactBatch& b,
                           CachedBridgeFit* fits, long listVersion) const {
        const int begin = sink.begin;
        const int end = sink.end;
        constexpr bool keepsRolling = Rolling == RollingModel::EPSD || Rolling == RollingModel::EPSD2;
        constexpr int capacity = ContactBatch::capacity;
        const auto [offsets, neighbors, slot, records, stride, bridge] = arraysOf(pairs);
        std::size_t touchingPairs = 0;
        // List entries from last to first (see rowsFromLastToFirst): k runs down
        // through the rows.
        int row = end - 1;                    // pass 1's cursor: row and list entry
        int k = begin < end ? offsets[end] - 1 : 0;
        int sumRow = end - 1;                 // pass 3's cursor and the sums of its row
        Vec3 fi = Vec3::Zero();
        Vec3 ti = Vec3::Zero();
        while (row >= begin) {
            // Pass 1a: the touching test over the listed pairs.
            // Without cohesion it selects without a branch: every pair is
            // written at the next free entry and the count grows by one if it
            // touches (the test is a coin toss for the branch predictor).
            int count = 0;
            for (; row >= begin; --row) {
                const Vec3 xi = p.position[row];
                const double ri = p.radius[row];
                const int rowStart = offsets[row];
                for (; k >= rowStart && count < capacity; --k) {
                    const int j = neighbors[k];
                    const Vec3 d = xi - p.position[j];
                    const double rj = p.radius[j];
                    const double radiusSum = ri + rj;
                    const double dist2 = d.squaredNorm();
                    const int e = count;
                    if constexpr (Cohesion == CohesionModel::None) {
                        const bool touching = !(dist2 >= radiusSum * radiusSum);
                        if ((slot[k] >= 0) & !touching) forgetSprings(slot, k);  // rare: a contact that opened
                        count += touching;
                    } else {
                        // A pair without a bridge that is clearly apart needs no
                        // root (the margin keeps the root's verdict: sqrt(dist2) > R).
                        if (!(bridge[k] > 0.0) && dist2 > radiusSum * radiusSum * (1.0 + 1e-12)) {
                            forgetSprings(slot, k);
                            continue;
                        }
                        // The bridge needs the gap of every other listed pair (the
                        // lanes compute the same root and normal again).
                        bool touching = true;
                        const double overlap = radiusSum - std::sqrt(dist2);
                        const double cohesiveForce =
                            pairBridgeForce(bridge[k], fits[k], listVersion, overlap, ri, rj, stats.bridges,
                                            stats.releasedLiquid);
                        if (overlap <= 0.0) {
                            forgetSprings(slot, k);
                            if (cohesiveForce == 0.0) continue;
                            touching = false;  // a bridge beyond contact: a force entry only
                        }
                        b.extraNormalForce[e] = cohesiveForce;
                        b.touching[e] = touching ? 1.0 : 0.0;
                        touchingPairs += touching;
                        ++count;
                    }
                    b.entry[e] = k;
                    b.particleI[e] = row;
                    b.particleJ[e] = j;
                    b.dx[e] = d.x();
                    b.dy[e] = d.y();
                    b.dz[e] = d.z();
                    b.distanceSquared[e] = dist2;
                    b.radiusI[e] = ri;
                    b.radiusJ[e] = rj;
                }
                if (k >= rowStart) break;  // batch full inside this row
            }
            if constexpr (Cohesion == CohesionModel::None) touchingPairs += count;

            // Pass 1b: the rest of the selected pairs' inputs.
            for (int e = 0; e < count; ++e) {
                const int i = b.particleI[e];
                const int j = b.particleJ[e];
                b.properties[e] = &interactions(p.material[i], p.material[j]);
                b.massI[e] = p.mass[i];
                b.massJ[e] = p.mass[j];
                const Vec3 dv = p.velocity[i] - p.velocity[j];
                b.dvx[e] = dv.x();
                b.dvy[e] = dv.y();
                b.dvz[e] = dv.z();
                const Vec3& wi = p.omega[i];
                const Vec3& wj = p.omega[j];
                b.wix[e] = wi.x();
                b.wiy[e] = wi.y();
                b.wiz[e] = wi.z();
                b.wjx[e] = wj.x();
                b.wjy[e] = wj.y();
                b.wjz[e] = wj.z();
                // A contact without a slot is new: its springs start from zero.
                // (A bridge beyond contact has no slot: forgotten above.)
                const int s = slot[b.entry[e]];
                const double* record = s >= 0 ? records + s * stride : nullptr;
                b.sx[e] = record ? record[0] : 0.0;
                b.sy[e] = record ? record[1] : 0.0;
                b.sz[e] = record ? record[2] : 0.0;
                if constexpr (keepsRolling) {
                    b.mx[e] = record ? record[3] : 0.0;
                    b.my[e] = record ? record[4] : 0.0;
                    b.mz[e] = record ? record[5] : 0.0;
                }
            }

            // Pass 2: the law in vector lanes.
            if (count > 0) evaluateContactBatch<Rolling, Cohesion == CohesionModel::Capillary>(b, count, dt);

            // Pass 3: sums in the loop's order; every row after pass 1's cursor is complete.
            auto closeRow = [&]() {
                sink.force[sumRow] += fi;
                sink.torque[sumRow] += ti;
                fi.setZero();
                ti.setZero();
                --sumRow;
            };
            for (int e = 0; e < count; ++e) {
                while (sumRow > b.particleI[e]) closeRow();
                const int j = b.particleJ[e];
                const Vec3 f(b.fx[e], b.fy[e], b.fz[e]);
                fi += f;
                if constexpr (Cohesion == CohesionModel::Capillary) {
                    if (b.touching[e] == 0.0) {  // a bridge beyond contact: no torque, no history
                        sink.forceOnOther(j, f);
                        continue;
                    }
                }
                ti += Vec3(b.tix[e], b.tiy[e], b.tiz[e]);
                sink.onOther(j, f, Vec3(b.tjx[e], b.tjy[e], b.tjz[e]));
                // History back to its record, or to the pool's new records after the loop.
                if (double* record = recordToWrite(slot, b.entry[e], records, stride)) {
                    record[0] = b.sx[e];
                    record[1] = b.sy[e];
                    record[2] = b.sz[e];
                    if constexpr (keepsRolling) {
                        record[3] = b.mx[e];
                        record[4] = b.my[e];
                        record[5] = b.mz[e];
                    }
                } else {
                    ContactHistory history;
                    history.shear = Vec3(b.sx[e], b.sy[e], b.sz[e]);
                    if constexpr (keepsRolling) history.rollingAngle = Vec3(b.mx[e], b.my[e], b.mz[e]);
                    changes.opened.push_back({b.entry[e], history});
                }
            }
            while (sumRow > row) closeRow();
        }
        stats.touchingPairs += touchingPairs;
    }

    void wallForces(ParticleStore& p, const ParticleWallContacts& old, const std::vector<Wall>& walls,
                    const ParticleWallCandidates& candidates, const InteractionTable& interactions, double time, double dt, int begin, int end,
                    Vec3* force, Vec3* torque, std::vector<WallContactRecord>& out,
                    ContactStatistics& stats) const {
        constexpr bool capillary = Cohesion == CohesionModel::Capillary;
        const bool bridges = capillary && settings_.wallBridges;
        const double reach = bridges ? old.bridgeReach() : 0.0;
        WallProximityQuery query(walls, time);
        ParticleWallContacts::Cursor previous(old, begin);
        for (int i = begin; i < end; ++i) {
            const std::size_t first = out.size();
            const Vec3 xi = p.position[i];
            const double ri = p.radius[i];
            // Only the static walls listed near i at the last list build, and the moving walls.
            query.forEachNearIn(candidates, i, xi, ri, reach, [&](int w, const WallContact& c) {
                const bool touching = c.overlap > 0.0;
                if (!touching && !bridges) return;
                WallContactRecord rec;
                rec.particle = i;
                rec.wall = w;
                rec.feature = c.feature;
                const WallContactRecord* prev = previous.find(i, w, c.feature);
                double cohesiveForce = 0.0;
                if (bridges && prev) {
                    // The sphere-wall bridge as the pair bridge of capillaryForceSphereWall.
                    const double equivalentRadius = wallEquivalentRadius(ri);
                    rec.bridgeVolume = prev->bridgeVolume;
                    cohesiveForce = bridgeForce(rec.bridgeVolume, c.overlap, equivalentRadius, equivalentRadius,
                                                stats.wallBridges, stats.releasedLiquid);
                }
                if (!touching) {
                    // Within the bridge reach only: no contact history, the
                    // bridge pulls along the wall normal through the centre.
                    rec.force = cohesiveForce * c.normal;
                    force[i] += rec.force;
                    out.push_back(rec);
                    return;
                }
                ++stats.wallContacts;
                if (prev) rec.history = prev->history;
                const double ci = ri - 0.5 * c.overlap;
                ContactKinematics kin;
                kin.normal = c.normal;
                kin.overlap = c.overlap;
                kin.radiusEff = ri;
                kin.massEff = p.mass[i];
                kin.relVelocity = p.velocity[i] - ci * p.omega[i].cross(c.normal) - c.wallVelocity;
                kin.relOmega = p.omega[i];
                kin.dt = dt;
                kin.isWall = true;
                if constexpr (Rolling == RollingModel::EPSD)
                    kin.rollingInertiaEff = rollingInertiaWall(p.mass[i], ri);
                const ContactForces f = Law::evaluate(kin, interactions(p.material[i], walls[w].materialIndex),
                                                      rec.history, cohesiveForce);
                rec.force = f.force;
                force[i] += f.force;
                torque[i] += -ci * c.normal.cross(f.tangentialForce) + f.rollingTorque;
                out.push_back(rec);
            });
            std::sort(out.begin() + first, out.end());
            if (bridges) releaseLostWallBridges(old, i, out, first, stats);
        }
    }

    // A wall bridge whose wall is no longer within the search reach (the
    // particle jumped past it in one step, or the wall was removed) is not
    // listed again: its liquid goes back to the pool.
    static void releaseLostWallBridges(const ParticleWallContacts& old, int particle,
                                       const std::vector<WallContactRecord>& out, std::size_t first,
                                       ContactStatistics& stats) {
        const auto [lo, hi] = old.rangeOf(particle);
        for (std::size_t k = lo; k < hi; ++k) {
            const WallContactRecord& r = old.records()[k];
            if (!(r.bridgeVolume > 0.0)) continue;
            const bool listed = std::binary_search(out.begin() + first, out.end(), r);
            if (!listed) stats.releasedLiquid += r.bridgeVolume;
        }
    }
};

template <RollingModel R>
std::unique_ptr<ContactForceKernel> makeWithRolling(const ForceFieldSettings& s) {
    if (s.cohesion == CohesionModel::Capillary)
        return std::make_unique<ContactForceKernelImpl<R, CohesionModel::Capillary>>(s);
    return std::make_unique<ContactForceKernelImpl<R, CohesionModel::None>>(s);
}

}  // namespace

std::unique_ptr<ContactForceKernel> makeContactForceKernel(const ForceFieldSettings& s) {
    switch (s.rolling) {
        case RollingModel::None: return makeWithRolling<RollingModel::None>(s);
        case RollingModel::CDT: return makeWithRolling<RollingModel::CDT>(s);
        case RollingModel::EPSD: return makeWithRolling<RollingModel::EPSD>(s);
        case RollingModel::EPSD2: return makeWithRolling<RollingModel::EPSD2>(s);
    }
    return nullptr;
}

}  // namespace dem
