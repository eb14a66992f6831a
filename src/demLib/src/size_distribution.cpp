// Seeded results must be bitwise identical across compilers and flags: keep
// every floating-point operation separately rounded (no fused multiply-add,
// which -march=native with GNU extensions would otherwise generate).
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "demLib/size_distribution.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "demLib/constants.hpp"
#include "demLib/error.hpp"

namespace dem {

namespace {

// Table 1 style inputs are rounded to whole percent; 0.5 accepts rounding but
// rejects a forgotten row.
constexpr double percentSumTolerance = 0.5;

std::string describeClass(std::size_t i, const SizeClassPercent& c) {
    std::ostringstream s;
    s << "class " << i + 1 << " (dMin = " << c.dMin << ", dMax = " << c.dMax
      << ", massPercent = " << c.massPercent << ")";
    return s.str();
}

}  // namespace

double sphereMass(double diameter, double density) {
    return density * pi / 6.0 * diameter * diameter * diameter;
}

SizeDistribution SizeDistribution::fromPercentages(const std::vector<SizeClassPercent>& table,
                                                   double scale, WithinClass within,
                                                   const std::string& context) {
    if (table.empty())
        throw InputError(context + ": expected at least one size class {dMin, dMax, massPercent}");
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        std::ostringstream s;
        s << context << ": coarse-grain scale must be a finite number > 0, got " << scale;
        throw InputError(s.str());
    }
    for (std::size_t i = 0; i < table.size(); ++i) {
        const SizeClassPercent& c = table[i];
        if (!(c.dMin > 0.0) || !std::isfinite(c.dMin))
            throw InputError(context + ": " + describeClass(i, c) + ": expected dMin > 0");
        if (!(c.dMax > c.dMin) || !std::isfinite(c.dMax))
            throw InputError(context + ": " + describeClass(i, c) +
                             ": expected dMax > dMin (an open class such as '> 0.355' needs an "
                             "explicit upper diameter)");
        if (!(c.massPercent >= 0.0) || !std::isfinite(c.massPercent))
            throw InputError(context + ": " + describeClass(i, c) + ": expected massPercent >= 0");
    }
    // Overlap check on the classes sorted by dMin; touching ends are allowed.
    std::vector<std::size_t> order(table.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return table[a].dMin < table[b].dMin; });
    for (std::size_t k = 1; k < order.size(); ++k) {
        const std::size_t lower = order[k - 1], upper = order[k];
        if (table[upper].dMin < table[lower].dMax) {
            std::ostringstream s;
            s << context << ": " << describeClass(upper, table[upper]) << " overlaps "
              << describeClass(lower, table[lower]) << ": expected dMin >= " << table[lower].dMax;
            throw InputError(s.str());
        }
    }
    double sum = 0.0;
    for (const SizeClassPercent& c : table) sum += c.massPercent;
    if (std::abs(sum - 100.0) > percentSumTolerance) {
        std::ostringstream s;
        s << context << ": mass percentages of classes 1.." << table.size() << " sum to " << sum
          << ", expected 100 (within " << percentSumTolerance << ")";
        if (sum < 100.0) s << "; is a class missing?";
        throw InputError(s.str());
    }

    SizeDistribution d;
    d.within_ = within;
    d.scale_ = scale;
    d.classes_.reserve(table.size());
    for (const SizeClassPercent& c : table)
        d.classes_.push_back({c.dMin * scale, c.dMax * scale, c.massPercent / sum});
    return d;
}

SizeDistribution SizeDistribution::monodisperse(double diameter, double scale,
                                                const std::string& context) {
    if (!(diameter > 0.0) || !std::isfinite(diameter)) {
        std::ostringstream s;
        s << context << ": monodisperse diameter must be a finite number > 0, got " << diameter;
        throw InputError(s.str());
    }
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        std::ostringstream s;
        s << context << ": coarse-grain scale must be a finite number > 0, got " << scale;
        throw InputError(s.str());
    }
    SizeDistribution d;
    d.scale_ = scale;
    d.classes_.push_back({diameter * scale, diameter * scale, 1.0});
    return d;
}

double SizeDistribution::dMin() const {
    double m = std::numeric_limits<double>::infinity();
    for (const SizeClass& c : classes_)
        if (c.massFraction > 0.0) m = std::min(m, c.dMin);
    return m;
}

double SizeDistribution::dMax() const {
    double m = 0.0;
    for (const SizeClass& c : classes_)
        if (c.massFraction > 0.0) m = std::max(m, c.dMax);
    return m;
}

double SizeDistribution::diameterInClass(std::size_t i, double u) const {
    const SizeClass& c = classes_.at(i);
    if (c.dMax == c.dMin) return c.dMin;
    double d = 0.0;
    if (within_ == WithinClass::UniformVolume) {
        const double a3 = c.dMin * c.dMin * c.dMin, b3 = c.dMax * c.dMax * c.dMax;
        d = std::cbrt(a3 + u * (b3 - a3));
    } else {
        d = c.dMin + u * (c.dMax - c.dMin);
    }
    // Rounding must not push a diameter into the neighbouring class.
    return std::min(std::max(d, c.dMin), std::nextafter(c.dMax, c.dMin));
}

double SizeDistribution::classMeanDiameterCubed(std::size_t i) const {
    const SizeClass& c = classes_.at(i);
    const double a = c.dMin, b = c.dMax;
    if (b == a) return a * a * a;
    if (within_ == WithinClass::UniformVolume) return 0.5 * (a * a * a + b * b * b);
    // E[d^3] for d ~ U(a, b) = (b^4 - a^4) / (4 (b - a)), factored to avoid cancellation.
    return 0.25 * (a + b) * (a * a + b * b);
}

double SizeDistribution::classMeanParticleMass(std::size_t i, double density) const {
    return density * pi / 6.0 * classMeanDiameterCubed(i);
}

double SizeDistribution::classMaxParticleMass(std::size_t i, double density) const {
    return sphereMass(classes_.at(i).dMax, density);
}

std::vector<double> SizeDistribution::numberFractions() const {
    std::vector<double> n(classes_.size());
    double total = 0.0;
    for (std::size_t i = 0; i < classes_.size(); ++i) {
        n[i] = classes_[i].massFraction / classMeanDiameterCubed(i);
        total += n[i];
    }
    for (double& x : n) x /= total;
    return n;
}

double SizeDistribution::meanParticleMass(double density) const {
    double inverse = 0.0;
    for (std::size_t i = 0; i < classes_.size(); ++i)
        inverse += classes_[i].massFraction / classMeanParticleMass(i, density);
    return 1.0 / inverse;
}

std::size_t SizeDistribution::classOf(double d) const {
    std::size_t top = 0;
    for (std::size_t i = 0; i < classes_.size(); ++i) {
        if (d >= classes_[i].dMin && d < classes_[i].dMax) return i;
        if (classes_[i].dMax > classes_[top].dMax) top = i;
    }
    if (d == classes_[top].dMax) return top;
    std::ostringstream s;
    s << "SizeDistribution::classOf: diameter " << d << " lies in no class";
    throw std::out_of_range(s.str());
}

std::vector<double> SizeDistribution::massFractionsOf(const std::vector<double>& diameters) const {
    std::vector<double> mass(classes_.size(), 0.0);
    double total = 0.0;
    for (double d : diameters) {
        const double m = d * d * d;  // the common factor rho*pi/6 cancels
        mass[classOf(d)] += m;
        total += m;
    }
    if (total > 0.0)
        for (double& x : mass) x /= total;
    return mass;
}

}  // namespace dem
