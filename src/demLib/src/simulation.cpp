#include "demLib/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "demLib/cell_bins.hpp"
#include "demLib/compensated_sum.hpp"
#include "demLib/constants.hpp"
#include "demLib/contact_stability.hpp"
#include "demLib/error.hpp"
#include "demLib/integrator.hpp"
#include "demLib/liquid_bridges_over_ranks.hpp"
#include "demLib/parallel.hpp"
#include "demLib/particle_reordering.hpp"

namespace dem {

namespace {

std::string formatVec(const Vec3& v) {
    std::ostringstream s;
    s.precision(6);
    s << "(" << v.x() << " " << v.y() << " " << v.z() << ")";
    return s.str();
}

// Throws InputError when settings.timeStep exceeds `allowed` (unless the
// settings allow a large time step), naming both values.
void requireTimeStepBelow(const SimulationSettings& settings, const Simulation::TimeStepLimits& limits,
                          const std::string& context) {
    const double allowed = limits.smallest();
    if (settings.timeStep > allowed && !settings.allowLargeTimeStep) {
        std::ostringstream s;
        s << settings.source << ": keyword 'timeStep' = " << settings.timeStep << " s is too large for the contact "
          << "stiffness after " << context << ": " << settings.maxRayleighFraction
          << " x the Rayleigh time of the smallest particle allows " << limits.rayleigh << " s, "
          << settings.maxHertzFraction << " x its Hertz collision time at " << settings.impactVelocity
          << " m/s (keyword 'impactVelocity') allows " << limits.hertz << " s";
        if (std::isfinite(limits.capillary))
            s << ", " << settings.maxCapillaryClusterFraction << " x the stable step of the smallest particle "
              << "pressed by capillary bridges into the largest (twelve around an equal one, at least six; keyword "
              << "'maxCapillaryClusterFraction'; "
              << "beyond it a wet bed rattles) allows " << limits.capillary << " s";
        s << "; expected timeStep <= " << allowed
          << " (or set 'allowLargeTimeStep true' to override, at your own risk)";
        throw InputError(s.str());
    }
}

// Two particles placed deep inside each other (the same position given twice, a
// list with a typo) would be shot apart by a huge force, or lost: the first pair
// overlapping by more than half the smaller radius is refused.  Beds taken from
// settled runs overlap less: about one per cent of the radius under 1 g, up to 16 %
// for the small grains of the polydisperse bench bed pressed under 4 g.  New particles
// are checked against each other and against those already in the simulation, in the
// linked cells the neighbour search uses (cell_bins).
void requireNoDeepOverlap(const std::vector<InsertedParticle>& inserted, const ParticleStore& existing,
                          const std::string& context) {
    if (inserted.empty()) return;
    // Existing particles first, then the new ones: index i >= before is new particle i - before.
    const std::size_t before = existing.size();
    std::vector<Vec3> position(existing.position);
    std::vector<double> radius(existing.radius);
    for (const InsertedParticle& q : inserted) {
        position.push_back(q.position);
        radius.push_back(q.radius);
    }
    const CellBins bins = binIntoCells(position, 2.0 * *std::max_element(radius.begin(), radius.end()));
    for (std::size_t i = before; i < position.size(); ++i) {
        forEachInNeighbouringCells(bins, static_cast<int>(i), [&](int neighbour) {
            const std::size_t j = static_cast<std::size_t>(neighbour);
            if (j >= i) return;  // itself, or a later new one (checked from there)
            const double overlap = radius[i] + radius[j] - (position[i] - position[j]).norm();
            if (!(overlap > 0.5 * std::min(radius[i], radius[j]))) return;
            throw InputError(context + ": particle " + std::to_string(i - before) + " at " + formatVec(position[i]) +
                             " (radius " + std::to_string(radius[i]) + ") overlaps " +
                             (j >= before ? "particle " + std::to_string(j - before) + " of the same insertion"
                                          : std::string("a particle already in the simulation")) +
                             " at " + formatVec(position[j]) + " by " + std::to_string(overlap) +
                             " m; expected particles at most half the smaller radius into each other");
        });
    }
}

}  // namespace

Simulation::Simulation(SimulationSettings settings, std::vector<Material> materials,
                       InteractionTable interactions, std::vector<Wall> walls)
    : settings_(std::move(settings)),
      materials_(std::move(materials)),
      interactions_(std::move(interactions)),
      walls_(std::move(walls)) {
    const std::string& src = settings_.source;
    if (!(settings_.timeStep > 0.0) || !std::isfinite(settings_.timeStep))
        throw InputError(src + ": keyword 'timeStep' expects a positive number of seconds");
    if (!(settings_.skinFraction > 0.0))
        throw InputError(src + ": keyword 'skinFraction' expects a positive fraction of the largest diameter");
    if (!(settings_.maxRayleighFraction > 0.0))
        throw InputError(src + ": keyword 'maxRayleighFraction' expects a positive number");
    if (!(settings_.maxCapillaryClusterFraction > 0.0))
        throw InputError(src + ": keyword 'maxCapillaryClusterFraction' expects a positive number");
    if (materials_.empty()) throw InputError(src + ": no material defined; expected at least one in 'materials'");
    for (const Material& m : materials_) validateMaterial(m);
    interactions_.requireComplete(materials_);
    for (const Wall& w : walls_)
        if (w.materialIndex < 0 || w.materialIndex >= static_cast<int>(materials_.size()))
            throw InputError(src + ": wall '" + w.name + "' has no valid material");
    if (settings_.forces.cohesion == CohesionModel::Capillary)
        validateCapillaryParameters(settings_.forces.capillary, src);
    kernel_ = makeContactForceKernel(settings_.forces);
    pairs_.setStateFields(PairStateFields::forModels(settings_.forces.rolling,
                                                     settings_.forces.cohesion != CohesionModel::None));
}

void Simulation::insert(const std::vector<InsertedParticle>& inserted, int materialIndex, const Vec3& velocity,
                        const std::string& context) {
    if (materialIndex < 0 || materialIndex >= static_cast<int>(materials_.size()))
        throw InputError(context + ": material index " + std::to_string(materialIndex) + " out of range");
    std::vector<WallContact> touching;
    for (std::size_t k = 0; k < inserted.size(); ++k) {
        const InsertedParticle& q = inserted[k];
        if (!(q.radius > 0.0) || !std::isfinite(q.radius))
            throw InputError(context + ": particle " + std::to_string(k) + " has radius " +
                             std::to_string(q.radius) + "; expected a positive radius");
        if (!q.position.allFinite())
            throw InputError(context + ": particle " + std::to_string(k) + " has a non-finite position");
        // Outside the domain it would be removed as lost at the first step, silently.
        if (settings_.domain && settings_.domain->loses(q.position))
            throw InputError(context + ": particle " + std::to_string(k) + " at " + formatVec(q.position) +
                             " lies outside the simulation domain (keyword 'domain': min " +
                             formatVec(settings_.domain->min) + ", max " + formatVec(settings_.domain->max) +
                             "); expected every particle inside it");
        for (const Wall& w : walls_) {
            if (!w.isActive(time_)) continue;
            touching.clear();
            w.findContacts(q.position, q.radius, time_, touching);
            for (const WallContact& c : touching) {
                // A particle placed inside a wall would be shot out by a huge force.
                if (c.overlap > 1e-6 * q.radius)
                    throw InputError(context + ": particle " + std::to_string(k) + " at " + formatVec(q.position) +
                                     " (radius " + std::to_string(q.radius) + ") overlaps wall '" + w.name +
                                     "' by " + std::to_string(c.overlap) +
                                     " m; expected every particle clear of the walls");
            }
            // A centre behind a plane or inside a closed part touches no
            // surface (or not deeper than its radius) and would be lost or
            // stuck inside, silently.
            if (w.enclosesPoint(q.position, time_))
                throw InputError(context + ": particle " + std::to_string(k) + " at " + formatVec(q.position) +
                                 " (radius " + std::to_string(q.radius) + ") lies " +
                                 (std::holds_alternative<PlaneWall>(w.shape) ? "behind" : "inside") + " wall '" +
                                 w.name + "'; expected every particle clear of the walls");
        }
    }
    // With a decomposition each rank sees only its own particles: a refusal
    // on one rank is a refusal on all.
    requireOnAllRanks([&] { requireNoDeepOverlap(inserted, particles_, context); });
    // The time step is checked before anything is added, so that a rejected
    // insertion leaves the simulation as it was.
    requireTimeStepBelow(settings_, timeStepLimits(inserted, materialIndex), context);
    const double density = materials_[materialIndex].density;
    if (decomposition_) {
        // Every rank is given the same particles and numbers them alike; each
        // keeps the ones in its slab, after its owned ones and before the
        // ghosts (moved behind them), so that the lists, bridges included,
        // stay as they are until the next step lists again (as serially).
        const std::size_t owned = ownedCount(), before = particles_.size();
        for (const InsertedParticle& q : inserted) {
            const std::int64_t id = nextId_++;
            if (decomposition_->owns(q.position))
                particles_.add(id, q.position, velocity, q.radius, density, materialIndex);
        }
        const std::size_t added = particles_.size() - before;
        if (added > 0 && before > owned) {
            std::vector<int> order;  // new index -> old index
            order.reserve(particles_.size());
            for (std::size_t i = 0; i < owned; ++i) order.push_back(static_cast<int>(i));
            for (std::size_t k = 0; k < added; ++k) order.push_back(static_cast<int>(before + k));
            for (std::size_t g = owned; g < before; ++g) order.push_back(static_cast<int>(g));
            const std::vector<int> oldToNew = inversePermutation(order);
            particles_.permute(order);
            pairs_.remap(oldToNew);
            wallContacts_.remap(oldToNew);
        }
        forcesValid_ = false;
        return;
    }
    particles_.reserve(particles_.size() + inserted.size());
    for (const InsertedParticle& q : inserted)
        particles_.add(nextId_++, q.position, velocity, q.radius, density, materialIndex);
    forcesValid_ = false;
}

Simulation::TimeStepLimits Simulation::timeStepLimits(const std::vector<InsertedParticle>& adding,
                                                      int materialIndex) const {
    constexpr double infinity = std::numeric_limits<double>::infinity();
    TimeStepLimits limits{infinity, infinity, infinity};
    double smallestRadius = infinity, largestRadius = 0.0;
    int smallestMaterial = 0, largestMaterial = 0;
    auto consider = [&](double radius, int material) {
        const Material& m = materials_[material];
        limits.rayleigh = std::min(limits.rayleigh, settings_.maxRayleighFraction * criticalTimeStep(m, radius));
        // Two equal spheres head-on: LIGGGHTS uses the particle mass, R/2 and
        // the pair's Y*, at twice the characteristic speed.
        const double mass = m.density * 4.0 / 3.0 * pi * radius * radius * radius;
        const double hertz =
            hertzCollisionTime(mass, 0.5 * radius, effectiveYoungsModulus(m, m), 2.0 * settings_.impactVelocity);
        limits.hertz = std::min(limits.hertz, settings_.maxHertzFraction * hertz);
        if (radius < smallestRadius) smallestRadius = radius, smallestMaterial = material;
        if (radius > largestRadius) largestRadius = radius, largestMaterial = material;
    };
    for (std::size_t i = 0; i < ownedCount(); ++i) consider(particles_.radius[i], particles_.material[i]);
    for (const InsertedParticle& q : adding) consider(q.radius, materialIndex);
    if (decomposition_) {
        // Every rank must reach the same verdict: the limits of the whole run.
        const Communicator& comm = decomposition_->communicator();
        limits.rayleigh = comm.min(limits.rayleigh);
        limits.hertz = comm.min(limits.hertz);
        const double smallest = comm.min(smallestRadius), largest = comm.max(largestRadius);
        smallestMaterial = static_cast<int>(
            comm.min(smallestRadius == smallest ? static_cast<double>(smallestMaterial) : infinity));
        largestMaterial = static_cast<int>(
            comm.min(largestRadius == largest ? static_cast<double>(largestMaterial) : infinity));
        smallestRadius = smallest;
        largestRadius = largest;
    }
    if (settings_.forces.cohesion == CohesionModel::Capillary && largestRadius > 0.0)
        limits.capillary = settings_.maxCapillaryClusterFraction *
                           capillaryClusterStableTimeStep(smallestRadius, materials_[smallestMaterial], largestRadius,
                                                          materials_[largestMaterial],
                                                          interactions_(smallestMaterial, largestMaterial),
                                                          settings_.forces.capillary,
                                                          settings_.forces.capillaryForceScale,
                                                          settings_.forces.rolling);
    return limits;
}

double Simulation::maxAllowedTimeStep() const { return timeStepLimits().smallest(); }

void Simulation::requireAllowedTimeStep(const std::string& context) const {
    requireTimeStepBelow(settings_, timeStepLimits(), context);
}

void Simulation::setDecomposition(std::shared_ptr<GhostExchange> decomposition) {
    if (!particles_.empty() || nextId_ != 0)
        throw InputError(settings_.source + ": the domain decomposition must be set before any particle is inserted");
    decomposition_ = std::move(decomposition);
    forcesValid_ = false;
}

void Simulation::requireNoDecomposition(const std::string& what) const {
    if (decomposition_)
        throw InputError(settings_.source + ": " + what + " is not available with MPI domain decomposition yet");
}

template <class Check>
void Simulation::requireOnAllRanks(const Check& check) const {
    if (!decomposition_) return check();
    std::string failure;
    try {
        check();
    } catch (const InputError& e) {
        failure = e.what();
    }
    if (!decomposition_->communicator().anyTrue(!failure.empty())) return;
    throw InputError(!failure.empty() ? failure
                                      : settings_.source + ": another rank of the domain decomposition refused the "
                                                           "input (its message is in that rank's output)");
}

std::vector<std::uint8_t> Simulation::countedPairs() const {
    const auto& offsets = pairs_.offsets();
    const auto& neighbors = pairs_.neighbors();
    std::vector<std::uint8_t> counted(neighbors.size(), 1);
    if (!decomposition_) return counted;
    const std::size_t owned = ownedCount();
    for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const std::size_t j = static_cast<std::size_t>(neighbors[k]);
            counted[k] = j < owned || particles_.id[i] < particles_.id[j];
        }
    return counted;
}

void Simulation::setWaterContent(double w) {
    double mass = 0.0;
    for (std::size_t i = 0; i < ownedCount(); ++i) mass += particles_.mass[i];
    if (decomposition_) mass = decomposition_->communicator().sum(mass);
    const double volume = waterVolumeFromContent(w, mass, 1000.0, settings_.source);
    liquid_.waterContent = w;
    // Water added for new particles waits in the pool until the next update.
    liquid_.poolVolume += volume - liquid_.totalVolume;
    liquid_.totalVolume = volume;
    liquidNetwork_ = std::make_unique<LiquidBridgeNetwork>(volume, settings_.bridges);
    pairs_.setStateFields({pairs_.stateFields().rollingSpring, true});
    largestBridge_ = 0.0;
    bridgeListingLimit_ = std::numeric_limits<double>::infinity();  // λ unknown for the new total
    forcesValid_ = false;
}

double Simulation::liquidInBridges() const {
    CompensatedSum total;
    if (decomposition_) return decomposition_->communicator().sum(heldLiquidHere(true, true).volume);
    for (double v : pairs_.bridgeVolume()) total.add(v);
    for (const WallContactRecord& r : wallContacts_.records()) total.add(r.bridgeVolume);
    return total.value();
}

double Simulation::liquidInWallBridges() const {
    CompensatedSum total;
    if (decomposition_) return decomposition_->communicator().sum(heldLiquidHere(false, true).volume);
    for (const WallContactRecord& r : wallContacts_.records()) total.add(r.bridgeVolume);
    return total.value();
}

double Simulation::liquidCoordinationNumber() const {
    if (decomposition_) {
        const double particles = static_cast<double>(
            decomposition_->communicator().sum(static_cast<std::int64_t>(ownedCount())));
        const LiquidState now = liquidOverRanks();
        return particles == 0.0 ? 0.0 : 2.0 * static_cast<double>(now.bridgeCount) / particles;
    }
    return particles_.empty() ? 0.0 : 2.0 * static_cast<double>(liquid_.bridgeCount) / particles_.size();
}

LiquidState Simulation::liquidOverRanks() const {
    if (!decomposition_) return liquid_;
    const Communicator& comm = decomposition_->communicator();
    const HeldLiquid held = heldLiquidHere(true, true);
    LiquidState now = liquid_;
    now.bridgeCount = static_cast<std::size_t>(comm.sum(held.pairBridges));
    now.wallBridgeCount = static_cast<std::size_t>(comm.sum(held.wallBridges));
    now.poolVolume = now.totalVolume - comm.sum(held.volume);
    return now;
}

Simulation::HeldLiquid Simulation::heldLiquidHere(bool pairs, bool walls) const {
    HeldLiquid held;
    CompensatedSum volume;
    if (pairs) {
        const std::vector<std::uint8_t> counted = countedPairs();
        const std::vector<double>& bridge = pairs_.bridgeVolume();
        for (std::size_t k = 0; k < bridge.size(); ++k)
            if (counted[k] && bridge[k] > 0.0) {
                ++held.pairBridges;
                volume.add(bridge[k]);
            }
    }
    if (walls) {
        const std::size_t owned = ownedCount();  // a ghost's wall records are its owner's
        for (const WallContactRecord& r : wallContacts_.records())
            if (static_cast<std::size_t>(r.particle) < owned && r.bridgeVolume > 0.0) {
                ++held.wallBridges;
                volume.add(r.bridgeVolume);
            }
    }
    held.volume = volume.value();
    return held;
}

double Simulation::coordinationNumber() const {
    const std::size_t n = ownedCount();
    return n == 0 ? 0.0 : 2.0 * static_cast<double>(last_.contacts.touchingPairs) / n;
}

std::vector<Vec3> Simulation::wallForces() const {
    std::vector<Vec3> sum(walls_.size(), Vec3::Zero());
    const std::size_t owned = ownedCount();
    for (const WallContactRecord& r : wallContacts_.records())
        if (static_cast<std::size_t>(r.particle) < owned) sum[r.wall] -= r.force;  // a ghost's is its owner's
    return sum;
}

void Simulation::restartWallForceMeans() {
    wallForceSum_.assign(walls_.size(), Vec3::Zero());
    wallForceSteps_ = 0;
}

void Simulation::accumulateWallForces() {
    if (wallForceSum_.size() != walls_.size()) restartWallForceMeans();
    const std::size_t owned = ownedCount();
    for (const WallContactRecord& r : wallContacts_.records())
        if (static_cast<std::size_t>(r.particle) < owned) wallForceSum_[r.wall] -= r.force;
    ++wallForceSteps_;
}

RunTotals Simulation::totalsOverRanks() const {
    RunTotals t;
    const std::size_t owned = ownedCount();
    t.particles = owned;
    t.kineticEnergy = particles_.kineticEnergy(owned);
    t.touchingPairs = last_.contacts.touchingPairs;
    t.wallContacts = last_.contacts.wallContacts;
    t.lost = lost_;
    t.lostMass = lostMass_;
    if (wallForceSteps_ > 0) {
        t.wallForces = wallForceSum_;
        for (Vec3& f : t.wallForces) f /= static_cast<double>(wallForceSteps_);
    } else {
        t.wallForces = wallForces();
    }
    if (!decomposition_) return t;
    // The kernel counted what it computed: a pair across a slab face on both
    // of its ranks, and the ghosts' wall contacts.  Those are taken out here
    // (the positions are the force computation's: a call of step() ends with
    // a kick), with the kernel's own tests.
    const auto& offsets = pairs_.offsets();
    const auto& neighbors = pairs_.neighbors();
    const ParticleStore& p = particles_;
    std::size_t twice = 0, ghostWalls = 0;
    if (forcesValid_) {
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
            for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
                const std::size_t j = static_cast<std::size_t>(neighbors[k]);
                if (j < owned || p.id[i] < p.id[j]) continue;
                const double radiusSum = p.radius[i] + p.radius[j];
                if (!((p.position[j] - p.position[i]).squaredNorm() >= radiusSum * radiusSum)) ++twice;
            }
        std::vector<WallContact> found;
        for (const WallContactRecord& r : wallContacts_.records()) {
            if (static_cast<std::size_t>(r.particle) < owned) continue;
            found.clear();
            walls_[r.wall].findContacts(p.position[r.particle], p.radius[r.particle], time_, found);
            for (const WallContact& c : found)
                if (c.feature == r.feature && c.overlap > 0.0) {
                    ++ghostWalls;
                    break;
                }
        }
    }
    std::vector<double> local{static_cast<double>(owned), t.kineticEnergy,
                              static_cast<double>(t.touchingPairs - std::min(twice, t.touchingPairs)),
                              static_cast<double>(t.wallContacts - std::min(ghostWalls, t.wallContacts)),
                              static_cast<double>(lost_), lostMass_};
    for (const Vec3& f : t.wallForces) local.insert(local.end(), {f.x(), f.y(), f.z()});
    const std::vector<double> sum = sumOverRanksInRankOrder(decomposition_->communicator(), local);
    t.particles = static_cast<std::size_t>(sum[0]);
    t.kineticEnergy = sum[1];
    t.touchingPairs = static_cast<std::size_t>(sum[2]);
    t.wallContacts = static_cast<std::size_t>(sum[3]);
    t.lost = static_cast<std::size_t>(sum[4]);
    t.lostMass = sum[5];
    for (std::size_t w = 0; w < t.wallForces.size(); ++w)
        t.wallForces[w] = Vec3(sum[6 + 3 * w], sum[7 + 3 * w], sum[8 + 3 * w]);
    return t;
}

void Simulation::removeLostParticles(bool knownNoneLost) {
    last_.lostThisStep = 0;
    if (!settings_.domain || knownNoneLost) return;
    // With a decomposition each rank removes its own particles; ghosts are
    // dropped first (their owners remove them), so the lists are empty below.
    const auto isLost = [&](std::size_t i) { return settings_.domain->loses(particles_.position[i]); };
    if (decomposition_) {
        const std::size_t owned = ownedCount();
        std::size_t i = 0;
        while (i < owned && !isLost(i)) ++i;
        if (i == owned) return;
        decomposition_->dropGhosts(particles_, pairs_, wallContacts_);
    }
    const std::size_t n = particles_.size();
    std::vector<char> keep(n, 1);
    std::size_t out = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (isLost(i)) {
            keep[i] = 0;
            ++out;
            lostMass_ += particles_.mass[i];
        }
    }
    if (out == 0) return;
    // Liquid held by bridges of lost particles returns to the pool: the water
    // budget stays closed and is redistributed over the remaining bridges.
    if (liquidNetwork_) {
        const auto& offsets = pairs_.offsets();
        const auto& neighbors = pairs_.neighbors();
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
            for (int k = offsets[i]; k < offsets[i + 1]; ++k)
                if (!keep[i] || !keep[neighbors[k]]) liquid_.poolVolume += pairs_.bridgeVolume()[k];
        for (const WallContactRecord& r : wallContacts_.records())
            if (!keep[r.particle]) liquid_.poolVolume += r.bridgeVolume;
    }
    const std::vector<int> oldToNew = particles_.compact(keep);
    pairs_.remap(oldToNew);
    wallContacts_.remap(oldToNew);
    lost_ += out;
    last_.lostThisStep = out;
}

void Simulation::updatePairList() {
    if (decomposition_) {
        // History to the id-keyed stash, ghosts away, the slabs re-cut when
        // the owned counts drifted apart (the powder moved), particles to
        // their owners.
        // The work is read from the lists before dropGhosts empties them; the
        // owned particles keep their order.
        // Timed: once a rank has been busy long enough to time (the same
        // decision on all ranks), by its busy time; until the first such
        // check by counts (the powder may start on one rank); between two
        // such checks not at all (counts would undo what time balanced).
        enum class Check { Counts, Weights, None } check = Check::Counts;
        std::vector<double> weights;
        if (decomposition_->balancingEnabled() && settings_.loadBalanceWeight == LoadBalanceWeight::Work) {
            check = Check::Weights;
            weights = ownedWork();
        } else if (decomposition_->balancingEnabled() && settings_.loadBalanceWeight == LoadBalanceWeight::Time) {
            const double now = busySecondsSoFar();
            const double busy = std::max(now - busySecondsAtCheck_, 0.0);
            if (decomposition_->communicator().max(busy) >= minimumTimedSeconds) {
                check = Check::Weights;
                const std::size_t owned = ownedCount();
                // A rank's busy time shared by its particles; one that owns none weighs nothing.
                weights.assign(owned, owned > 0 ? busy / static_cast<double>(owned) : 0.0);
                busySecondsAtCheck_ = now;
                timedCheckDone_ = true;
            } else if (timedCheckDone_) {
                check = Check::None;
            }
        }
        decomposition_->dropGhosts(particles_, pairs_, wallContacts_);
        const bool recut = check == Check::Weights  ? decomposition_->rebalanceByWeight(particles_, weights).recut
                           : check == Check::Counts ? decomposition_->rebalanceIfNeeded(particles_).recut
                                                    : false;
        decomposition_->migrate(particles_);
        if (recut) decomposition_->noteBalanceAfterMigration(particles_);
    }
    double rMax = 0.0;
    for (double r : particles_.radius) rMax = std::max(rMax, r);
    // The same skin on every rank as in a one-rank run.
    if (decomposition_) rMax = decomposition_->communicator().max(rMax);
    double extra = 0.0;
    if (liquidNetwork_ && (decomposition_ || !particles_.empty())) {
        // Bridges can only form between listed pairs: reach out to the debonding
        // distance of a bridge larger than any seen so far (and at least of the
        // liquid of one particle, which bounds a bridge at the first update).
        const double particles = decomposition_ ? static_cast<double>(decomposition_->communicator().sum(
                                                      static_cast<std::int64_t>(particles_.size())))
                                                : static_cast<double>(particles_.size());
        if (particles > 0.0) {
            const double perParticle = liquid_.totalVolume / particles;
            extra = debondingDistance(std::max(1.5 * largestBridge_, perParticle), settings_.bridges.contactAngle);
        }
    }
    const double skin = settings_.skinFraction * 2.0 * rMax;
    // Neighbours in space become neighbours in memory: the force loop's reads of
    // particle j stay in cache (the cost per particle no longer grows with N).
    // Small systems are left in their order; sorting every few builds suffices.
    if (particles_.size() >= settings_.spatialSortMinParticles && pairs_.buildCount() % spatialSortInterval == 0) {
        const std::vector<int> order = spatialOrder(particles_.position, 2.0 * rMax + skin + extra);
        const std::vector<int> oldToNew = inversePermutation(order);
        particles_.permute(order);
        pairs_.remap(oldToNew);
        wallContacts_.remap(oldToNew);
    }
    pairs_.setRanges(skin, extra);
    // Bridges form at the list build between pairs within their debonding
    // distance at the liquid per weight λ that the distribution then finds;
    // λ changes little between builds, so only pairs that could hold a bridge
    // at bridgeListingMargin times the last λ are listed beyond touching reach
    // (in a polydisperse wet bed the range of the largest bridge lists 3x
    // more pairs).  Should the new λ exceed the limit, the list is made again
    // without it (below): the results never depend on it.  (Bridges formed at
    // contact only list the whole range.  With a decomposition λ is the
    // run's, so every rank relists or not alike.)
    const bool limitBridgePairs = liquidNetwork_ &&
                                  settings_.bridges.formation == BridgeFormation::WithinDebondingDistance;
    pairs_.setBridgeListing(settings_.bridges,
                            limitBridgePairs ? bridgeListingLimit_ : std::numeric_limits<double>::infinity());
    if (decomposition_) {
        // A listed pair is closer than r_i + r_j + skin + extra <= r_i + r_max +
        // skin + extra: ghosts out to that distance from the slab suffice.
        decomposition_->appendGhosts(particles_, rMax + skin + extra);
        pairs_.build(particles_, ownedCount());
        decomposition_->restoreHistory(particles_, pairs_, wallContacts_);
    } else {
        pairs_.build(particles_);
    }
    if (liquidNetwork_) {
        double liquidPerWeight = redistributeLiquid(extra);
        // (With a margin for the rounding of λ = V / Σw against λ*_k Σw <= V.)
        if (liquidPerWeight * (1.0 + 1e-9) > pairs_.bridgeListingLimit()) {
            pairs_.setBridgeListing(settings_.bridges, std::numeric_limits<double>::infinity());
            pairs_.relistAtBuildPositions(particles_, ownedCount());
            ++bridgeRelists_;
            liquidPerWeight = redistributeLiquid(extra);
        }
        bridgeListingLimit_ = liquidPerWeight > 0.0 && settings_.bridgeListingMargin > 0.0
                                  ? settings_.bridgeListingMargin * liquidPerWeight
                                  : std::numeric_limits<double>::infinity();
    }
    rebuildWallCandidates();
}

namespace {
double secondsNow() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

double Simulation::busySecondsSoFar() const {
    if (!inStep_) return busySeconds_;
    const double collective = decomposition_ ? decomposition_->communicator().counters().seconds : 0.0;
    return busySeconds_ + (secondsNow() - stepStartSeconds_) - (collective - stepStartCollectiveSeconds_);
}

std::vector<double> Simulation::ownedWork() const {
    const std::size_t owned = ownedCount();
    std::vector<double> work(owned, 1.0);
    const auto& offsets = pairs_.offsets();
    const auto& neighbors = pairs_.neighbors();
    const std::size_t rows = std::min(owned, offsets.size() - 1);
    for (std::size_t i = 0; i < rows; ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const std::size_t j = static_cast<std::size_t>(neighbors[k]);
            if (j < owned) {
                work[i] += 0.5;
                work[j] += 0.5;
            } else {
                work[i] += 1.0;
            }
        }
    for (const WallContactRecord& r : wallContacts_.records())
        if (static_cast<std::size_t>(r.particle) < owned) work[r.particle] += 1.0;
    return work;
}

void Simulation::rebuildWallCandidates() {
    // A particle moves less than skin/2 from its position at the list build
    // before the next build, so walls farther than the skin (plus the bridge
    // reach) from it now cannot touch it before then.  A moving mesh wall is
    // listed within a further skin/2, and the lists are built again when it
    // has moved that far (computeForces).
    const double bridgeReach = settings_.forces.wallBridges ? wallContacts_.bridgeReach() : 0.0;
    wallCandidates_.build(particles_, walls_, time_, pairs_.skin() + bridgeReach, 0.5 * pairs_.skin());
}

void Simulation::wallBridgeCandidates(double reach, std::vector<WallContactRecord>& records,
                                      std::vector<double>& gaps) const {
    records.clear();
    gaps.clear();
    std::vector<std::pair<WallContactRecord, double>> near;
    WallProximityQuery query(walls_, time_);
    for (std::size_t i = 0; i < ownedCount(); ++i) {  // a ghost's wall bridges are its owner's
        near.clear();
        query.forEachNear(particles_.position[i], particles_.radius[i], reach, [&](int w, const WallContact& c) {
            WallContactRecord r;
            r.particle = static_cast<int>(i);
            r.wall = w;
            r.feature = c.feature;
            if (const WallContactRecord* prev = wallContacts_.find(r.particle, w, c.feature)) {
                r.history = prev->history;
                // Read only as "was bonded" (ContactThenPersist); replaced by the update.
                r.bridgeVolume = prev->bridgeVolume;
            }
            near.emplace_back(r, -c.overlap);
        });
        std::sort(near.begin(), near.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        for (const auto& [record, gap] : near) {
            records.push_back(record);
            gaps.push_back(gap);
        }
    }
}

double Simulation::redistributeLiquid(double wallReach) {
    BridgeCandidates candidates;
    const auto& offsets = pairs_.offsets();
    const auto& neighbors = pairs_.neighbors();
    std::vector<double>& bridge = pairs_.bridgeVolume();
    candidates.reserve(neighbors.size());
    for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const int j = neighbors[k];
            candidates.add(particles_.radius[i], particles_.radius[j],
                           (particles_.position[i] - particles_.position[j]).norm(), bridge[k] > 0.0);
        }
    // Particle-wall bridges (option): the wall enters the distribution as a
    // mirror particle, the candidate (R, R, 2R + gap) -- it takes the share of a
    // same-size neighbour at the same gap, and the gap tested against δmax is
    // the wall gap (docs/capillary-model.md, "Wall bridges").
    std::vector<WallContactRecord> wallRecords;
    std::vector<double> wallGaps;
    if (settings_.forces.wallBridges) {
        wallBridgeCandidates(wallReach, wallRecords, wallGaps);
        for (std::size_t m = 0; m < wallRecords.size(); ++m) {
            const double radius = particles_.radius[wallRecords[m].particle];
            candidates.add(radius, radius, 2.0 * radius + wallGaps[m], wallRecords[m].bridgeVolume > 0.0);
        }
    }
    // Over ranks: the pairs this rank accounts for, then every wall candidate
    // (of owned particles only, wallBridgeCandidates).
    const bool overRanks = decomposition_ && !decomposition_->communicator().isSerial();
    BridgeDistribution sharedOverRanks;
    if (overRanks) {
        std::vector<std::uint8_t> counted = countedPairs();
        counted.resize(candidates.size(), 1);
        sharedOverRanks = distributeLiquidOverRanks(candidates, counted, liquid_.totalVolume, settings_.bridges,
                                                    decomposition_->communicator());
    }
    const BridgeDistribution& d = overRanks ? sharedOverRanks : liquidNetwork_->update(candidates);
    largestBridge_ = 0.0;
    liquid_.bridgeCount = 0;
    liquid_.wallBridgeCount = 0;
    for (std::size_t k = 0; k < bridge.size(); ++k) {
        bridge[k] = d.volume[k];
        largestBridge_ = std::max(largestBridge_, d.volume[k]);
        if (d.volume[k] > 0.0) ++liquid_.bridgeCount;
    }
    if (settings_.forces.wallBridges) {
        for (std::size_t m = 0; m < wallRecords.size(); ++m) {
            const double volume = d.volume[bridge.size() + m];
            wallRecords[m].bridgeVolume = volume;
            largestBridge_ = std::max(largestBridge_, volume);
            if (volume > 0.0) ++liquid_.wallBridgeCount;
        }
        wallContacts_.records().swap(wallRecords);
        // Follow every wall bridge out to its own debonding distance.
        wallContacts_.setBridgeReach(
            std::max(wallReach, debondingDistance(largestBridge_, settings_.bridges.contactAngle)));
    }
    liquid_.poolVolume = d.freeLiquid;
    if (decomposition_) {
        // The same list range and bridge reach on every rank; the run's counts.
        const Communicator& comm = decomposition_->communicator();
        largestBridge_ = comm.max(largestBridge_);
        if (settings_.forces.wallBridges)
            wallContacts_.setBridgeReach(std::max(wallReach, debondingDistance(largestBridge_, settings_.bridges.contactAngle)));
        const LiquidState now = liquidOverRanks();
        liquid_.bridgeCount = now.bridgeCount;
        liquid_.wallBridgeCount = now.wallBridgeCount;
    }
    return d.liquidPerWeight;
}

void Simulation::computeForces(bool forcesReset) {
    if (!forcesReset) resetForces(particles_, settings_.gravity);
    // A wall starts or stops moving, or a moving mesh wall moved as far as its
    // listing allows: the walls are listed anew.
    if (time_ >= wallCandidates_.validUntil() || wallCandidates_.movedTooFar(walls_, time_)) rebuildWallCandidates();
    last_.contacts = kernel_->compute(particles_, pairs_, wallContacts_, walls_, wallCandidates_, interactions_,
                                      time_, settings_.timeStep);
    // With a decomposition a pair across a slab face breaks on both ranks: the
    // run's counts come from liquidOverRanks() (collective), not from here.
    if (liquidNetwork_ && !decomposition_) {
        liquid_.poolVolume += last_.contacts.releasedLiquid;
        liquid_.bridgeCount = last_.contacts.bridges;
        liquid_.wallBridgeCount = last_.contacts.wallBridges;
    }
}

void Simulation::advanceWallLoads() {
    bool loaded = false;
    for (const Wall& w : walls_) loaded = loaded || (w.motion.hasLoad() && w.motion.isMovingAt(time_));
    if (!loaded) {
        for (Wall& w : walls_) w.motion.advanceLoad(time_, settings_.timeStep, 0.0, 0.0);  // zero outside
        return;
    }
    // The same time on every rank: every rank takes this path, and the sum in
    // rank order gives every rank the same force, so the walls stay alike.
    std::vector<Vec3> forces = wallForces();
    if (decomposition_) {
        std::vector<double> local;
        for (const Vec3& f : forces) local.insert(local.end(), {f.x(), f.y(), f.z()});
        const std::vector<double> sum = sumOverRanksInRankOrder(decomposition_->communicator(), local);
        for (std::size_t w = 0; w < forces.size(); ++w) forces[w] = Vec3(sum[3 * w], sum[3 * w + 1], sum[3 * w + 2]);
    }
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        WallMotion& motion = walls_[w].motion;
        if (!motion.hasLoad()) continue;
        const Vec3& d = motion.load().direction;
        motion.advanceLoad(time_, settings_.timeStep, forces[w].dot(d), settings_.gravity.dot(d));
    }
}

void Simulation::step(long steps) {
    const double dt = settings_.timeStep;
    // Within one call the closing half kick of a step and the opening half kick
    // and drift of the next are one pass over the particles (same arithmetic).
    // Without MPI that pass also tests the displacement since the list build
    // and resets the forces to the body force: the particles pass through the
    // cache once per step instead of three times.  (With MPI the test also
    // covers the ghosts and the reset their forces, so the loops stay apart.)
    const bool fused = !decomposition_;
    // Read just before each drift: a rebuild replaces the positions at build.
    auto driftExtras = [&]() {
        DriftExtras extras;
        if (fused && pairs_.positionsAtBuild().size() == particles_.size()) {
            extras.displacementFrom = pairs_.positionsAtBuild().data();
            extras.limitSquared = pairs_.rebuildDisplacementSquared();
        }
        extras.resetForces = fused;
        extras.gravity = settings_.gravity;
        if (extras.displacementFrom && settings_.domain) extras.domain = &*settings_.domain;
        return extras;
    };
    bool drifted = false;
    bool watched = false;     // the drift did the rebuild test ...
    DriftReport drifting;     // ... with this result
    bool domainTested = false;  // ... and the lost-particle test
    auto drift = [&](bool twoKicks) {
        const DriftExtras extras = driftExtras();
        drifting = twoKicks ? kickKickAndDrift(particles_, dt, ownedCount(), extras)
                            : kickAndDrift(particles_, dt, ownedCount(), extras);
        watched = extras.displacementFrom != nullptr;
        domainTested = extras.domain != nullptr;
    };
    // The busy time of this call (LoadBalanceWeight::Time), kept if it throws too.
    struct BusyClock {
        Simulation& sim;
        explicit BusyClock(Simulation& s) : sim(s) {
            sim.stepStartSeconds_ = secondsNow();
            sim.stepStartCollectiveSeconds_ =
                sim.decomposition_ ? sim.decomposition_->communicator().counters().seconds : 0.0;
            sim.inStep_ = true;
        }
        ~BusyClock() {
            sim.busySeconds_ = sim.busySecondsSoFar();
            sim.inStep_ = false;
        }
    } busyClock(*this);
    for (long s = 0; s < steps; ++s) {
        if (!forcesValid_) {
            updatePairList();
            computeForces(false);
            forcesValid_ = true;
        }
        if (!drifted) drift(false);
        ++step_;
        // Time from the step count: no drift from summing dt, exact on restart.
        time_ = step_ * dt;
        removeLostParticles(domainTested && !drifting.leftDomain);
        bool rebuild = last_.lostThisStep > 0 || (watched ? drifting.movedFar : pairs_.needsRebuild(particles_));
        if (decomposition_) {
            // All ranks rebuild together (the rebuild exchanges particles); the
            // test and the ghost update share one round.
            rebuild = decomposition_->updateGhostsUnlessRebuild(particles_, rebuild);
        }
        if (rebuild) updatePairList();
        computeForces(fused);  // a drift (this step's or the last one's) came first
        advanceWallLoads();
        accumulateWallForces();
        drifted = s + 1 < steps;
        if (drifted)
            drift(true);  // with the next step's list test and force reset
        else
            kick(particles_, dt, ownedCount());
    }
}

}  // namespace dem
