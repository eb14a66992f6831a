#include "demLib/coarse_grain.hpp"

#include <cmath>
#include <string>

#include "demLib/error.hpp"

namespace dem {

void validateCoarseGrainSettings(const CoarseGrainSettings& settings, const std::string& source) {
    if (!(settings.factor >= 1.0) || !std::isfinite(settings.factor))
        throw InputError(source + ": keyword 'coarseGrainFactor' expects a finite number >= 1, got " +
                         std::to_string(settings.factor));
    if (!(settings.capillaryExponent >= 0.0 && settings.capillaryExponent <= 3.0))
        throw InputError(source + ": keyword 'capillaryExponent' expects a number in [0, 3] (paper eq 9: 2.0142), got " +
                         std::to_string(settings.capillaryExponent));
}

double coarseGrainCapillaryFactor(double l, double kappa) { return std::pow(l, kappa); }

double coarseGrainCapillaryForce(double forceFromCoarseGeometry, double l, double kappa) {
    return forceFromCoarseGeometry * coarseGrainCapillaryFactor(l, kappa);
}

double coarseGrainedCapillaryForce(double coarseRadius1, double coarseRadius2, double coarseGap,
                                   double coarseBridgeVolume, const CapillaryParameters& capillary,
                                   const CoarseGrainSettings& coarseGrain) {
    return coarseGrainCapillaryForce(
        capillaryForce(coarseRadius1, coarseRadius2, coarseGap, coarseBridgeVolume, capillary), coarseGrain.factor,
        coarseGrain.capillaryExponent);
}

double coarseGrainedCapillaryForceSphereWall(double coarseRadius, double coarseGap, double coarseBridgeVolume,
                                             const CapillaryParameters& capillary,
                                             const CoarseGrainSettings& coarseGrain) {
    return coarseGrainCapillaryForce(capillaryForceSphereWall(coarseRadius, coarseGap, coarseBridgeVolume, capillary),
                                     coarseGrain.factor, coarseGrain.capillaryExponent);
}

double capillaryBondNumber(double capillaryForce, double particleWeight) {
    return std::abs(capillaryForce) / particleWeight;
}

}  // namespace dem
