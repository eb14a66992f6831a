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
    // The slabs must have one slab per rank of the communicator (InputError otherwise).
    GhostExchange(Communicator communicator, SlabDecomposition slabs);

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
    // lies within haloWidth of this rank's slab, and records what this rank
    // sends to whom for updateGhosts.  Requires no ghosts.  Collective.
    void appendGhosts(ParticleStore& particles, double haloWidth);

    // After the pair list was built over owned + ghost particles: gives every
    // listed pair and every owned particle's wall contacts the stashed history
    // of the same global ids, then empties the stash.  Local.
    void restoreHistory(const ParticleStore& particles, ParticleParticleNeighborList& pairs,
                        ParticleWallContacts& walls);

    // Copies position, velocity and spin of the owners into the ghosts (every
    // step between list builds).  Collective.
    void updateGhosts(ParticleStore& particles) const;

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
    // Particles this rank has sent to other ranks by migrate() so far.
    std::size_t migratedCount() const { return migrated_; }

private:
    Communicator communicator_;
    SlabDecomposition slabs_;
    std::size_t ghostCount_ = 0;
    std::size_t migrated_ = 0;
    std::vector<std::vector<int>> sendList_;  // per rank: owned indices sent as ghosts
    std::vector<std::size_t> receiveCount_;   // per rank: ghosts received from it
    std::vector<PairRecord> pairStash_;
    std::vector<WallRecord> wallStash_;
};

}  // namespace dem
