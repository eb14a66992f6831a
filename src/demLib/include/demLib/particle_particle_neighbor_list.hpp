#pragma once
// Particle-particle broad search: a linked-cell grid feeding a half Verlet list
// (pairs i < j) with a skin, rebuilt when some particle has moved more than half
// the skin since the last build.  Per-pair state (contact history of touching
// pairs in a ContactHistoryPool, liquid bridge volumes in an array parallel to
// the list) is carried over at rebuild.
#include <cstdint>
#include <limits>
#include <vector>

#include "demLib/contact_history_pool.hpp"
#include "demLib/contact_law.hpp"
#include "demLib/liquid_bridges.hpp"
#include "demLib/particle_store.hpp"

namespace dem {

// What a pair remembers between steps beyond the contact law's own history.
struct PairState {
    ContactHistory contact;
    double bridgeVolume = 0.0;  // liquid held by a capillary bridge (0: none)
};

// Which parts of PairState a run keeps.  The list stores each part as its own
// array parallel to the pairs; a part that is off costs no memory and reads as
// zero: the rolling spring (rolled angle) exists only for the EPSD models, the bridge
// volume only with cohesion.  The tangential spring (shear) is always kept.
struct PairStateFields {
    bool rollingSpring = true;
    bool bridgeVolume = true;
    static PairStateFields forModels(RollingModel rolling, bool cohesion) {
        return {rolling == RollingModel::EPSD || rolling == RollingModel::EPSD2, cohesion};
    }
    bool operator==(const PairStateFields& o) const {
        return rollingSpring == o.rollingSpring && bridgeVolume == o.bridgeVolume;
    }
};

// Read-only view of the pair state as PairState values (absent parts zero),
// indexable like the pair list: for inspection, tests and restart files.
class PairStateView {
public:
    PairStateView(const ContactHistoryPool& history, const std::vector<double>& bridge)
        : history_(history), bridge_(bridge) {}
    std::size_t size() const { return history_.entries(); }
    PairState operator[](std::size_t k) const {
        PairState s;
        s.contact = history_.get(k);
        if (!bridge_.empty()) s.bridgeVolume = bridge_[k];
        return s;
    }
    class iterator {
    public:
        iterator(const PairStateView& v, std::size_t k) : v_(&v), k_(k) {}
        PairState operator*() const { return (*v_)[k_]; }
        iterator& operator++() {
            ++k_;
            return *this;
        }
        bool operator!=(const iterator& o) const { return k_ != o.k_; }

    private:
        const PairStateView* v_;
        std::size_t k_;
    };
    iterator begin() const { return iterator(*this, 0); }
    iterator end() const { return iterator(*this, size()); }

private:
    const ContactHistoryPool& history_;
    const std::vector<double>& bridge_;
};

class ParticleParticleNeighborList {
public:
    // skin: absolute distance added to the contact range; extraRange: extra
    // interaction range beyond contact (capillary debonding distance).
    void setRanges(double skin, double extraRange);
    // Pairs that cannot touch before the next build (gap >= skin) but lie
    // within the extra range are listed only where a liquid bridge could hold
    // at liquid per unit weight `liquidPerWeightLimit` (λ*_k <= limit, see
    // bridgeStabilityThreshold): in a polydisperse wet bed the extra range of
    // the largest bridge otherwise lists about three times more pairs.
    // Infinity (the default) lists every pair within the extra range.
    void setBridgeListing(const LiquidBridgeSettings& settings, double liquidPerWeightLimit);
    double bridgeListingLimit() const { return bridgeListingLimit_; }
    // Lists again from the positions at the last build (after a change of the
    // bridge listing), keeping the pair state; not counted as a build.
    void relistAtBuildPositions(const ParticleStore& particles,
                                std::size_t listedRows = static_cast<std::size_t>(-1));
    // Which pair-state parts to keep (default: all).  Changing them drops or
    // zero-fills the affected arrays.
    void setStateFields(const PairStateFields& fields);
    const PairStateFields& stateFields() const { return fields_; }
    double skin() const { return skin_; }
    double extraRange() const { return extraRange_; }

    // True when a particle has moved more than skin/2 since the last build
    // (then a pair may have come into range unseen), or the count changed.
    bool needsRebuild(const ParticleStore& particles) const;
    // (skin/2)^2: the squared displacement needsRebuild tests against.
    double rebuildDisplacementSquared() const { return 0.25 * skin_ * skin_; }

    // Rebuilds the list from the current positions; pair state of pairs that
    // stay neighbours is kept.  Deterministic for any thread count.
    // listedRows: only particles 0 .. listedRows-1 are first particles of
    // pairs (default: all).  With MPI ghosts stored after the owned particles,
    // listedRows = owned count: ghosts are partners only, ghost-ghost pairs
    // are not listed.
    void build(const ParticleStore& particles, std::size_t listedRows = static_cast<std::size_t>(-1));

    // Particles were reordered or removed: oldToNew[i] is the new index of old
    // particle i, or -1.  Keeps the pair state of surviving pairs.
    void remap(const std::vector<int>& oldToNew);

    // The pair list, CSR by first particle: for i, entries [offsets[i], offsets[i+1]).
    const std::vector<int>& offsets() const { return offsets_; }
    const std::vector<int>& neighbors() const { return neighbors_; }
    // Pair state: contact history of the pairs in contact, and the bridge
    // volume per listed pair (empty when stateFields() leaves it out).
    ContactHistoryPool& history() { return history_; }
    const ContactHistoryPool& history() const { return history_; }
    std::vector<double>& bridgeVolume() { return bridgeVolume_; }
    const std::vector<double>& bridgeVolume() const { return bridgeVolume_; }
    PairStateView state() const { return PairStateView(history_, bridgeVolume_); }
    const std::vector<Vec3>& positionsAtBuild() const { return positionAtBuild_; }
    // Pairs in contact at the last build, as a prefix over the rows (like
    // offsets(): rows before i hold touchingOffsets()[i] of them); the force
    // loop weighs its split of the rows between threads with it.  Empty after
    // remap() until the next build.  A function of the positions at build, so
    // a restart reproduces it.
    const std::vector<int>& touchingOffsets() const { return touchingOffsets_; }
    std::size_t pairCount() const { return neighbors_.size(); }
    long buildCount() const { return buildCount_; }
    // Changes whenever the entries change meaning (build, relist, remap,
    // restore): data kept per entry elsewhere is stale then.
    long version() const { return version_; }

    // Restart support: the list is a pure function of the positions at the last
    // build (and the bridge listing limit, set before), so restoring those and
    // rebuilding reproduces it exactly.
    // listedRows as in build() (the owned particles of an MPI rank).
    void restore(const ParticleStore& particles, const std::vector<Vec3>& positionAtBuild,
                 long buildCount, std::size_t listedRows = static_cast<std::size_t>(-1));
    // Installs saved pair state for pair (i, j), i < j, after restore(); parts
    // the list does not keep are ignored.
    bool setState(int i, int j, const PairState& s);
    // The same for list entry k (offsets()/neighbors() order).
    void setStateAt(std::size_t k, const PairState& s);

    // Memory held, including the build buffers kept for the next build.
    std::size_t bytes() const;
    std::size_t buildBufferBytes() const;

private:
    void buildFrom(const ParticleStore& particles, const std::vector<Vec3>& positions,
                   std::size_t listedRows = static_cast<std::size_t>(-1));

    // What one thread lists at a build (its block of rows), kept between
    // builds so that a rebuild allocates nothing new in the steady state.
    struct BuildBlock {
        std::vector<int> neighbors;
        std::vector<int> slotSource;  // see ContactHistoryPool::repack
        std::vector<double> bridgeVolume;
        std::vector<int> row;  // neighbours of one particle, sorted
    };
    std::vector<BuildBlock> blocks_;

    double skin_ = 0.0;
    double extraRange_ = 0.0;
    LiquidBridgeSettings bridgeSettings_;
    double bridgeListingLimit_ = std::numeric_limits<double>::infinity();
    std::vector<int> offsets_{0};
    std::vector<int> neighbors_;
    std::vector<int> touchingOffsets_;
    PairStateFields fields_;
    ContactHistoryPool history_;
    std::vector<double> bridgeVolume_;
    std::vector<Vec3> positionAtBuild_;
    long buildCount_ = 0;
    long version_ = 0;
};

}  // namespace dem
