#pragma once
// Velocity-Verlet integration of translation and rotation of spheres (second
// order; the same split as LIGGGHTS' fix nve/sphere): a half kick and a drift
// before the forces are computed, a second half kick after.
#include "demLib/axis_aligned_box.hpp"
#include "demLib/particle_store.hpp"

namespace dem {

// Work the engine folds into the drift's pass over the particles, so that the
// particles are streamed through the cache once per step instead of three
// times (the results are those of separate loops: same operations per particle).
struct DriftExtras {
    // The neighbour list's rebuild test: the drift reports whether any
    // particle ends farther than sqrt(limitSquared) from displacementFrom[i]
    // (null: no test).
    const Vec3* displacementFrom = nullptr;
    double limitSquared = 0.0;
    // Reset the force to the body force, F = m g + F_external, and the torque
    // to zero, after the kick has used them (the next force computation adds
    // the contacts to it).
    bool resetForces = false;
    Vec3 gravity = Vec3::Zero();
    // With the rebuild test: also report whether a particle is lost from this
    // domain (AxisAlignedBox::loses; null: no test), so that the engine's
    // lost-particle test need not pass over the particles again.
    const AxisAlignedBox* domain = nullptr;
};

// What the drift's extras found.
struct DriftReport {
    bool movedFar = false;    // a particle moved beyond the rebuild limit
    bool leftDomain = false;  // a particle is lost from the domain (AxisAlignedBox::loses)
};

// v += dt/2 F/m, ω += dt/2 T/I, then x += dt v, for particles 0 .. count-1
// (default: all; with MPI ghosts stored after them, the owned ones).
void kickAndDrift(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

// v += dt/2 F/m, ω += dt/2 T/I, for particles 0 .. count-1.
void kick(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

// kick() of one step followed by kickAndDrift() of the next, in one pass over
// the particles (the forces do not change in between): the same operations in
// the same order per particle, so the same results as the two calls.
void kickKickAndDrift(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

// kickAndDrift / kickKickAndDrift with the extras (both flags false for a
// test not asked for).
DriftReport kickAndDrift(ParticleStore& particles, double dt, std::size_t count, const DriftExtras& extras);
DriftReport kickKickAndDrift(ParticleStore& particles, double dt, std::size_t count, const DriftExtras& extras);

// F = m g + F_external, T = 0 for particles 0 .. n-1: the start of a force computation.
void resetForces(ParticleStore& particles, const Vec3& gravity);

}  // namespace dem
