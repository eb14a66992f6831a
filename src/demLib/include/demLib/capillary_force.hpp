#pragma once
// Capillary (pendular liquid bridge) cohesion after Richefeu, El Youssoufi &
// Radjaï, Phys. Rev. E 73, 051304 (2006), with the fit of Soulié et al.,
// Int. J. Numer. Anal. Meth. Geomech. 30, 213 (2006); paper eqs 1-5.
//
//   f = -π γ √(R1 R2) [exp(A δ* + B) + C]   for δ* > 0
//   f = -π γ √(R1 R2) [exp(B) + C]          for δ* ≤ 0            (eq 1)
//   A = -1.1 V*^-0.53                                                (eq 2)
//   B = (-0.148 ln V* - 0.96) θ² - 0.0082 ln V* + 0.48               (eq 3)
//   C = 0.0018 ln V* + 0.078                                         (eq 4)
//   δ* = δ/R2, V* = V_b/R2³, R1 ≤ R2, bridge breaks beyond
//   δmax = (1 + θ/2) V_b^(1/3)                                       (eq 5)
//
// Sign: negative = attractive, as the paper writes eq 1.  The force acts along
// the line of centres; the engine adds it to the contact law's normal force
// (extraNormalForce), so it also raises the Coulomb friction limit μ|Fn|.
//
// Everything here is inline and allocation-free: it is called once per bonded
// pair and time step.  Preconditions on the hot path (radii > 0, θ in radians)
// are the caller's; validateCapillaryParameters() checks user input once.
#include <cmath>
#include <string>
#include <utility>

#include "demLib/constants.hpp"
#include "demLib/error.hpp"

namespace dem {

struct CapillaryParameters {
    double surfaceTension = 0.072;  // γ [N/m], water at 20 °C
    double contactAngle = 0.0;      // θ [rad]
};

// The fit coefficients of eqs 2-4 for a reduced bridge volume V* = V_b/R2³.
struct CapillaryFitCoefficients {
    double A;
    double B;
    double C;
};

// Eqs 2-4 one by one (B and C take ln V*, computed once by the caller).
inline double capillaryFitA(double reducedVolume) { return -1.1 * std::pow(reducedVolume, -0.53); }
inline double capillaryFitB(double logReducedVolume, double contactAngle) {
    return (-0.148 * logReducedVolume - 0.96) * (contactAngle * contactAngle) - 0.0082 * logReducedVolume + 0.48;
}
inline double capillaryFitC(double logReducedVolume) { return 0.0018 * logReducedVolume + 0.078; }

inline CapillaryFitCoefficients capillaryFitCoefficients(double reducedVolume, double contactAngle) {
    const double logVolume = std::log(reducedVolume);
    return {capillaryFitA(reducedVolume), capillaryFitB(logVolume, contactAngle), capillaryFitC(logVolume)};
}

// Eq 5: the gap beyond which the bridge of volume V_b is unstable and breaks.
inline double debondingDistance(double bridgeVolume, double contactAngle) {
    return (1.0 + 0.5 * contactAngle) * std::cbrt(bridgeVolume);
}

// What eq 1 needs of one bridge besides its gap, fixed while its volume and
// radii are: a bridge is evaluated at every step between list updates, its
// volume only changes at them, so the force loop keeps these per bridge and
// spends one exp per step on a bridge across a gap and none on one in contact.
struct CapillaryBridgeFit {
    double debonding = 0.0;     // δmax, eq 5
    double largerRadius = 0.0;  // R2
    double A = 0.0, B = 0.0, C = 0.0;
    double prefactor = 0.0;     // -π γ √(R1 R2)
    double contactForce = 0.0;  // eq 1 at δ* <= 0: prefactor (exp(B) + C)
};

inline CapillaryBridgeFit capillaryBridgeFit(double radius1, double radius2, double bridgeVolume,
                                             const CapillaryParameters& parameters) {
    if (radius1 > radius2) std::swap(radius1, radius2);  // the fit is written for R1 ≤ R2
    CapillaryBridgeFit fit;
    fit.debonding = debondingDistance(bridgeVolume, parameters.contactAngle);
    fit.largerRadius = radius2;
    const double reducedVolume = bridgeVolume / (radius2 * radius2 * radius2);
    const double logVolume = std::log(reducedVolume);
    fit.A = capillaryFitA(reducedVolume);
    fit.B = capillaryFitB(logVolume, parameters.contactAngle);
    fit.C = capillaryFitC(logVolume);
    fit.prefactor = -pi * parameters.surfaceTension * std::sqrt(radius1 * radius2);
    fit.contactForce = fit.prefactor * (std::exp(fit.B) + fit.C);
    return fit;
}

// Eq 1 of a fitted bridge at `gap` (within its debonding distance).
inline double capillaryForceOfFit(const CapillaryBridgeFit& fit, double gap) {
    // In contact no division: a gap > 0 whose δ* underflows to 0 gives
    // exp(A·0 + B) + C, the contact value, on either branch.
    if (!(gap > 0.0)) return fit.contactForce;
    const double reducedGap = gap / fit.largerRadius;
    return fit.prefactor * (std::exp(fit.A * reducedGap + fit.B) + fit.C);
}

// Eq 1 between spheres of radii R1, R2 (either order) separated by `gap`
// (surface-to-surface; negative when they overlap) and joined by a bridge of
// volume `bridgeVolume`.  Zero when there is no liquid or gap > δmax (eq 5).
inline double capillaryForce(double radius1, double radius2, double gap, double bridgeVolume,
                             const CapillaryParameters& parameters) {
    if (!(bridgeVolume > 0.0)) return 0.0;
    const CapillaryBridgeFit fit = capillaryBridgeFit(radius1, radius2, bridgeVolume, parameters);
    if (gap > fit.debonding) return 0.0;
    return capillaryForceOfFit(fit, gap);
}

// The radius of the sphere pair that stands in for a sphere-plane bridge.
// Eq 1 has no plane limit: √(R1 R2) diverges as R2 → ∞ while δ* and V* go to
// zero.  In the thin-bridge (Derjaguin) picture the meniscus only sees the gap
// profile h(r) = δ + r²/(2 R_eq) with 1/R_eq = 1/R1 + 1/R2; a plane gives
// R_eq = R, two equal spheres of radius 2R give the same profile.  So a
// particle-wall bridge is evaluated as the bridge between two spheres of
// radius 2R.  At contact this doubles the equal-sphere force, as the classical
// limits 2πγR cosθ (two spheres) and 4πγR cosθ (sphere-plane) require.
inline double wallEquivalentRadius(double particleRadius) { return 2.0 * particleRadius; }

// Particle-wall bridge: `gap` is the distance from the sphere surface to the
// wall (negative when overlapping).  The debonding distance is eq 5 unchanged.
inline double capillaryForceSphereWall(double particleRadius, double gap, double bridgeVolume,
                                       const CapillaryParameters& parameters) {
    const double equivalentRadius = wallEquivalentRadius(particleRadius);
    return capillaryForce(equivalentRadius, equivalentRadius, gap, bridgeVolume, parameters);
}

// Checks user input once (not on the hot path).  The fit of eqs 2-4 was made
// for wetting liquids, 0 ≤ θ < π/2.  `source` names the case file, if known.
inline void validateCapillaryParameters(const CapillaryParameters& parameters,
                                        const std::string& source = "capillary model") {
    if (!(parameters.surfaceTension >= 0.0) || !std::isfinite(parameters.surfaceTension))
        throw InputError(source + ": keyword 'surfaceTension' expects a finite number >= 0 [N/m], got " +
                         std::to_string(parameters.surfaceTension));
    if (!(parameters.contactAngle >= 0.0 && parameters.contactAngle < 0.5 * pi))
        throw InputError(source + ": keyword 'contactAngle' expects radians in [0, pi/2), got " +
                         std::to_string(parameters.contactAngle));
}

}  // namespace dem
