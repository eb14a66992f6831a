#include "demLib/integrator.hpp"

#include "demLib/parallel.hpp"

#include <algorithm>

namespace dem {

namespace {
// 1/m and 1/I of a solid sphere (I = 2/5 m r^2), recomputed instead of stored:
// two divisions per particle and half step cost less than streaming 16 more
// bytes per particle through the cache.
struct InverseMass {
    double mass, inertia;
    InverseMass(double m, double r) : mass(1.0 / m), inertia(1.0 / (0.4 * m * r * r)) {}
};
}  // namespace

void kickAndDrift(ParticleStore& p, double dt, std::size_t count) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        const InverseMass inv(p.mass[i], p.radius[i]);
        p.velocity[i] += (half * inv.mass) * p.force[i];
        p.omega[i] += (half * inv.inertia) * p.torque[i];
        p.position[i] += dt * p.velocity[i];
    }
}

void kick(ParticleStore& p, double dt, std::size_t count) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        const InverseMass inv(p.mass[i], p.radius[i]);
        p.velocity[i] += (half * inv.mass) * p.force[i];
        p.omega[i] += (half * inv.inertia) * p.torque[i];
    }
}

}  // namespace dem
