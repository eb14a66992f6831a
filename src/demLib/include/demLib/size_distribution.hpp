#pragma once
// A particle size distribution given as mass fractions per diameter class, as
// sieve analyses report it (e.g. Table 1 of the die-filling paper for F32 sand).
// Diameters are stored already multiplied by the coarse-grain factor, so every
// consumer (population drawing, insertion, logging) sees simulation diameters.
// See docs/insertion.md for the sampling rule and its limits.
#include <cstddef>
#include <string>
#include <vector>

namespace dem {

// One row of a sieve table as the user writes it: a diameter range and the
// percentage of the total MASS that lies in it.
struct SizeClassPercent {
    double dMin = 0.0;
    double dMax = 0.0;
    double massPercent = 0.0;
};

// How a diameter is drawn inside a class [dMin, dMax).
enum class WithinClass {
    UniformDiameter,  // d ~ U(dMin, dMax)            (default)
    UniformVolume,    // d^3 ~ U(dMin^3, dMax^3)
};

struct SizeClass {
    double dMin = 0.0;          // simulation diameter (scaled), same unit as input
    double dMax = 0.0;
    double massFraction = 0.0;  // in [0, 1]; all classes sum to exactly 1
};

class SizeDistribution {
public:
    // Validates the table (dMin > 0, dMax > dMin, percentages >= 0, classes do
    // not overlap, percentages sum to 100 within 0.5) and normalises the mass
    // fractions to sum to 1.  Each diameter is multiplied by `scale` (the
    // coarse-grain factor l).  `context` prefixes every error message, e.g.
    // "case.json: particles.sizeDistribution".  Throws dem::InputError.
    static SizeDistribution fromPercentages(const std::vector<SizeClassPercent>& table,
                                            double scale = 1.0,
                                            WithinClass within = WithinClass::UniformDiameter,
                                            const std::string& context = "size distribution");

    // All particles share one diameter (times scale).
    static SizeDistribution monodisperse(double diameter, double scale = 1.0,
                                         const std::string& context = "size distribution");

    const std::vector<SizeClass>& classes() const { return classes_; }
    std::size_t classCount() const { return classes_.size(); }
    WithinClass withinClass() const { return within_; }
    double scale() const { return scale_; }

    double dMin() const;  // smallest simulation diameter any class can produce
    double dMax() const;  // largest one: sets the insertion lattice spacing

    // Maps u in [0, 1) to a diameter of class i by the within-class rule.
    double diameterInClass(std::size_t i, double u) const;

    // Exact mean of d^3 over class i under the within-class rule.
    double classMeanDiameterCubed(std::size_t i) const;
    // Mean mass of one particle of class i (solid sphere).
    double classMeanParticleMass(std::size_t i, double density) const;
    // Mass of the heaviest particle class i can produce.
    double classMaxParticleMass(std::size_t i, double density) const;

    // Fraction of particles (by number) in each class that reproduces the mass
    // fractions: n_i ∝ w_i / <m>_i.
    std::vector<double> numberFractions() const;

    // Mean particle mass of the whole distribution: 1 / sum_i(w_i / <m>_i).
    double meanParticleMass(double density) const;

    // Index of the class that holds diameter d (classes are [dMin, dMax); the
    // top class also holds its dMax).  Throws std::out_of_range when no class does.
    std::size_t classOf(double d) const;

    // Mass fraction per class (same order as classes()) of a set of diameters;
    // all zeros for an empty set.  Throws std::out_of_range for a diameter
    // outside every class.
    std::vector<double> massFractionsOf(const std::vector<double>& diameters) const;

private:
    SizeDistribution() = default;
    std::vector<SizeClass> classes_;
    WithinClass within_ = WithinClass::UniformDiameter;
    double scale_ = 1.0;
};

// Mass of a solid sphere.
double sphereMass(double diameter, double density);

}  // namespace dem
