#pragma once
// The per-step contact force loop over particle pairs and particle-wall
// contacts.  The contact law (rolling model, cohesion) is chosen once per run by
// makeContactForceKernel(): the loop is a class template specialised with
// `if constexpr`, so there is one virtual call per step and none per contact.
#include <memory>
#include <vector>

#include "demLib/capillary_force.hpp"
#include "demLib/contact_law.hpp"
#include "demLib/interaction_properties.hpp"
#include "demLib/particle_particle_neighbor_list.hpp"
#include "demLib/particle_store.hpp"
#include "demLib/particle_wall_broad_search.hpp"
#include "demLib/particle_wall_contacts.hpp"
#include "demLib/wall.hpp"

namespace dem {

enum class CohesionModel { None, Capillary };

struct ForceFieldSettings {
    RollingModel rolling = RollingModel::None;
    CohesionModel cohesion = CohesionModel::None;
    CapillaryParameters capillary;
    // Multiplies every capillary force: the coarse-grain correction l^κ of the
    // paper's eq 9 (1 for original-size particles).
    double capillaryForceScale = 1.0;
    // Particle-wall liquid bridges (capillaryForceSphereWall); walls are then
    // searched out to ParticleWallContacts::bridgeReach() beyond contact.
    bool wallBridges = false;
    // Pair contacts evaluated in batches in vector lanes (contact_law_batch.hpp).
    // false runs the scalar loop instead: the reference the batched loop is
    // tested against; both give bitwise the same results.
    bool vectorizedPairLaw = true;
};

struct ContactStatistics {
    std::size_t touchingPairs = 0;   // particle-particle pairs with overlap > 0
    std::size_t wallContacts = 0;    // particle-wall contacts with overlap > 0
    std::size_t bridges = 0;         // particle-particle capillary bridges holding liquid
    std::size_t wallBridges = 0;     // particle-wall capillary bridges holding liquid
    double releasedLiquid = 0.0;     // volume of bridges that broke this step
};

class ContactForceKernel {
public:
    virtual ~ContactForceKernel() = default;
    // Adds contact forces and torques to particles.force / particles.torque
    // (which hold body and external forces on entry) and updates the history.
    // Bridges that break (gap beyond eq 5, or a wall bridge whose wall left the
    // search reach) are emptied; their volume is returned in releasedLiquid.
    virtual ContactStatistics compute(ParticleStore& particles, ParticleParticleNeighborList& pairs,
                                      ParticleWallContacts& wallContacts, const std::vector<Wall>& walls,
                                      const ParticleWallCandidates& wallCandidates,
                                      const InteractionTable& interactions, double time, double dt) = 0;
    const ForceFieldSettings& settings() const { return settings_; }

protected:
    explicit ContactForceKernel(const ForceFieldSettings& s) : settings_(s) {}
    ForceFieldSettings settings_;
};

std::unique_ptr<ContactForceKernel> makeContactForceKernel(const ForceFieldSettings& settings);

}  // namespace dem
