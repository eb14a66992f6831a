#pragma once
// MPI domain decomposition of a Simulation: migration of owned particles
// between ranks, a layer of ghost particles (copies of other ranks' particles
// within the halo of this rank's slab) and contact history that follows the
// global particle ids across ranks.  docs/engine.md, "Domain decomposition".
//
// Storage: the ParticleStore holds the owned particles first, then the
// ghosts (ghostCount() of them, grouped by sending rank in rank order).  Ghosts
// are partners in the neighbour list, never first particles of a pair (so
// ghost-ghost pairs do not exist) and never integrated; the forces the kernel
// adds to them are discarded.  A pair straddling two slabs is computed by both
// ranks, each keeping the force on its own particle: no reverse communication,
// and both copies of its history evolve from the same data.
//
// Between neighbour-list builds only ghost positions, velocities and spins
// travel (updateGhosts); at a build the ghosts are dropped, particles migrate
// to the rank owning their centre, and the ghost layer is built again.  Pair
// and wall contact history survive this because they are taken off the lists
// into a stash keyed by global ids (dropGhosts), travel with migrating
// particles, and are put back by ids once the new list exists (restoreHistory).
#include <cstdint>
#include <vector>

#include "demLib/communicator.hpp"
#include "demLib/domain_decomposition.hpp"
#include "demLib/particle_particle_neighbor_list.hpp"
#include "demLib/particle_store.hpp"
#include "demLib/particle_wall_contacts.hpp"

namespace dem {

class GhostExchange {
public:
    // max/mean owned beyond which rebalanceIfNeeded re-cuts the slabs.
    static constexpr double defaultRebalanceThreshold = 1.10;

    // The slabs must have one slab per rank of the communicator (InputError
    // otherwise).  rebalanceThreshold: see setRebalanceThreshold.
    GhostExchange(Communicator communicator, SlabDecomposition slabs,
                  double rebalanceThreshold = defaultRebalanceThreshold);

    const Communicator& communicator() const { return communicator_; }
    const SlabDecomposition& slabs() const { return slabs_; }
    int rank() const { return communicator_.rank(); }

    std::size_t ghostCount() const { return ghostCount_; }
    std::size_t ownedCount(const ParticleStore& particles) const { return particles.size() - ghostCount_; }
    // Whether this rank owns a particle centred at x.
    bool owns(const Vec3& x) const { return slabs_.ownerOf(x, rank()) == rank(); }

    // Takes the pair and wall contact history of the owned particles off the
    // lists into the id-keyed stash, removes the ghosts and empties both lists.
    // Local; may be called again before the next restoreHistory (the stash grows).
    void dropGhosts(ParticleStore& particles, ParticleParticleNeighborList& pairs, ParticleWallContacts& walls);

    // Sends every owned particle whose centre left this rank's slab to the rank
    // owning it, with the stashed history of its pairs and wall contacts;
    // appends the particles received.  Requires no ghosts.  Collective.
    // Returns the number of particles that left.
    std::size_t migrate(ParticleStore& particles);

    // Appends, as ghosts, copies of the particles of other ranks whose centre
    // lies within their own radius + reachBeyondRadius of this rank's slab,
    // and records what this rank sends to whom for updateGhosts.  Requires no
    // ghosts.  Collective.
    void appendGhosts(ParticleStore& particles, double reachBeyondRadius);

    // After the pair list was built over owned + ghost particles: gives every
    // listed pair and every owned particle's wall contacts the stashed history
    // of the same global ids, then empties the stash.  Local.
    void restoreHistory(const ParticleStore& particles, ParticleParticleNeighborList& pairs,
                        ParticleWallContacts& walls);

    // Copies position, velocity and spin of the owners into the ghosts (every
    // step between list builds).  Collective.
    void updateGhosts(ParticleStore& particles) const;

    // The rebuild test and the ghost update of one step in one round
    // (Communicator::exchangeKnownSizesAndAnyTrue): returns whether any rank
    // needs a rebuild (rebuildHere on some rank); when none does, the ghosts
    // got their owners' new state as from updateGhosts, else they are left
    // as they were (the rebuild replaces them).  Collective.
    bool updateGhostsUnlessRebuild(ParticleStore& particles, bool rebuildHere) const;

    // Stash entries (global ids; history defined for particle `first`).
    struct PairRecord {
        std::int64_t first, second;  // first < second
        PairState state;
    };
    struct WallRecord {
        std::int64_t particle;
        int wall, feature;
        ContactHistory history;
        double bridgeVolume;
    };
    std::size_t stashedPairs() const { return pairStash_.size(); }

    // Replaces the slabs (same rank count; the axis may change).  Requires no
    // ghosts; the next migrate() moves the particles.  Local: every rank must
    // be given the same slabs.
    void setSlabs(SlabDecomposition slabs);

    // What one rebalanceIfNeeded call found and did.
    struct RebalanceReport {
        bool recut = false;
        // Before any re-cut: the largest and the mean owned count over the
        // ranks, and max/mean of the balanced load (the counts, or the summed
        // weights when weights were given).  Zeros when balancing is disabled.
        std::int64_t maxOwned = 0;
        double meanOwned = 0.0;
        double imbalance = 0.0;
        std::vector<double> cuts;  // interior cuts after the call
        // After a re-cut and the migration that follows it: max/mean owned
        // (noteBalanceAfterMigration; 0 until then).
        double imbalanceAfter = 0.0;
        // With weights: whether they were given, and after a re-cut max/mean
        // of the summed weights under the new cuts (0 otherwise).
        bool weighted = false;
        double loadImbalanceAfter = 0.0;
    };
    // A threshold t >= 1: re-cut when max/mean load > t.  0 or +infinity
    // disables balancing (rebalanceIfNeeded then does no collective; all ranks
    // must hold the same setting).  Anything else throws InputError.
    void setRebalanceThreshold(double threshold);
    double rebalanceThreshold() const { return rebalanceThreshold_; }
    bool balancingEnabled() const { return rebalanceThreshold_ > 0.0 && rebalanceThreshold_ < 1e300; }

    // With no ghosts present (after dropGhosts, before migrate): the owned
    // counts of all ranks; if max/mean exceeds the threshold, new cuts along
    // the same axis from the owned positions (SlabDecomposition::balanced:
    // max/mean owned <= 1.01 + 2/mean after the migrate that must follow).
    // Costs two reductions when no re-cut is needed; a re-cut adds a few
    // rounds of small exchanges, bounded by the rank count.  Collective.
    RebalanceReport rebalanceIfNeeded(const ParticleStore& particles);
    // The same for the summed `weights`, one per owned particle (e.g. contact
    // counts; none on a rank that owns none): five reductions without a
    // re-cut.  Every rank must call the same one of the two.
    RebalanceReport rebalanceByWeight(const ParticleStore& particles, const std::vector<double>& weights);
    // Before particles are given to the ranks (a restart file's, held by the
    // rank that read it: `positions` there, none elsewhere): if the current
    // slabs would give them max/mean owned above the threshold, cuts balanced
    // by count over them, reported and counted as a re-cut.  A run continued
    // on another rank count then starts balanced instead of waiting for its
    // next list build.  Requires no ghosts; collective; does nothing with
    // balancing disabled or on one rank.
    RebalanceReport balanceUndistributed(const std::vector<Vec3>& positions);
    // Re-cuts so far, and the report of the latest rebalanceIfNeeded call.
    std::size_t recutCount() const { return recuts_; }
    const RebalanceReport& lastRebalance() const { return lastRebalance_; }
    // The report of the latest call that re-cut (front ends log it).
    const RebalanceReport& lastRecut() const { return lastRecut_; }
    // After the migrate() that follows a re-cut: records max/mean owned in
    // lastRecut().imbalanceAfter (two reductions).  Collective.
    void noteBalanceAfterMigration(const ParticleStore& particles);
    // Particles this rank has sent to other ranks by migrate() so far.
    std::size_t migratedCount() const { return migrated_; }

private:
    Communicator communicator_;
    SlabDecomposition slabs_;
    std::size_t ghostCount_ = 0;
    std::size_t migrated_ = 0;
    // The ghost updates to send (per rank), and the received ones into the ghosts.
    std::vector<std::vector<char>> packGhostUpdates(const ParticleStore& particles) const;
    void unpackGhostUpdates(ParticleStore& particles, const std::vector<std::vector<char>>& received) const;

    std::vector<std::vector<int>> sendList_;  // per rank: owned indices sent as ghosts
    std::vector<std::size_t> receiveCount_;   // per rank: ghosts received from it
    // Per rank: the bytes of a ghost update sent to it and received from it,
    // as of the last ghost build (kept when a rank drops its ghosts alone).
    std::vector<std::size_t> updateSendBytes_, updateReceiveBytes_;
    std::vector<PairRecord> pairStash_;
    std::vector<WallRecord> wallStash_;
    RebalanceReport rebalance(const ParticleStore& particles, const std::vector<double>& weights, bool weighted);
    // New cuts along the slabs' axis holding equal shares of `weights` (1 each
    // when empty) of the first n particles at `positions` (collective), counted
    // as a re-cut.
    void cutBalanced(const std::vector<Vec3>& positions, std::size_t n, const std::vector<double>& weights);
    double rebalanceThreshold_ = defaultRebalanceThreshold;
    std::size_t recuts_ = 0;
    RebalanceReport lastRebalance_;
    RebalanceReport lastRecut_;
};

}  // namespace dem
