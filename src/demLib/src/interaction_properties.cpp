#include "demLib/interaction_properties.hpp"

#include <cmath>
#include <sstream>

#include "demLib/constants.hpp"
#include "demLib/contact_normal_hertz.hpp"  // kSqrtFiveSixths
#include "demLib/error.hpp"

namespace dem {
namespace {


std::string pairLabel(const Material& a, const Material& b) {
    return "materials '" + a.name + "' and '" + b.name + "'";
}

[[noreturn]] void throwRange(const std::string& keyword, const std::string& owner, double value,
                             const std::string& expected) {
    std::ostringstream message;
    message << keyword << " of " << owner << " is " << value << ": expected " << expected;
    throw InputError(message.str());
}

}  // namespace

void validateMaterial(const Material& material) {
    const std::string owner = "material '" + material.name + "'";
    // Written as !(ok) so that NaN is rejected too.
    if (!(material.youngsModulus > 0.0) || !std::isfinite(material.youngsModulus))
        throwRange("youngsModulus", owner, material.youngsModulus, "a finite value > 0 [Pa]");
    if (!(material.poissonRatio >= 0.0 && material.poissonRatio <= 0.5))
        throwRange("poissonRatio", owner, material.poissonRatio, "0 <= poissonRatio <= 0.5");
    if (!(material.density > 0.0) || !std::isfinite(material.density))
        throwRange("density", owner, material.density, "a finite value > 0 [kg/m^3]");
}

double effectiveYoungsModulus(const Material& a, const Material& b) {
    return 1.0 / ((1.0 - a.poissonRatio * a.poissonRatio) / a.youngsModulus +
                  (1.0 - b.poissonRatio * b.poissonRatio) / b.youngsModulus);
}

double effectiveShearModulus(const Material& a, const Material& b) {
    // (2 - nu)/G with G = E / (2(1 + nu)), as in LIGGGHTS createGeff.
    return 1.0 / (2.0 * (2.0 - a.poissonRatio) * (1.0 + a.poissonRatio) / a.youngsModulus +
                  2.0 * (2.0 - b.poissonRatio) * (1.0 + b.poissonRatio) / b.youngsModulus);
}

double dampingBetaFromRestitution(double restitution) {
    const double logE = std::log(restitution);
    return logE / std::sqrt(logE * logE + pi * pi);
}

InteractionProperties makeInteraction(const Material& a, const Material& b,
                                      const PairCoefficients& coefficients) {
    validateMaterial(a);
    validateMaterial(b);
    const std::string owner = pairLabel(a, b);
    // LIGGGHTS itself demands 0.05 < e <= 1; any e in (0, 1] is well defined here.
    if (!(coefficients.restitution > 0.0 && coefficients.restitution <= 1.0))
        throwRange("restitution", owner, coefficients.restitution, "0 < restitution <= 1");
    if (!(coefficients.friction >= 0.0) || !std::isfinite(coefficients.friction))
        throwRange("friction", owner, coefficients.friction, "a finite value >= 0");
    if (!(coefficients.rollingFriction >= 0.0) || !std::isfinite(coefficients.rollingFriction))
        throwRange("rollingFriction", owner, coefficients.rollingFriction, "a finite value >= 0");
    if (!(coefficients.rollingViscousDamping >= 0.0) ||
        !std::isfinite(coefficients.rollingViscousDamping))
        throwRange("rollingViscousDamping", owner, coefficients.rollingViscousDamping,
                   "a finite value >= 0");

    InteractionProperties properties;
    properties.youngsEff = effectiveYoungsModulus(a, b);
    properties.shearEff = effectiveShearModulus(a, b);
    properties.beta = dampingBetaFromRestitution(coefficients.restitution);
    properties.friction = coefficients.friction;
    properties.rollingFriction = coefficients.rollingFriction;
    properties.rollingViscousDamping = coefficients.rollingViscousDamping;
    const double dampingPrefactor = -2.0 * kSqrtFiveSixths * properties.beta;
    properties.normalStiffnessFactor = 4.0 / 3.0 * properties.youngsEff;
    properties.tangentialStiffnessFactor = 8.0 * properties.shearEff;
    properties.normalDampingFactor = dampingPrefactor * std::sqrt(2.0 * properties.youngsEff);
    properties.tangentialDampingFactor = dampingPrefactor * std::sqrt(8.0 * properties.shearEff);
    return properties;
}

InteractionTable::InteractionTable(std::size_t materialCount)
    : materialCount_(materialCount),
      entries_(materialCount * materialCount),
      assigned_(materialCount * materialCount, 0) {}

void InteractionTable::set(std::size_t a, std::size_t b, const InteractionProperties& properties) {
    if (a >= materialCount_ || b >= materialCount_) {
        std::ostringstream message;
        message << "material index pair (" << a << ", " << b << "): expected indices below "
                << materialCount_;
        throw InputError(message.str());
    }
    entries_[a * materialCount_ + b] = properties;
    entries_[b * materialCount_ + a] = properties;
    assigned_[a * materialCount_ + b] = 1;
    assigned_[b * materialCount_ + a] = 1;
}

void InteractionTable::set(const std::vector<Material>& materials, std::size_t a, std::size_t b,
                           const PairCoefficients& coefficients) {
    if (a >= materials.size() || b >= materials.size()) {
        std::ostringstream message;
        message << "material index pair (" << a << ", " << b << "): expected indices below "
                << materials.size();
        throw InputError(message.str());
    }
    set(a, b, makeInteraction(materials[a], materials[b], coefficients));
}

bool InteractionTable::isSet(std::size_t a, std::size_t b) const {
    return a < materialCount_ && b < materialCount_ && assigned_[a * materialCount_ + b] != 0;
}

void InteractionTable::requireComplete(const std::vector<Material>& materials) const {
    for (std::size_t a = 0; a < materialCount_; ++a) {
        for (std::size_t b = a; b < materialCount_; ++b) {
            if (isSet(a, b)) continue;
            const std::string nameA = a < materials.size() ? materials[a].name : std::to_string(a);
            const std::string nameB = b < materials.size() ? materials[b].name : std::to_string(b);
            throw InputError("pair coefficients (restitution, friction, rollingFriction) for "
                             "materials '" + nameA + "' and '" + nameB +
                             "': expected a definition for every pair of materials");
        }
    }
}

}  // namespace dem
