#include "demLib/integrator.hpp"

#include "demLib/parallel.hpp"
#include "demLib/spin_barrier.hpp"

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

// The body force: weight plus the external (fluid) force where a coupling set one.
inline Vec3 bodyForce(const ParticleStore& p, std::size_t i, const Vec3& g, bool external) {
    return external ? Vec3(p.mass[i] * g + p.externalForce[i]) : Vec3(p.mass[i] * g);
}

// The one loop behind the entry points: `kicks` half kicks with the same force
// and torque (two = the closing kick of a step and the opening kick of the
// next), then the drift if asked, then the extras.  Each half kick is its own
// addition, so kicks = 2 rounds exactly like two separate calls.
template <int kicks, bool drift, bool watch, bool reset>
DriftReport advance(ParticleStore& p, double dt, std::size_t count, const DriftExtras& extras) {
    const double half = 0.5 * dt;
    const std::size_t n = std::min(count, p.size());
    const Vec3* from = extras.displacementFrom;
    const double limit2 = extras.limitSquared;
    const Vec3 g = extras.gravity;
    const AxisAlignedBox* domain = extras.domain;
    const ParticleStore& cp = p;  // reads of externalForce must not allocate it
    const bool external = cp.externalForce.allocated();
    bool moved = false;
    bool left = false;
    SpinBarrier teamBarrier;
#pragma omp parallel num_threads(threadsFor(n, lightLoopParticlesPerThread))
    {
#pragma omp for schedule(static) reduction(|| : moved, left) nowait
        for (std::size_t i = 0; i < n; ++i) {
            const InverseMass inv(p.mass[i], p.radius[i]);
            const Vec3 dv = (half * inv.mass) * p.force[i];
            const Vec3 dw = (half * inv.inertia) * p.torque[i];
            for (int k = 0; k < kicks; ++k) {
                p.velocity[i] += dv;
                p.omega[i] += dw;
            }
            if constexpr (drift) p.position[i] += dt * p.velocity[i];
            if constexpr (watch) {
                moved = moved || (p.position[i] - from[i]).squaredNorm() > limit2;
                if (domain) left = left || domain->loses(p.position[i]);
            }
            if constexpr (reset) {
                p.force[i] = bodyForce(cp, i, g, external);
                p.torque[i].setZero();
            }
        }
        // Meet here rather than at the region's end, where GOMP puts an early
        // thread to sleep (SpinBarrier).
        teamBarrier.arriveAndWait(teamSize());
    }
    return {moved, left};
}

template <int kicks>
DriftReport advanceWith(ParticleStore& p, double dt, std::size_t count, const DriftExtras& e) {
    const bool watch = e.displacementFrom != nullptr;
    if (watch && e.resetForces) return advance<kicks, true, true, true>(p, dt, count, e);
    if (watch) return advance<kicks, true, true, false>(p, dt, count, e);
    if (e.resetForces) return advance<kicks, true, false, true>(p, dt, count, e);
    return advance<kicks, true, false, false>(p, dt, count, e);
}
}  // namespace

void kickAndDrift(ParticleStore& p, double dt, std::size_t count) { advance<1, true, false, false>(p, dt, count, {}); }

void kick(ParticleStore& p, double dt, std::size_t count) { advance<1, false, false, false>(p, dt, count, {}); }

void kickKickAndDrift(ParticleStore& p, double dt, std::size_t count) {
    advance<2, true, false, false>(p, dt, count, {});
}

DriftReport kickAndDrift(ParticleStore& p, double dt, std::size_t count, const DriftExtras& e) {
    return advanceWith<1>(p, dt, count, e);
}

DriftReport kickKickAndDrift(ParticleStore& p, double dt, std::size_t count, const DriftExtras& e) {
    return advanceWith<2>(p, dt, count, e);
}

void resetForces(ParticleStore& p, const Vec3& g) {
    const std::size_t n = p.size();
    const ParticleStore& cp = p;
    const bool external = cp.externalForce.allocated();
#pragma omp parallel for schedule(static) num_threads(threadsFor(n, lightLoopParticlesPerThread))
    for (std::size_t i = 0; i < n; ++i) {
        p.force[i] = bodyForce(cp, i, g, external);
        p.torque[i].setZero();
    }
}

}  // namespace dem
