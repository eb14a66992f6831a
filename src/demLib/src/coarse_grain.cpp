#include "demLib/coarse_grain.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "demLib/error.hpp"

namespace dem {

void validateCoarseGrainSettings(const CoarseGrainSettings& settings, const std::string& factorSource,
                                 const std::string& exponentSource) {
    auto shown = [](double v) {
        std::ostringstream s;
        s << v;  // -5, not std::to_string's -5.000000
        return s.str();
    };
    if (!(settings.factor >= 1.0) || !std::isfinite(settings.factor))
        throw InputError(factorSource + ": expected a number >= 1 (1: no coarse graining), got " +
                         shown(settings.factor));
    if (!(settings.capillaryExponent >= 0.0 && settings.capillaryExponent <= 3.0))
        throw InputError(exponentSource + ": expected a number in [0, 3] (paper eq 9: 2.0142), got " +
                         shown(settings.capillaryExponent));
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
