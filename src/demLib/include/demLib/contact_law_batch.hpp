#pragma once
// The pair contact law of contact_law.hpp evaluated over a batch of touching
// particle pairs held as structure-of-arrays, so that the compiler evaluates
// several contacts at once in the lanes of a vector register (SSE2: 2, AVX2: 4,
// AVX-512: 8; chosen at run time by GCC's target_clones).
//
// Each lane performs exactly the operations of the scalar law, in the same order
// (IEEE add, mul, div and sqrt round the same in every lane width, and demLib is
// built with -ffp-contract=off so that no clone fuses a multiply-add): the results
// are bitwise those of ContactLaw::evaluate.  The branches of the law (Coulomb
// sliding, rolling-torque limit, CDT at rest) become selects: both sides are
// computed and one is kept.  Tested in test_contact_law_batch.cpp.
#include "demLib/contact_law.hpp"

namespace dem {

// One batch of touching pairs (i, j), filled by the pair loop in list order.
// Inputs are what ContactLaw needs before any arithmetic of its own; outputs are
// the force on i and the torques on i and j; the history is updated in place.
// Fixed-size arrays in one object: every field is one base register plus a
// constant offset away, in the filling loop and in the vector loop.
struct ContactBatch {
    static constexpr int capacity = 128;

    // bookkeeping for the pair loop: list entry k, particles i and j
    int entry[capacity], particleI[capacity], particleJ[capacity];
    // the material pair of each contact (the vector loop reads the constants
    // of the first one when all are the same, else copies them per lane)
    const InteractionProperties* properties[capacity];
    // inputs: d = x_i - x_j and |d|^2, radii, masses, v_i - v_j, w_i, w_j
    alignas(64) double dx[capacity], dy[capacity], dz[capacity], distanceSquared[capacity];
    alignas(64) double radiusI[capacity], radiusJ[capacity], massI[capacity], massJ[capacity];
    alignas(64) double dvx[capacity], dvy[capacity], dvz[capacity];
    alignas(64) double wix[capacity], wiy[capacity], wiz[capacity], wjx[capacity], wjy[capacity], wjz[capacity];
    // with cohesion only: the cohesive normal force (ContactLaw's extraNormalForce),
    // and 1 for a touching pair, 0 for a bridge beyond contact (force = cohesive
    // force along the normal, no torque, no history)
    alignas(64) double extraNormalForce[capacity], touching[capacity];
    // history, read and written: shear displacement, EPSD/EPSD2 rolled angle
    alignas(64) double sx[capacity], sy[capacity], sz[capacity], mx[capacity], my[capacity], mz[capacity];
    // outputs: total force on i (j gets the opposite), torques on i and on j
    alignas(64) double fx[capacity], fy[capacity], fz[capacity];
    alignas(64) double tix[capacity], tiy[capacity], tiz[capacity], tjx[capacity], tjy[capacity], tjz[capacity];
    // per-lane copies of the material-pair constants (mixed batches only)
    alignas(64) double normalStiffnessFactor[capacity], tangentialStiffnessFactor[capacity];
    alignas(64) double normalDampingFactor[capacity], tangentialDampingFactor[capacity];
    alignas(64) double friction[capacity], rollingFriction[capacity], rollingViscousDamping[capacity];
};

// Evaluates entries [0, count) of the batch, count <= capacity.  Without
// cohesion every entry must touch (distanceSquared < (radiusI + radiusJ)^2) and
// extraNormalForce and touching are not read.
template <RollingModel Rolling, bool Cohesive>
void evaluateContactBatch(ContactBatch& batch, int count, double dt);

}  // namespace dem
