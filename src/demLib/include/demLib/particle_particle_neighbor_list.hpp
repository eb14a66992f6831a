#pragma once
// Particle-particle broad search: a linked-cell grid feeding a half Verlet list
// (pairs i < j) with a skin, rebuilt when some particle has moved more than half
// the skin since the last build.  Per-pair state (contact history, liquid
// bridges) lives in arrays parallel to the list and is carried over at rebuild.
#include <cstdint>
#include <vector>

#include "demLib/contact_law.hpp"
#include "demLib/particle_store.hpp"

namespace dem {

// What a pair remembers between steps beyond the contact law's own history.
struct PairState {
    ContactHistory contact;
    double bridgeVolume = 0.0;  // liquid held by a capillary bridge (0: none)
};

class ParticleParticleNeighborList {
public:
    // skin: absolute distance added to the contact range; extraRange: extra
    // interaction range beyond contact (capillary debonding distance).
    void setRanges(double skin, double extraRange);
    double skin() const { return skin_; }
    double extraRange() const { return extraRange_; }

    bool needsRebuild(const ParticleStore& particles) const;

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
    std::vector<PairState>& state() { return state_; }
    const std::vector<PairState>& state() const { return state_; }
    const std::vector<Vec3>& positionsAtBuild() const { return positionAtBuild_; }
    std::size_t pairCount() const { return neighbors_.size(); }
    long buildCount() const { return buildCount_; }

    // Restart support: the list is a pure function of the positions at the last
    // build, so restoring those and rebuilding reproduces it exactly.
    void restore(const ParticleStore& particles, const std::vector<Vec3>& positionAtBuild,
                 long buildCount);
    // Installs saved pair state for pair (i, j), i < j, after restore().
    bool setState(int i, int j, const PairState& s);

    std::size_t bytes() const;

private:
    void buildFrom(const ParticleStore& particles, const std::vector<Vec3>& positions,
                   std::size_t listedRows = static_cast<std::size_t>(-1));

    double skin_ = 0.0;
    double extraRange_ = 0.0;
    std::vector<int> offsets_{0};
    std::vector<int> neighbors_;
    std::vector<PairState> state_;
    std::vector<Vec3> positionAtBuild_;
    long buildCount_ = 0;
};

}  // namespace dem
