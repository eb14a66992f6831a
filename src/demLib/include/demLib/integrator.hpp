#pragma once
// Velocity-Verlet integration of translation and rotation of spheres (second
// order; the same split as LIGGGHTS' fix nve/sphere): a half kick and a drift
// before the forces are computed, a second half kick after.
#include "demLib/particle_store.hpp"

namespace dem {

// v += dt/2 F/m, ω += dt/2 T/I, then x += dt v, for particles 0 .. count-1
// (default: all; with MPI ghosts stored after them, the owned ones).
void kickAndDrift(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

// v += dt/2 F/m, ω += dt/2 T/I, for particles 0 .. count-1.
void kick(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

// kick() of one step followed by kickAndDrift() of the next, in one pass over
// the particles (the forces do not change in between): the same operations in
// the same order per particle, so the same results as the two calls.
void kickKickAndDrift(ParticleStore& particles, double dt, std::size_t count = static_cast<std::size_t>(-1));

}  // namespace dem
