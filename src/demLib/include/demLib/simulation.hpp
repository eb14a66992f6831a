#pragma once
// The DEM engine's front door: configuration structs in, state and fields out.
// A Simulation owns the particles, the walls, the contact lists and the force
// kernel, and advances them with velocity Verlet.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demLib/axis_aligned_box.hpp"
#include "demLib/contact_force_kernel.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/insertion.hpp"
#include "demLib/interaction_properties.hpp"
#include "demLib/liquid_bridges.hpp"
#include "demLib/particle_particle_neighbor_list.hpp"
#include "demLib/particle_store.hpp"
#include "demLib/particle_wall_contacts.hpp"
#include "demLib/wall.hpp"

namespace dem {

// What the slabs of a domain decomposition balance when they are re-cut.
enum class LoadBalanceWeight {
    Particles,  // each rank's owned particles
    Work,       // their work: per particle 1 + its listed pairs + its wall contacts
    Time        // each rank's measured busy time in step() since the last check, shared
                // equally by its owned particles (not reproducible run to run)
};

struct SimulationSettings {
    double timeStep = 1e-5;
    Vec3 gravity = Vec3(0.0, 0.0, -9.81);
    ForceFieldSettings forces;
    // Which pairs hold liquid bridges and how the water is shared (capillary only).
    LiquidBridgeSettings bridges;
    // With capillary bridges, pairs that cannot touch before the next list
    // build are listed only where a bridge could hold at this multiple of the
    // last distribution's liquid per unit weight (see updatePairList); 0 lists
    // every pair within the range of the largest bridge.  The results do not
    // depend on it (a distribution beyond the limit lists again), the cost does.
    double bridgeListingMargin = 1.5;
    // Verlet skin as a fraction of the largest particle diameter.
    double skinFraction = 0.2;
    // The time step must not exceed this fraction of the Rayleigh time of the
    // smallest particle (LIGGGHTS warns above 0.2) unless explicitly allowed.
    double maxRayleighFraction = 0.2;
    bool allowLargeTimeStep = false;
    // ... and not exceed this fraction of the Hertz collision time of two of the
    // smallest particles meeting head-on at twice impactVelocity (LIGGGHTS'
    // fix check/timestep/gran estimate).
    double maxHertzFraction = 0.1;
    double impactVelocity = 1.0;  // [m/s], the largest speed expected in the run
    // ... and, with capillary cohesion, not exceed this fraction of the step at
    // which the explicit integration of the smallest particle, pressed by its
    // bridges into the largest (as many as fit, at least six), turns unstable (contact_stability.hpp):
    // beyond it a wet bed at rest rattles.
    // The default 0.9 leaves room for the bed's weight, which the cluster does
    // not carry: on the full die fill's 22 mm bed the stable step of the bed
    // itself (bed_stability.hpp) is 5 % below the cluster's.
    double maxCapillaryClusterFraction = 0.9;
    // Systems of at least this many particles are sorted in space now and then
    // (see Simulation::updatePairList); smaller ones keep their order.
    std::size_t spatialSortMinParticles = 4096;
    // Particles whose centre leaves this box are removed and counted as lost.
    std::optional<AxisAlignedBox> domain;
    // With a domain decomposition: what a re-cut of the slabs balances, and the
    // max/mean of that load over the ranks beyond which the slabs are re-cut
    // (at a list build; GhostExchange::rebalanceIfNeeded).  Work counts, per
    // owned particle, 1 plus its pairs listed at the last build (a pair of two
    // owned particles half at each, a pair with a ghost whole, as this rank
    // computes it) plus its wall contacts: the pair walk is most of a step.
    // Time weighs each rank's particles by the wall time it spent in step()
    // since the last check, less its time in the DEM's collectives (waiting
    // for the other ranks): what each rank's slab costs, whatever makes it
    // cost (pairs, bridges, walls, a slower core).
    LoadBalanceWeight loadBalanceWeight = LoadBalanceWeight::Particles;
    double loadBalanceThreshold = GhostExchange::defaultRebalanceThreshold;
    // The axis the slabs are cut across (0 = x, 1 = y, 2 = z); -1: the longest
    // side of the domain box (docs/performance.md: the die filling cut across
    // the shoe's motion ran no faster on 2 ranks than cut along it).
    int decompositionAxis = -1;
    // Name of the input the settings came from, for error messages.
    std::string source = "demLib";
};

struct StepStatistics {
    ContactStatistics contacts;
    std::size_t lostThisStep = 0;
};

// Capillary liquid bookkeeping; volumes in m^3.
// total = particle bridges + wall bridges + pool, always (to rounding).
struct LiquidState {
    double totalVolume = 0.0;   // water added, conserved
    double poolVolume = 0.0;    // not held by any bridge (redistributed at list updates)
    double waterContent = 0.0;  // mass of water / mass of dry solid
    std::size_t bridgeCount = 0;      // particle-particle bridges
    std::size_t wallBridgeCount = 0;  // particle-wall bridges (option wallBridges)
};

// What a front end reports of the whole run (summary lines, progress): each
// particle, pair and wall contact once, whatever the decomposition.
struct RunTotals {
    std::size_t particles = 0;
    double kineticEnergy = 0.0;     // [J]
    std::size_t touchingPairs = 0;  // particle-particle pairs in contact at the last force computation
    std::size_t wallContacts = 0;   // particle-wall contacts in contact then
    std::size_t lost = 0;           // particles lost so far ...
    double lostMass = 0.0;          // ... and their mass [kg]
    // Force of the particles on each wall [N]: the mean over the steps since
    // Simulation::restartWallForceMeans() (the impulse they gave the wall over
    // that time / the time), or the last step's when no step was made since.
    std::vector<Vec3> wallForces;
    // Mean number of touching contacts per particle.
    double coordinationNumber() const { return particles == 0 ? 0.0 : 2.0 * touchingPairs / particles; }
};

class Simulation {
public:
    // Particles are sorted in space at every spatialSortInterval-th list build.
    static constexpr long spatialSortInterval = 16;
    // LoadBalanceWeight::Time re-cuts at a list build once the busiest rank has
    // been busy this long since the last timed check: shorter spans time noise.
    static constexpr double minimumTimedSeconds = 0.05;

    Simulation(SimulationSettings settings, std::vector<Material> materials, InteractionTable interactions,
               std::vector<Wall> walls);

    // Adds particles (positions, radii) of one material with one velocity.
    // Throws InputError for a non-positive radius, a particle inside a wall, or
    // a time step too large for the new particles' contact stiffness.
    void insert(const std::vector<InsertedParticle>& particles, int materialIndex, const Vec3& velocity,
                const std::string& context = "insertion");

    // Sets the water content w (mass of water / mass of dry solid) of the
    // particles present now; the liquid is spread over bridges at the next step.
    void setWaterContent(double w);

    void step(long steps = 1);

    // MPI domain decomposition (docs/engine.md, "Domain decomposition"): from
    // now on this rank owns the particles in its slab and holds ghosts of its
    // neighbours' particles after them.  Set before any particle is inserted;
    // every rank then calls insert() with the same particles (ids are given
    // the same on all ranks, each keeps those it owns) and step() the same
    // number of times.  Capillary bridges share the run's water over all
    // ranks (liquid_bridges_over_ranks.hpp); restart files are written
    // gathered by rank 0 and can be read on any rank count (writeRestart).
    void setDecomposition(std::shared_ptr<GhostExchange> decomposition);
    const GhostExchange* decomposition() const { return decomposition_.get(); }
    // Particles integrated by this rank: all of them without a decomposition,
    // else the owned ones, stored first (particles().size() - ghosts).
    std::size_t ownedCount() const {
        return decomposition_ ? decomposition_->ownedCount(particles_) : particles_.size();
    }

    double time() const { return time_; }
    long stepCount() const { return step_; }
    double timeStep() const { return settings_.timeStep; }
    const SimulationSettings& settings() const { return settings_; }
    ParticleStore& particles() { return particles_; }
    const ParticleStore& particles() const { return particles_; }
    const std::vector<Wall>& walls() const { return walls_; }
    const std::vector<Material>& materials() const { return materials_; }
    const InteractionTable& interactions() const { return interactions_; }
    const ParticleParticleNeighborList& pairList() const { return pairs_; }
    // List builds whose liquid distribution exceeded the bridge listing limit
    // and were listed again without it (see SimulationSettings::bridgeListingMargin).
    long bridgeRelistCount() const { return bridgeRelists_; }
    const ParticleWallContacts& wallContacts() const { return wallContacts_; }
    const StepStatistics& lastStep() const { return last_; }
    // With a decomposition: the run's values (all ranks) as of the last list
    // build; liquidOverRanks() gives the current ones.
    const LiquidState& liquid() const { return liquid_; }
    // The liquid state now, summed over the ranks (a pair across a slab face
    // counted once).  Collective with a decomposition; liquid() without one.
    LiquidState liquidOverRanks() const;
    std::size_t lostCount() const { return lost_; }
    double lostMass() const { return lostMass_; }
    std::int64_t nextId() const { return nextId_; }

    // Liquid volume held by all bridges, particle-particle and particle-wall
    // (plus liquid().poolVolume it is the conserved total).  With a
    // decomposition this and the two below are collectives over all ranks.
    double liquidInBridges() const;
    // The part of liquidInBridges() held by particle-wall bridges.
    double liquidInWallBridges() const;
    // Mean number of particle-particle capillary bridges per particle
    // (liquid coordination number z = 2 bridges / N; wall bridges not counted).
    double liquidCoordinationNumber() const;
    // Mean number of touching contacts per particle.
    double coordinationNumber() const;
    // Force of the particles on each wall in the last step (contacts and
    // liquid bridges; walls in the order of walls()) [N].  With a
    // decomposition: of this rank's particles.
    std::vector<Vec3> wallForces() const;
    // Starts the means of the walls' forces over the steps to come (RunTotals::
    // wallForces): a front end calls it after each summary line.  A force that
    // alternates from step to step (CDT's rolling torque in a bed at rest) is
    // then logged as its mean, not as the value at one phase.
    void restartWallForceMeans();

    // The run's totals now.  Collective with a decomposition (sums in rank
    // order); without one the values of this simulation.
    RunTotals totalsOverRanks() const;

    // Largest time step the settings accept for the particles present, and the
    // limits it is the smallest of.
    double maxAllowedTimeStep() const;
    struct TimeStepLimits {
        double rayleigh;   // maxRayleighFraction x smallest Rayleigh time
        double hertz;      // maxHertzFraction x smallest Hertz collision time
        double capillary;  // maxCapillaryClusterFraction x stable step of a wet grain (infinite when dry)
        double smallest() const { return std::min(rayleigh, std::min(hertz, capillary)); }
    };
    TimeStepLimits timeStepLimits(const std::vector<InsertedParticle>& adding = {}, int materialIndex = 0) const;
    // Throws InputError naming the limits, `context` and the settings' source
    // when the time step exceeds them (unless allowLargeTimeStep); insert() and
    // readRestart() call it.
    void requireAllowedTimeStep(const std::string& context) const;

    // Restart: the whole state, contact history included.  The file's attributes and
    // each dataset carry checksums; readRestart throws DamagedFileError when one does not
    // match, and returns false for a file written before checksums (read unchecked).
    // With a decomposition both are collectives: rank 0 gathers the ranks'
    // particles and writes one file (the same format), and reads a file of any
    // rank count (or a serial one) into a simulation without particles, giving
    // each rank its particles; on the rank count that wrote it the run
    // continues bitwise as it would have.
    void writeRestart(const std::string& path) const;
    bool readRestart(const std::string& path);

private:
    // Removes particles outside the domain box (or not finite); knownNoneLost:
    // the drift has just tested every particle and found none (no pass here).
    void removeLostParticles(bool knownNoneLost = false);
    void updatePairList();
    // Per owned particle, its work at the last list build (LoadBalanceWeight::Work).
    std::vector<double> ownedWork() const;
    // This rank's seconds in step() less those in the DEM's collectives, so far
    // (the step under way included).
    double busySecondsSoFar() const;
    void rebuildWallCandidates();
    double redistributeLiquid(double wallReach);  // returns λ, the liquid per unit weight
    // Walls within `reach` of each particle's surface at the current positions:
    // records (sorted, history of the current list carried) and their gaps.
    void wallBridgeCandidates(double reach, std::vector<WallContactRecord>& records,
                              std::vector<double>& gaps) const;
    // forcesReset: F = m g + F_external and T = 0 are set already (by the drift).
    void computeForces(bool forcesReset);
    // Moves each wall under load (WallMotion::addLoad) by one step under the
    // particles' force on it (summed over ranks) and gravity.
    void advanceWallLoads();
    // Adds this step's force of this rank's particles on each wall to the sums
    // behind RunTotals::wallForces.
    void accumulateWallForces();
    void requireNoDecomposition(const std::string& what) const;
    // Per list entry: 1 where this rank accounts for the pair (every pair of
    // two owned particles; a pair with a ghost on the rank owning the smaller
    // id), so that sums over ranks count each pair once.
    std::vector<std::uint8_t> countedPairs() const;
    // This rank's share of the liquid held by particle (`pairs`) and wall
    // (`walls`) bridges, each bridge on one rank only, and their counts.
    struct HeldLiquid {
        double volume = 0.0;
        std::int64_t pairBridges = 0, wallBridges = 0;
    };
    HeldLiquid heldLiquidHere(bool pairs, bool walls) const;
    // Runs `check`; with a decomposition a failure on any rank is a failure
    // on all (with the failing rank's message where it is known), so that no
    // rank goes on to a collective the others never reach.
    template <class Check>
    void requireOnAllRanks(const Check& check) const;
    // Restart with a decomposition: rank 0 reads and hands out (simulation_restart.cpp).
    bool readRestartDecomposed(const std::string& path);
    // Time, counts, liquid and list settings of a restart file's header.
    void applyRestartScalars(const std::vector<double>& header);

    SimulationSettings settings_;
    std::vector<Material> materials_;
    InteractionTable interactions_;
    std::vector<Wall> walls_;
    ParticleStore particles_;
    ParticleParticleNeighborList pairs_;
    ParticleWallContacts wallContacts_;
    ParticleWallCandidates wallCandidates_;
    std::unique_ptr<ContactForceKernel> kernel_;
    double time_ = 0.0;
    long step_ = 0;
    std::int64_t nextId_ = 0;
    std::size_t lost_ = 0;
    double lostMass_ = 0.0;
    bool forcesValid_ = false;
    // Busy time (LoadBalanceWeight::Time): seconds in finished step() calls less
    // their collectives; the clock and collective seconds where the call under
    // way began (inStep_); the busy seconds at the last balance check.
    double busySeconds_ = 0.0;
    bool inStep_ = false;
    double stepStartSeconds_ = 0.0, stepStartCollectiveSeconds_ = 0.0;
    double busySecondsAtCheck_ = 0.0;
    bool timedCheckDone_ = false;
    LiquidState liquid_;
    std::unique_ptr<LiquidBridgeNetwork> liquidNetwork_;
    double largestBridge_ = 0.0;
    // Liquid per unit weight up to which the next list build lists pairs
    // beyond touching reach (bridgeListingMargin x the last distribution's;
    // infinity: all within the bridge range).  See updatePairList.
    double bridgeListingLimit_ = std::numeric_limits<double>::infinity();
    long bridgeRelists_ = 0;
    StepStatistics last_;
    std::vector<Vec3> wallForceSum_;  // sum over the steps since restartWallForceMeans()
    long wallForceSteps_ = 0;
    std::shared_ptr<GhostExchange> decomposition_;  // null: serial run
};

}  // namespace dem
