#pragma once
// Stability of the explicit time integration for contacts held closed.
//
// The Rayleigh and Hertz criteria (contact_law.hpp) look at one undamped
// contact.  A grain held in place by several damped contacts - as every grain of
// a wet bed is, pressed into its neighbours by capillary forces of hundreds of
// its weights - has stiffer and more heavily damped modes: its spin and sliding
// against its neighbours (the tangential springs and dashpots of all its
// contacts act on one rotational inertia 0.4 m R^2).  The engine's velocity
// Verlet step (half kick, drift, forces from the new positions and the
// half-step velocities, half kick) integrates a mode of frequency w and damping
// ratio z stably only for  w dt <= 2 (sqrt(1 + z^2) - z)  (2 undamped, 0.83 at
// z = 1); beyond it the mode grows until friction caps it, and the bed rattles
// at rest.  docs/engine.md, "Time-step limits", has the derivation and the
// measurements.
#include <Eigen/Core>

#include "demLib/capillary_force.hpp"
#include "demLib/contact_law.hpp"
#include "demLib/interaction_properties.hpp"

namespace dem {

// One particle's linearised dynamics about rest, neighbours held fixed:
// generalised coordinates q = (translation x y z, rotation x y z),
// mass q'' = -stiffness q - damping q'.
struct ContactClusterModel {
    Eigen::Matrix<double, 6, 6> mass = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 6> stiffness = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 6> damping = Eigen::Matrix<double, 6, 6>::Zero();
};

// Springs and dashpots of one contact, linearised at its overlap (tangent
// normal stiffness dF/dd = 2 Y* a, tangential k_t = 8 G* a, a = sqrt(R* d);
// the rolling spring of EPSD/EPSD2 acts on the rotation's tangential part).
struct LinearContact {
    double normalStiffness = 0.0;      // [N/m]
    double tangentialStiffness = 0.0;  // [N/m]
    double normalDamping = 0.0;        // [kg/s]
    double tangentialDamping = 0.0;    // [kg/s]
    double rollingStiffness = 0.0;     // [N m/rad]
    double rollingDamping = 0.0;       // [N m s/rad]
};

// The Hertz-Mindlin contact of `props` at overlap d (> 0) between bodies of
// effective radius and mass radiusEff, massEff, linearised, with the rolling
// spring (and EPSD's dashpot) of `rolling` in its elastic range; CDT and none
// add no spring.  rollingInertia: EPSD's I_r (rollingInertiaEff).
LinearContact linearHertzContact(const InteractionProperties& props, double radiusEff, double massEff,
                                 double overlap, RollingModel rolling = RollingModel::None,
                                 double rollingInertia = 0.0);

// A sphere (radius, mass, moment of inertia 0.4 m R^2) with one contact of the
// same law towards each of the six directions +-x, +-y, +-z, at `leverArm` from
// its centre (the engine's c = R - d/2).
ContactClusterModel cubicContactCluster(double radius, double mass, const LinearContact& contact, double leverArm);
// The same with one contact of outward normal `normal` (the side it touches).
void addContact(ContactClusterModel& model, double leverArm, const Eigen::Vector3d& normal,
                const LinearContact& contact);

// Largest modulus of the eigenvalues of one velocity Verlet step of `model`.
double verletSpectralRadius(const ContactClusterModel& model, double dt);

// The largest dt for which no mode of `model` grows (spectral radius <= 1 +
// 1e-5, so that the neutral modes of an unconstrained direction do not count),
// to a relative 1e-9; infinity for a model without stiffness.
double verletStableTimeStep(const ContactClusterModel& model);

// How many spheres of radius R fit around one of radius r = ratio R, all
// touching it (the Tammes problem: N caps of angular radius
// asin(1 / (1 + ratio)) on a sphere): 12 for ratio >= 0.902 (equal spheres),
// 10, 9, 8, 7 down to ratio 0.591, then 6 (from 0.414; 5 fits no sooner),
// 4 (0.225), 3 (0.155), else 2.
int contactNumberAround(double ratio);

// The contact force eqs 1-5 (times `forceScale`, the coarse-grain factor l^k
// of eq 9) give for a bridge between touching spheres of radii r1 and r2, at
// the reduced volume V* = V/r2^3 in [1e-5, 1e-1] that gives the largest force
// (the force depends on V* only logarithmically) [N, >= 0].
double capillaryContactForceBound(double radius1, double radius2, const CapillaryParameters& capillary,
                                  double forceScale);

// The stable time step of the smallest particle (radius, material) of a wet
// bed, pressed by capillary bridges into N of the largest particles
// (neighbourRadius, neighbourMaterial) around it: each contact carries the
// capillary force at contact, compressed to the Hertz overlap of that force.
// N = contactNumberAround(radius / neighbourRadius), but at least six: a
// grain among equal ones has twelve neighbours (a wet monodisperse bed packs
// with 9-12 contacts per grain), and the six of a small grain among large
// ones stand for its contacts with the middle sizes (docs/engine.md).  The N
// contacts act as the six along +-x, +-y, +-z with springs and dashpots
// times N/6: exact for twelve in an icosahedron (both arrangements have
// sum n n^T = N/3 I and sum n = 0), an isotropic approximation for 7-10,
// whose closest packings are not isotropic (for eight, a square antiprism,
// the step is 0.91 of the approximation's; the engine's default fraction 0.9
// covers it).  neighbourCount > 0 sets N instead.
// The neighbours move too: each contact's springs and dashpots are scaled by
// 1 + m/m_neighbour, exact for two bodies moving against each other (2 for
// equal spheres, ~1 for a small grain among large ones).
// `props` is the interaction of the two materials, `rolling` the run's model.
double capillaryClusterStableTimeStep(double radius, const Material& material, double neighbourRadius,
                                      const Material& neighbourMaterial, const InteractionProperties& props,
                                      const CapillaryParameters& capillary, double forceScale,
                                      RollingModel rolling = RollingModel::None, int neighbourCount = 0);

}  // namespace dem
