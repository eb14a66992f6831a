#pragma once
// Velocity-Verlet integration of translation and rotation of spheres (second
// order; the same split as LIGGGHTS' fix nve/sphere): a half kick and a drift
// before the forces are computed, a second half kick after.
#include "demLib/particle_store.hpp"

namespace dem {

// v += dt/2 F/m, ω += dt/2 T/I, then x += dt v.
void kickAndDrift(ParticleStore& particles, double dt);

// v += dt/2 F/m, ω += dt/2 T/I.
void kick(ParticleStore& particles, double dt);

}  // namespace dem
