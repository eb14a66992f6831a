#include "demLib/integrator.hpp"

#include "demLib/parallel.hpp"

#include <algorithm>

namespace dem {

namespace {
// 1/m and 1/I of a solid sphere (I = 2/5 m r^2), recomputed instead of stored:
// one division per particle and half step costs less than streaming 16 more
// bytes per particle through the cache.  1/I = 1/(0.4 m r^2) is the division;
// 1/m = 0.4 r^2 / I follows from it with multiplications.
struct InverseMass {
    double mass, inertia;
    InverseMass(double m, double r) {
        const double armSquared = 0.4 * r * r;
        inertia = 1.0 / (armSquared * m);
        mass = armSquared * inertia;
    }
};

// The one loop behind the three entry points: `kicks` half kicks with the
// same force and torque (two = the closing kick of a step and the opening
// kick of the next), then the drift if asked.  Each half kick is its own
// addition, so kicks = 2 rounds exactly like two separate calls.
template <int kicks, bool drift>
void advance(ParticleStore& p, double dt, std::size_t count) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        const InverseMass inv(p.mass[i], p.radius[i]);
        const Vec3 dv = (half * inv.mass) * p.force[i];
        const Vec3 dw = (half * inv.inertia) * p.torque[i];
        for (int k = 0; k < kicks; ++k) {
            p.velocity[i] += dv;
            p.omega[i] += dw;
        }
        if constexpr (drift) p.position[i] += dt * p.velocity[i];
    }
}
}  // namespace

void kickAndDrift(ParticleStore& p, double dt, std::size_t count) { advance<1, true>(p, dt, count); }

void kick(ParticleStore& p, double dt, std::size_t count) { advance<1, false>(p, dt, count); }

void kickKickAndDrift(ParticleStore& p, double dt, std::size_t count) { advance<2, true>(p, dt, count); }

}  // namespace dem
