#pragma once
// Material data and the per-pair constants that the contact laws need, derived
// once per material pair exactly as LIGGGHTS 3.8 derives them
// (src/global_properties.cpp: createYeff, createGeff, createBetaEff).
// See docs/contact-models.md for the formulas and their references.
#include <cstddef>
#include <string>
#include <vector>

namespace dem {

// One bulk material (SI units: Pa, -, kg/m^3).
struct Material {
    std::string name;
    double youngsModulus = 0.0;
    double poissonRatio = 0.0;
    double density = 0.0;
};

// Coefficients that belong to a pair of materials, not to one material.
struct PairCoefficients {
    double restitution = 1.0;            // e, 0 < e <= 1
    double friction = 0.0;               // Coulomb mu >= 0
    double rollingFriction = 0.0;        // mu_r >= 0 (CDT, EPSD, EPSD2)
    double rollingViscousDamping = 0.0;  // eta_r >= 0 (EPSD only)
};

// What the contact laws read for one pair of materials.
struct InteractionProperties {
    double youngsEff = 0.0;   // Y* = 1 / ((1-nu1^2)/E1 + (1-nu2^2)/E2)             [Pa]
    double shearEff = 0.0;    // G* = 1 / (2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2)   [Pa]
    double beta = 0.0;        // ln e / sqrt(ln^2 e + pi^2)  (<= 0)                  [-]
    double friction = 0.0;
    double rollingFriction = 0.0;
    double rollingViscousDamping = 0.0;
    // Derived once per material pair by makeInteraction (and only there), so
    // that a contact evaluates the Hertz coefficients from a = sqrt(R* d) and
    // sqrt(a m*) with two square roots instead of four (docs/contact-models.md):
    //   kn = normalStiffnessFactor a,  kt = tangentialStiffnessFactor a,
    //   gn = normalDampingFactor sqrt(a m*),  gt = tangentialDampingFactor sqrt(a m*).
    double normalStiffnessFactor = 0.0;      // 4/3 Y*                         [Pa]
    double tangentialStiffnessFactor = 0.0;  // 8 G*                           [Pa]
    double normalDampingFactor = 0.0;        // -2 sqrt(5/6) beta sqrt(2 Y*)   [Pa^0.5]
    double tangentialDampingFactor = 0.0;    // -2 sqrt(5/6) beta sqrt(8 G*)   [Pa^0.5]
};

// Throws InputError unless E > 0, 0 <= nu <= 0.5 and density > 0.
void validateMaterial(const Material& material);

double effectiveYoungsModulus(const Material& a, const Material& b);
double effectiveShearModulus(const Material& a, const Material& b);
// beta(e) = ln e / sqrt(ln^2 e + pi^2); e must lie in (0, 1].
double dampingBetaFromRestitution(double restitution);

// Validates both materials and the coefficients (InputError naming the quantity,
// the two materials and the accepted range) and derives the pair constants.
InteractionProperties makeInteraction(const Material& a, const Material& b,
                                      const PairCoefficients& coefficients);

// Symmetric n x n table of InteractionProperties indexed by material index.
// Stored in full (both triangles) in one flat array so that a lookup is one
// multiply-add and no branch: table(i, j) is table.entries_[i * n + j].
class InteractionTable {
public:
    InteractionTable() = default;
    explicit InteractionTable(std::size_t materialCount);

    std::size_t materialCount() const noexcept { return materialCount_; }

    // Sets (a, b) and (b, a).  Throws InputError if an index is out of range.
    void set(std::size_t a, std::size_t b, const InteractionProperties& properties);
    // Convenience: set(a, b, makeInteraction(materials[a], materials[b], coefficients)).
    void set(const std::vector<Material>& materials, std::size_t a, std::size_t b,
             const PairCoefficients& coefficients);

    bool isSet(std::size_t a, std::size_t b) const;

    // Hot-loop lookup: no range check.
    const InteractionProperties& operator()(std::size_t a, std::size_t b) const noexcept {
        return entries_[a * materialCount_ + b];
    }

    // Throws InputError naming the first pair of materials without coefficients.
    void requireComplete(const std::vector<Material>& materials) const;

private:
    std::size_t materialCount_ = 0;
    std::vector<InteractionProperties> entries_;
    std::vector<unsigned char> assigned_;
};

}  // namespace dem
