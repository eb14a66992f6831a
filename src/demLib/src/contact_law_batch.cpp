#include "demLib/contact_law_batch.hpp"

#include <cmath>

namespace dem {

namespace {

// Material-pair constants: one set for the whole batch (read at [0]) or one per lane.
struct PairConstants {
    const double *kn, *kt, *gn, *gt, *mu, *muR, *etaR;
};

// The body of ContactLaw<Rolling>::evaluate and of the pair loop around it
// (contact_force_kernel.cpp), written lane by lane with the same operations in
// the same order.  The comments name the scalar expression each line mirrors.

template <RollingModel Rolling, bool Cohesive, bool Uniform>
DEM_ALWAYS_INLINE void evaluateBatchBody(ContactBatch& b, int count, double dt, const PairConstants& c) {
    using Settings = LiggghtsDefaultContactSettings;
    static_assert(!Settings::limitForce && Settings::tangentialDamping && !Settings::cohesionInFrictionLimits,
                  "the batch mirrors the default switches of ContactLaw");
    // The constants: one value each (uniform batch) or one per lane.
    const double* __restrict knLane = c.kn;
    const double* __restrict ktLane = c.kt;
    const double* __restrict gnLane = c.gn;
    const double* __restrict gtLane = c.gt;
    const double* __restrict muLane = c.mu;
    const double* __restrict muRLane = c.muR;
    const double* __restrict etaRLane = c.etaR;
    const double kn0 = c.kn[0], kt0 = c.kt[0], gn0 = c.gn[0], gt0 = c.gt[0], mu0 = c.mu[0], muR0 = c.muR[0],
                 etaR0 = c.etaR[0];
    const double* __restrict extra = b.extraNormalForce;
    const double* __restrict touching = b.touching;
    const double* __restrict dx = b.dx;
    const double* __restrict dy = b.dy;
    const double* __restrict dz = b.dz;
    const double* __restrict dist2 = b.distanceSquared;
    const double* __restrict ri = b.radiusI;
    const double* __restrict rj = b.radiusJ;
    const double* __restrict mi = b.massI;
    const double* __restrict mj = b.massJ;
    const double* __restrict dvx = b.dvx;
    const double* __restrict dvy = b.dvy;
    const double* __restrict dvz = b.dvz;
    const double* __restrict wix = b.wix;
    const double* __restrict wiy = b.wiy;
    const double* __restrict wiz = b.wiz;
    const double* __restrict wjx = b.wjx;
    const double* __restrict wjy = b.wjy;
    const double* __restrict wjz = b.wjz;
    double* __restrict sxs = b.sx;
    double* __restrict sys = b.sy;
    double* __restrict szs = b.sz;
    double* __restrict mxs = b.mx;
    double* __restrict mys = b.my;
    double* __restrict mzs = b.mz;
    double* __restrict fxs = b.fx;
    double* __restrict fys = b.fy;
    double* __restrict fzs = b.fz;
    double* __restrict tixs = b.tix;
    double* __restrict tiys = b.tiy;
    double* __restrict tizs = b.tiz;
    double* __restrict tjxs = b.tjx;
    double* __restrict tjys = b.tjy;
    double* __restrict tjzs = b.tjz;

#pragma omp simd
    for (int e = 0; e < count; ++e) {
        // --- kinematics (pair loop) ---
        const double radiusSum = ri[e] + rj[e];
        const double dist = std::sqrt(dist2[e]);
        const double inverseDist = 1.0 / dist;
        const double nx = dx[e] * inverseDist, ny = dy[e] * inverseDist, nz = dz[e] * inverseDist;
        const double overlap = radiusSum - dist;
        const double ci = ri[e] - 0.5 * overlap;
        const double cj = rj[e] - 0.5 * overlap;
        const double massSum = mi[e] + mj[e];
        const double inverseSums = 1.0 / (radiusSum * massSum);
        const double radiusEff = ri[e] * rj[e] * massSum * inverseSums;
        const double massEff = mi[e] * mj[e] * radiusSum * inverseSums;
        // relVelocity = (v_i - v_j) - (ci w_i + cj w_j) x n
        const double ax = ci * wix[e] + cj * wjx[e];
        const double ay = ci * wiy[e] + cj * wjy[e];
        const double az = ci * wiz[e] + cj * wjz[e];
        const double vx = dvx[e] - (ay * nz - az * ny);
        const double vy = dvy[e] - (az * nx - ax * nz);
        const double vz = dvz[e] - (ax * ny - ay * nx);
        const double omx = wix[e] - wjx[e], omy = wiy[e] - wjy[e], omz = wiz[e] - wjz[e];

        // --- normal: hertzNormal ---
        const double normalVelocity = vx * nx + vy * ny + vz * nz;
        const double tvx = vx - normalVelocity * nx;
        const double tvy = vy - normalVelocity * ny;
        const double tvz = vz - normalVelocity * nz;
        const double contactScale = std::sqrt(radiusEff * overlap);
        const double dampingScale = std::sqrt(contactScale * massEff);
        const double kn = (Uniform ? kn0 : knLane[e]) * contactScale;
        const double kt = (Uniform ? kt0 : ktLane[e]) * contactScale;
        const double gn = (Uniform ? gn0 : gnLane[e]) * dampingScale;
        const double gt = (Uniform ? gt0 : gtLane[e]) * dampingScale;
        const double elasticForce = kn * overlap;
        const double hertzForce = elasticForce - gn * normalVelocity;
        const double normalForce = hertzForce + (Cohesive ? extra[e] : 0.0);  // + extraNormalForce
        const double limitingNormalForce = std::abs(hertzForce);

        // --- tangential: tangentialHistoryForce ---
        const double frictionLimit = (Uniform ? mu0 : muLane[e]) * limitingNormalForce;
        double sx = sxs[e] + tvx * dt, sy = sys[e] + tvy * dt, sz = szs[e] + tvz * dt;
        const double shearNormal = sx * nx + sy * ny + sz * nz;
        sx = sx - shearNormal * nx;
        sy = sy - shearNormal * ny;
        sz = sz - shearNormal * nz;
        const double shearLengthSquared = sx * sx + sy * sy + sz * sz;
        const double negativeKt = -kt;
        double ftx = negativeKt * sx, fty = negativeKt * sy, ftz = negativeKt * sz;
        const bool sliding = kt * kt * shearLengthSquared > frictionLimit * frictionLimit;
        const double scale = frictionLimit / (kt * std::sqrt(shearLengthSquared));
        ftx = sliding ? ftx * scale : ftx - gt * tvx;
        fty = sliding ? fty * scale : fty - gt * tvy;
        ftz = sliding ? ftz * scale : ftz - gt * tvz;
        sxs[e] = sliding ? sx * scale : sx;
        sys[e] = sliding ? sy * scale : sy;
        szs[e] = sliding ? sz * scale : sz;

        // --- rolling ---
        double rtx = 0.0, rty = 0.0, rtz = 0.0;
        if constexpr (Rolling == RollingModel::CDT) {
            // cdtRollingTorque with lever arm R*
            const double omegaLength = std::sqrt(omx * omx + omy * omy + omz * omz);
            const double factor = (Uniform ? muR0 : muRLane[e]) * elasticForce * radiusEff / omegaLength;
            const double tx = factor * omx, ty = factor * omy, tz = factor * omz;
            const double torqueNormal = tx * nx + ty * ny + tz * nz;
            const bool turning = omegaLength > 0.0;
            rtx = turning ? -(tx - torqueNormal * nx) : 0.0;
            rty = turning ? -(ty - torqueNormal * ny) : 0.0;
            rtz = turning ? -(tz - torqueNormal * nz) : 0.0;
        } else if constexpr (Rolling == RollingModel::EPSD || Rolling == RollingModel::EPSD2) {
            double stiffness = 0.0;
            double viscous = 0.0;
            if constexpr (Rolling == RollingModel::EPSD) {
                stiffness = 2.25 * kn * (Uniform ? muR0 : muRLane[e]) * (Uniform ? muR0 : muRLane[e]) * radiusEff * radiusEff;
                const double reducedI = mi[e] * ri[e] * ri[e];
                const double reducedJ = mj[e] * rj[e] * rj[e];
                const double inertia = 1.4 * reducedI * reducedJ / (reducedI + reducedJ);
                viscous = (Uniform ? etaR0 : etaRLane[e]) * 2.0 * std::sqrt(inertia * stiffness);
            } else {
                stiffness = kt * radiusEff * radiusEff;
            }
            const double torqueLimit = (Uniform ? muR0 : muRLane[e]) * radiusEff * limitingNormalForce;
            // elasticPlasticRollingTorque: b.mx/my/mz hold the rolled angle
            const double omegaNormal = omx * nx + omy * ny + omz * nz;
            const double wtx = omx - omegaNormal * nx;
            const double wty = omy - omegaNormal * ny;
            const double wtz = omz - omegaNormal * nz;
            double thx = mxs[e] + wtx * dt, thy = mys[e] + wty * dt, thz = mzs[e] + wtz * dt;
            const double angleNormal = thx * nx + thy * ny + thz * nz;
            thx = thx - angleNormal * nx;
            thy = thy - angleNormal * ny;
            thz = thz - angleNormal * nz;
            const double negativeStiffness = -stiffness;
            const double mx = negativeStiffness * thx, my = negativeStiffness * thy, mz = negativeStiffness * thz;
            const double torqueSquared = mx * mx + my * my + mz * mz;
            const bool limited = torqueSquared > torqueLimit * torqueLimit;
            const double limitScale = torqueLimit / std::sqrt(torqueSquared);
            mxs[e] = limited ? thx * limitScale : thx;
            mys[e] = limited ? thy * limitScale : thy;
            mzs[e] = limited ? thz * limitScale : thz;
            rtx = limited ? mx * limitScale : mx - viscous * wtx;
            rty = limited ? my * limitScale : my - viscous * wty;
            rtz = limited ? mz * limitScale : mz - viscous * wtz;
        }

        // --- result and torques (pair loop) ---
        fxs[e] = normalForce * nx + ftx;
        fys[e] = normalForce * ny + fty;
        fzs[e] = normalForce * nz + ftz;
        if constexpr (Cohesive) {
            // A bridge beyond contact pulls along the normal only (the law's
            // lanes hold NaN from the negative overlap and are dropped).
            const bool contact = touching[e] != 0.0;
            fxs[e] = contact ? fxs[e] : extra[e] * nx;
            fys[e] = contact ? fys[e] : extra[e] * ny;
            fzs[e] = contact ? fzs[e] : extra[e] * nz;
        }
        const double cx = ny * ftz - nz * fty;  // n x Ft
        const double cy = nz * ftx - nx * ftz;
        const double cz = nx * fty - ny * ftx;
        tixs[e] = -ci * cx + rtx;
        tiys[e] = -ci * cy + rty;
        tizs[e] = -ci * cz + rtz;
        tjxs[e] = -cj * cx - rtx;
        tjys[e] = -cj * cy - rty;
        tjzs[e] = -cj * cz - rtz;
    }
}

}  // namespace

// One clone per instruction set; the loader picks the widest the CPU has.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define DEM_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define DEM_VECTOR_CLONES
#endif

template <RollingModel Rolling, bool Cohesive>
DEM_VECTOR_CLONES void evaluateContactBatch(ContactBatch& batch, int count, double dt) {
    const InteractionProperties* first = batch.properties[0];
    bool uniform = true;
    for (int e = 1; e < count; ++e) uniform = uniform && batch.properties[e] == first;
    if (uniform) {
        const PairConstants c{&first->normalStiffnessFactor, &first->tangentialStiffnessFactor,
                                    &first->normalDampingFactor,   &first->tangentialDampingFactor,
                                    &first->friction,              &first->rollingFriction,
                                    &first->rollingViscousDamping};
        evaluateBatchBody<Rolling, Cohesive, true>(batch, count, dt, c);
        return;
    }
    for (int e = 0; e < count; ++e) {
        const InteractionProperties& props = *batch.properties[e];
        batch.normalStiffnessFactor[e] = props.normalStiffnessFactor;
        batch.tangentialStiffnessFactor[e] = props.tangentialStiffnessFactor;
        batch.normalDampingFactor[e] = props.normalDampingFactor;
        batch.tangentialDampingFactor[e] = props.tangentialDampingFactor;
        batch.friction[e] = props.friction;
        batch.rollingFriction[e] = props.rollingFriction;
        batch.rollingViscousDamping[e] = props.rollingViscousDamping;
    }
    const PairConstants c{batch.normalStiffnessFactor, batch.tangentialStiffnessFactor,
                                 batch.normalDampingFactor,   batch.tangentialDampingFactor,
                                 batch.friction,              batch.rollingFriction,
                                 batch.rollingViscousDamping};
    evaluateBatchBody<Rolling, Cohesive, false>(batch, count, dt, c);
}

template void evaluateContactBatch<RollingModel::None, false>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::None, true>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::CDT, false>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::CDT, true>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::EPSD, false>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::EPSD, true>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::EPSD2, false>(ContactBatch&, int, double);
template void evaluateContactBatch<RollingModel::EPSD2, true>(ContactBatch&, int, double);

}  // namespace dem
