#include "demLib/particle_particle_neighbor_list.hpp"

#include "demLib/cell_bins.hpp"
#include "demLib/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dem {


void ParticleParticleNeighborList::setStateFields(const PairStateFields& fields) {
    if (fields == fields_) return;
    history_.setRolling(fields.rollingSpring);
    if (fields.bridgeVolume != fields_.bridgeVolume) {
        if (fields.bridgeVolume)
            bridgeVolume_.assign(neighbors_.size(), 0.0);
        else
            std::vector<double>().swap(bridgeVolume_);
    }
    fields_ = fields;
}

void ParticleParticleNeighborList::setRanges(double skin, double extraRange) {
    skin_ = skin;
    extraRange_ = extraRange;
}

void ParticleParticleNeighborList::setBridgeListing(const LiquidBridgeSettings& settings, double liquidPerWeightLimit) {
    bridgeSettings_ = settings;
    bridgeListingLimit_ = liquidPerWeightLimit;
}

void ParticleParticleNeighborList::relistAtBuildPositions(const ParticleStore& particles, std::size_t listedRows) {
    buildFrom(particles, positionAtBuild_, listedRows);
}

bool ParticleParticleNeighborList::needsRebuild(const ParticleStore& particles) const {
    if (positionAtBuild_.size() != particles.size()) return true;
    const double limit2 = rebuildDisplacementSquared();
    const std::size_t n = particles.size();
    bool rebuild = false;
#pragma omp parallel for schedule(static) reduction(|| : rebuild) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i)
        if ((particles.position[i] - positionAtBuild_[i]).squaredNorm() > limit2) rebuild = true;
    return rebuild;
}

void ParticleParticleNeighborList::build(const ParticleStore& particles, std::size_t listedRows) {
    buildFrom(particles, particles.position, listedRows);
    positionAtBuild_ = particles.position;
    ++buildCount_;
}

void ParticleParticleNeighborList::restore(const ParticleStore& particles,
                                           const std::vector<Vec3>& positionAtBuild,
                                           long buildCount, std::size_t listedRows) {
    offsets_.assign(1, 0);
    neighbors_.clear();
    history_.reset(0);
    bridgeVolume_.clear();
    buildFrom(particles, positionAtBuild, listedRows);
    positionAtBuild_ = positionAtBuild;
    buildCount_ = buildCount;
}

bool ParticleParticleNeighborList::setState(int i, int j, const PairState& s) {
    if (i > j) return false;
    const auto first = neighbors_.begin() + offsets_[i];
    const auto last = neighbors_.begin() + offsets_[i + 1];
    const auto it = std::lower_bound(first, last, j);
    if (it == last || *it != j) return false;
    setStateAt(static_cast<std::size_t>(it - neighbors_.begin()), s);
    return true;
}

void ParticleParticleNeighborList::setStateAt(std::size_t k, const PairState& s) {
    // Zero history is what "no slot" means already.
    if (!s.contact.shear.isZero(0.0) || (fields_.rollingSpring && !s.contact.rollingAngle.isZero(0.0)))
        history_.set(k, s.contact);
    if (fields_.bridgeVolume) bridgeVolume_[k] = s.bridgeVolume;
}

void ParticleParticleNeighborList::buildFrom(const ParticleStore& particles,
                                             const std::vector<Vec3>& positions, std::size_t listedRows) {
    ++version_;
    const int n = static_cast<int>(particles.size());
    // Rows listed (first particles of pairs): all but MPI ghosts.
    const int rows = static_cast<int>(std::min(listedRows, particles.size()));
    // Particles appended since the last build (insertion) have no old pairs.
    const int oldN = static_cast<int>(offsets_.size()) - 1;
    const bool canTransfer = oldN >= 0 && oldN <= n;
    if (!canTransfer) {
        offsets_.assign(1, 0);
        neighbors_.clear();
        history_.reset(0);
        bridgeVolume_.clear();
    }
    std::vector<int> newOffsets(n + 1, 0);
    touchingOffsets_.assign(n + 1, 0);
    if (n == 0) {
        offsets_.swap(newOffsets);
        neighbors_.clear();
        history_.reset(0);
        bridgeVolume_.clear();
        return;
    }

    // Cells at least one interaction range wide, so that only the 27
    // surrounding cells need a look; and of those only the ones that the
    // particle's own search sphere (its radius + the largest radius + the
    // reach) touches: in a polydisperse bed the cells are sized for two of the
    // largest particles, and a small particle reaches few of its 26 neighbour
    // cells (the wet bench's list build 27 % faster; finer cells with a wider
    // stencil were slower).  The rows are sorted below, so the list does not
    // depend on which cells are visited, only on the pairs found.
    double rMax = 0.0;
    for (int i = 0; i < n; ++i) rMax = std::max(rMax, particles.radius[i]);
    CellBins bins = binIntoCells(positions, 2.0 * rMax + skin_ + extraRange_);
    const int nx = bins.nx, ny = bins.ny, nz = bins.nz;
    const double invCell = 1.0 / bins.cellSize;
    const Vec3 gridLower = bins.lower;
    const std::vector<int>& cellOf = bins.cellOf;
    const std::vector<int>& cellStart = bins.cellStart;
    const std::vector<int>& cellParticles = bins.particles;

    // Each thread lists a contiguous block of i into its own buffers; blocks
    // are joined in order, so the list does not depend on the thread count.
    // Each new row is merged with the old row of the same particle (both
    // sorted by j) as it is made: a pair that stays listed takes its history
    // slot and bridge volume along, a new pair already in contact gets a zero
    // record.  So no old-to-new entry map is needed, and the old list and
    // history slots are dead once the blocks are complete.
    const int threads = threadsFor(rows, heavyLoopParticlesPerThread);
    blocks_.resize(threads);
    const double reach = skin_ + extraRange_;
    const bool filterBridges = extraRange_ > 0.0 && bridgeListingLimit_ < std::numeric_limits<double>::infinity();
    const int* oldOffsets = offsets_.data();
    const int* oldNeighbors = neighbors_.data();
    const int* oldSlots = history_.slots();
    const double* oldBridge = bridgeVolume_.data();
    const bool keepBridges = fields_.bridgeVolume;
    const int transferRows = canTransfer ? oldN : 0;
    int* touchingCount = touchingOffsets_.data() + 1;
#pragma omp parallel num_threads(threads)
    {
        const int t = threadIndex();
        const int begin = static_cast<int>(static_cast<long>(rows) * t / threads);
        const int end = static_cast<int>(static_cast<long>(rows) * (t + 1) / threads);
        BuildBlock& out = blocks_[t];
        out.neighbors.clear();
        out.slotSource.clear();
        out.bridgeVolume.clear();
        // Room for the old block's pairs and an eighth more (the first build:
        // eight per particle); later builds reuse the buffers' memory.  The
        // buffers are replaced only when they hold less than a sixteenth more
        // than the old block: a bed whose pair count creeps up by a few
        // hundred per build otherwise took new buffers at every other build
        // (the single-thread buffers alternate with the list's own arrays),
        // and the freed ones stayed in the heap (+70 bytes per particle of
        // peak memory over 3000 steps of bench (a)).
        const int lo = std::min(begin, transferRows), hi = std::min(end, transferRows);
        const std::size_t oldPairs = static_cast<std::size_t>(oldOffsets[hi] - oldOffsets[lo]);
        const std::size_t expected = transferRows > 0 ? oldPairs * 9 / 8 + 64 : static_cast<std::size_t>(end - begin) * 8;
        const std::size_t enough = transferRows > 0 ? oldPairs * 17 / 16 + 64 : expected;
        if (out.neighbors.capacity() < enough) {
            out.neighbors.reserve(expected);
            out.slotSource.reserve(expected);
        }
        if (keepBridges && out.bridgeVolume.capacity() < enough) out.bridgeVolume.reserve(expected);
        std::vector<int>& mine = out.row;
        for (int i = begin; i < end; ++i) {
            mine.clear();
            int touching = 0;
            const int c = cellOf[i];
            const int cx = c % nx, cy = (c / nx) % ny, cz = c / (nx * ny);
            const Vec3& xi = positions[i];
            const double ri = particles.radius[i];
            // Position and search radius in cell units (the position computed
            // as the binning did); a cell is skipped when its gap to the
            // position exceeds the radius, with a margin far above rounding.
            const Vec3 at = (xi - gridLower) * invCell;
            const double search = (ri + rMax + reach) * invCell * (1.0 + 1e-9) + 1e-9;
            const double search2 = search * search;
            // Gap in cell units between coordinate u (in cell k) and cell q.
            auto gap = [](double u, int k, int q) { return q > k ? q - u : (q < k ? u - (q + 1) : 0.0); };
            for (int dz = -1; dz <= 1; ++dz) {
                const int z = cz + dz;
                if (z < 0 || z >= nz) continue;
                const double gz = gap(at.z(), cz, z);
                const double gz2 = gz * gz;
                if (gz2 > search2) continue;
                for (int dy = -1; dy <= 1; ++dy) {
                    const int y = cy + dy;
                    if (y < 0 || y >= ny) continue;
                    const double gy = gap(at.y(), cy, y);
                    const double gzy2 = gz2 + gy * gy;
                    if (gzy2 > search2) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int x = cx + dx;
                        if (x < 0 || x >= nx) continue;
                        const double gx = gap(at.x(), cx, x);
                        if (gzy2 + gx * gx > search2) continue;
                        const int cc = (z * ny + y) * nx + x;
                        for (int k = cellStart[cc]; k < cellStart[cc + 1]; ++k) {
                            const int j = cellParticles[k];
                            if (j <= i) continue;
                            const double rj = particles.radius[j];
                            const double contact = ri + rj;
                            const double range = contact + reach;
                            const double dist2 = (positions[j] - xi).squaredNorm();
                            touching += dist2 < contact * contact;
                            if (!(dist2 < range * range)) continue;
                            // Beyond touching reach: only where a bridge can hold.
                            const double touchingRange = contact + skin_;
                            if (filterBridges && !(dist2 < touchingRange * touchingRange) &&
                                !(bridgeStabilityThreshold(ri, rj, std::sqrt(dist2), bridgeSettings_) <= bridgeListingLimit_))
                                continue;
                            mine.push_back(j);
                        }
                    }
                }
            }
            std::sort(mine.begin(), mine.end());
            newOffsets[i + 1] = static_cast<int>(mine.size());
            touchingCount[i] = touching;
            int a = i < transferRows ? oldOffsets[i] : 0;
            const int aEnd = i < transferRows ? oldOffsets[i + 1] : 0;
            for (const int j : mine) {
                while (a < aEnd && oldNeighbors[a] < j) ++a;
                const int old = a < aEnd && oldNeighbors[a] == j ? a : -1;
                // A resting record (a contact that opened) is not carried.
                int source = old >= 0 && oldSlots[old] >= 0 ? oldSlots[old] : -1;
                if (source < 0) {
                    // Pairs in contact now get their record here, in list
                    // order; only contacts that close later take slots out of order.
                    const double contact = ri + particles.radius[j];
                    if ((positions[j] - xi).squaredNorm() < contact * contact)
                        source = ContactHistoryPool::freshRecord;
                }
                out.neighbors.push_back(j);
                out.slotSource.push_back(source);
                if (keepBridges) out.bridgeVolume.push_back(old >= 0 ? oldBridge[old] : 0.0);
            }
        }
    }
    // The cells are not needed any more: free them before the list is joined.
    std::vector<int>().swap(bins.cellOf);
    std::vector<int>().swap(bins.cellStart);
    std::vector<int>().swap(bins.particles);
    for (int i = 0; i < n; ++i) {
        newOffsets[i + 1] += newOffsets[i];
        touchingOffsets_[i + 1] += touchingOffsets_[i];
    }
    offsets_.swap(newOffsets);
    std::vector<int>().swap(newOffsets);

    if (threads == 1) {
        // The old arrays become the block's buffers for the next build.
        neighbors_.swap(blocks_[0].neighbors);
        if (keepBridges) bridgeVolume_.swap(blocks_[0].bridgeVolume);
        history_.repack(blocks_[0].slotSource);
    } else {
        // The old list is dead: its memory takes the joined one (with an
        // eighth more room when it must grow, for the same reason as above).
        const auto reserveFor = [&](auto& v) {
            v.clear();
            if (v.capacity() < static_cast<std::size_t>(offsets_[n]))
                v.reserve(static_cast<std::size_t>(offsets_[n]) * 9 / 8 + 64);
        };
        reserveFor(neighbors_);
        for (const BuildBlock& block : blocks_)
            neighbors_.insert(neighbors_.end(), block.neighbors.begin(), block.neighbors.end());
        if (keepBridges) {
            reserveFor(bridgeVolume_);
            for (const BuildBlock& block : blocks_)
                bridgeVolume_.insert(bridgeVolume_.end(), block.bridgeVolume.begin(), block.bridgeVolume.end());
        }
        std::vector<int> source = history_.releaseSlots();
        reserveFor(source);
        for (const BuildBlock& block : blocks_)
            source.insert(source.end(), block.slotSource.begin(), block.slotSource.end());
        history_.repack(source);
    }
    if (!keepBridges) bridgeVolume_.clear();
}

void ParticleParticleNeighborList::remap(const std::vector<int>& oldToNew) {
    ++version_;
    touchingOffsets_.clear();  // rows moved: known again at the next build
    const int oldN = static_cast<int>(offsets_.size()) - 1;
    int newN = 0;
    for (int k : oldToNew) newN = std::max(newN, k + 1);
    // The surviving pairs as (new i, new j, old entry); `flip` when the pair is
    // seen from the other particle now.
    struct Entry {
        int i, j, from;
        bool flip;
    };
    std::vector<Entry> entries;
    entries.reserve(neighbors_.size());
    for (int i = 0; i < oldN; ++i) {
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            const int a = oldToNew[i], b = oldToNew[neighbors_[k]];
            if (a < 0 || b < 0) continue;
            if (a < b)
                entries.push_back({a, b, k, false});
            else
                entries.push_back({b, a, k, true});
        }
    }
    std::sort(entries.begin(), entries.end(),
              [](const Entry& x, const Entry& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
    offsets_.assign(newN + 1, 0);
    neighbors_.resize(entries.size());
    for (std::size_t k = 0; k < entries.size(); ++k) {
        ++offsets_[entries[k].i + 1];
        neighbors_[k] = entries[k].j;
    }
    for (int i = 0; i < newN; ++i) offsets_[i + 1] += offsets_[i];
    // History vectors are defined for the first particle of the pair: they
    // change sign when the pair is seen from the other particle.
    std::vector<int> from(entries.size());
    std::vector<char> flip(entries.size());
    for (std::size_t k = 0; k < entries.size(); ++k) {
        from[k] = entries[k].from;
        flip[k] = entries[k].flip;
    }
    history_.rebuild(from, flip, {});
    if (fields_.bridgeVolume) {
        std::vector<double> out(entries.size());
        for (std::size_t k = 0; k < entries.size(); ++k) out[k] = bridgeVolume_[entries[k].from];
        bridgeVolume_.swap(out);
    }
    std::vector<Vec3> moved(newN, Vec3::Zero());
    for (int i = 0; i < oldN && i < static_cast<int>(positionAtBuild_.size()); ++i)
        if (oldToNew[i] >= 0) moved[oldToNew[i]] = positionAtBuild_[i];
    positionAtBuild_.swap(moved);
}

std::size_t ParticleParticleNeighborList::bytes() const {
    return (offsets_.capacity() + neighbors_.capacity() + touchingOffsets_.capacity()) * sizeof(int) +
           history_.bytes() + bridgeVolume_.capacity() * sizeof(double) + positionAtBuild_.capacity() * sizeof(Vec3) +
           buildBufferBytes();
}

std::size_t ParticleParticleNeighborList::buildBufferBytes() const {
    std::size_t bytes = 0;
    for (const BuildBlock& b : blocks_)
        bytes += (b.neighbors.capacity() + b.slotSource.capacity() + b.row.capacity()) * sizeof(int) +
                 b.bridgeVolume.capacity() * sizeof(double);
    return bytes;
}

}  // namespace dem
