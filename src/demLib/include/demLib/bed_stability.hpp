#pragma once
// The stable time step of a bed as it is: every contact of the bed linearised
// (contact_stability.hpp's springs and dashpots, at each contact's own overlap),
// all particles moving, and the growth of the velocity Verlet step map
// measured by iterating it from a random state.
//
// The a-priori limits (the Rayleigh and Hertz limits, and the wet-bed cluster
// of capillaryClusterStableTimeStep) are evaluated before a particle exists;
// they assume a packing.  This analysis needs a bed (e.g. a restart file of a
// settled one) and assumes nothing about it: measured on the wet beds of
// docs/engine.md it predicts where they start to rattle (polydisperse F32 at
// coarse grain 5: 3.98e-6 s, measured onset between 3.5 and 4.2e-6 s; a
// monodisperse bed: 5.75e-6 s, measured onset between 5 and 6e-6 s, where the
// cluster model with six neighbours said 1.02e-5 s).  Its cost grows with the
// bed (about 2 s per thousand particles and trial step): a tool for a bed of
// some thousand particles (demStability), not a check inside a run.
#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

class Simulation;

struct BedStabilityOptions {
    int iterations = 10000;            // steps of the linear map per trial time step
    double relativeTolerance = 0.01;   // of the bisection on the time step
    unsigned seed = 1;                 // of the random start
    double timeStep = 0.0;             // the step to judge [s] (0: the simulation's)
    // Only the particles with centres in this box move; those outside that
    // touch them are held fixed, as walls (default: the whole bed).
    Vec3 regionLower = Vec3::Constant(-std::numeric_limits<double>::infinity());
    Vec3 regionUpper = Vec3::Constant(std::numeric_limits<double>::infinity());
    // Called after each trial step (e.g. for progress lines): the trial's
    // number (from 1), the number of trials expected in all, its step, its log
    // growth per step and whether a mode grew.
    std::function<void(int trial, int expectedTrials, double dt, double growth, bool grows)> onTrial;
};

struct BedStabilityReport {
    std::size_t particles = 0;         // that move (those in the region)
    std::size_t particleContacts = 0;  // touching pairs of them
    std::size_t fixedParticleContacts = 0;  // with particles outside the region
    std::size_t wallContacts = 0;
    // contactsPerParticle[k]: particles with k contacts (walls included).
    std::vector<std::size_t> contactsPerParticle;
    double undampedLimit = 0.0;        // 2 / w_max of the undamped bed [s]
    double stableTimeStep = 0.0;       // largest step without a growing mode [s] (within the tolerance)
    double runTimeStep = 0.0;          // the step judged [s] (options.timeStep, or the simulation's)
    double growthAtRunStep = 0.0;      // log growth per step of the fastest mode at that step
    bool stableAtRunStep = true;
};

// Analyses the bed of `simulation` at its current state (contacts with
// overlap > 0 between particles and with the active walls).  A bed without
// contacts has an infinite stable step.
BedStabilityReport analyseBedStability(const Simulation& simulation, const BedStabilityOptions& options = {});

}  // namespace dem
