#include "demLib/integrator.hpp"

#include "demLib/parallel.hpp"

#include <algorithm>

namespace dem {

void kickAndDrift(ParticleStore& p, double dt, std::size_t count) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        p.velocity[i] += (half * p.invMass[i]) * p.force[i];
        p.omega[i] += (half * p.invInertia[i]) * p.torque[i];
        p.position[i] += dt * p.velocity[i];
    }
}

void kick(ParticleStore& p, double dt, std::size_t count) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        p.velocity[i] += (half * p.invMass[i]) * p.force[i];
        p.omega[i] += (half * p.invInertia[i]) * p.torque[i];
    }
}

}  // namespace dem
