#pragma once
// Particle insertion: draw a population whose per-class mass fractions match a
// SizeDistribution (to a target mass or a target count), then place it without
// overlaps inside a Region on a jittered lattice.  Everything is reproducible
// from one 64-bit seed, bit for bit across compilers (std::mt19937_64 is fully
// specified; the conversions to doubles and indices are our own).
// docs/insertion.md explains the quota rule, the placement and the limits.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "demLib/size_distribution.hpp"
#include "demLib/vec3.hpp"

namespace dem {

// Where particles may go.  A sphere is accepted only if it lies wholly inside.
class Region {
public:
    enum class Kind { Box, Cylinder, Predicate };
    using InsidePredicate = std::function<bool(const Vec3& point)>;

    // Axis-aligned box; expects max > min in every component.
    static Region box(const Vec3& min, const Vec3& max);
    // Cylinder of `radius` around the line axisPoint + t*axis, for t in
    // [axialMin, axialMax] (axis is normalised here, so t is a length).
    static Region cylinder(const Vec3& axisPoint, const Vec3& axis, double radius,
                           double axialMin, double axialMax);
    // Any shape given by an inside test (e.g. a closed STL's containsPoint) and
    // a bounding box that contains it.  A sphere counts as inside when it lies
    // in the bounding box and its centre and 14 probe points at distance r
    // (6 along +-x,y,z and 8 along the cube diagonals) are inside: exact for
    // convex shapes, an approximation for features thinner than the sphere.
    static Region predicate(InsidePredicate inside, const Vec3& boundsMin, const Vec3& boundsMax);

    bool containsSphere(const Vec3& centre, double radius) const;
    // The region's volume (box, cylinder), or its bounding box's (predicate):
    // never less than the volume particles can fill.
    double volumeBound() const;

    Kind kind() const { return kind_; }
    const Vec3& boundsMin() const { return boundsMin_; }
    const Vec3& boundsMax() const { return boundsMax_; }

private:
    Region() = default;
    Kind kind_ = Kind::Box;
    Vec3 boundsMin_ = Vec3::Zero();
    Vec3 boundsMax_ = Vec3::Zero();
    // Cylinder
    Vec3 axisPoint_ = Vec3::Zero();
    Vec3 axis_ = Vec3::UnitZ();
    double radius_ = 0.0;
    double axialMin_ = 0.0;
    double axialMax_ = 0.0;
    // Predicate
    InsidePredicate inside_;
};

enum class Lattice {
    SimpleCubic,     // sites per volume 1/s^3
    HexagonalClose,  // ABAB stacking along z, sqrt(2)/s^3: holds 41 % more
};

enum class WhenRegionFull {
    Throw,          // dem::InputError naming the requested and the maximal amount
    PlaceWhatFits,  // place the leading particles that fit (insertion in waves)
};

// Particles already in the domain, as the engine stores them (non-owning; the
// vectors must outlive the call).  New particles never overlap them.
struct ExistingParticles {
    const std::vector<Vec3>* positions = nullptr;
    const std::vector<double>* radii = nullptr;
    std::size_t size() const { return positions ? positions->size() : 0; }
};

// true when a sphere of this radius at this centre is allowed (e.g. not cut by a wall).
using ClearancePredicate = std::function<bool(const Vec3& centre, double radius)>;

struct PlacementOptions {
    Lattice lattice = Lattice::HexagonalClose;
    // Lattice spacing = (largest diameter) * (1 + gapFraction); >= 0.
    double gapFraction = 0.05;
    std::uint64_t seed = 1;
    // Zero: sites are taken in random order all over the region (a loose
    // cloud).  Non-zero (e.g. gravity): the sites farthest along it are filled
    // first (a compact block at the bottom); ties within a layer stay random.
    Vec3 settleDirection = Vec3::Zero();
    WhenRegionFull whenFull = WhenRegionFull::Throw;
    ExistingParticles existing;
    ClearancePredicate clearance;  // empty: everything is clear
    std::string context = "insertion";  // prefixes error messages (file: keyword)
};

struct InsertedParticle {
    Vec3 position;
    double radius;
};

struct InsertionRequest {
    // Exactly one of targetMass (kg) and targetCount must be > 0.
    double targetMass = 0.0;
    std::size_t targetCount = 0;
    double density = 0.0;  // kg/m^3
    // Not used for placement: the engine gives it to every inserted particle.
    Vec3 initialVelocity = Vec3::Zero();
    // placement.seed also seeds the population draw (an independent stream).
    PlacementOptions placement;
};

// Diameters whose per-class masses follow the distribution's mass fractions
// and sum to targetMass within half the largest particle's mass (quota rule,
// classes from large to small), in seeded random order.
std::vector<double> drawDiametersForMass(const SizeDistribution& distribution, double targetMass,
                                         double density, std::uint64_t seed);

// Exactly `count` diameters; class counts follow the number fractions that
// reproduce the mass fractions (largest-remainder rounding); seeded random order.
std::vector<double> drawDiametersForCount(const SizeDistribution& distribution, std::size_t count,
                                          std::uint64_t seed);

// Number of lattice sites free for particles no larger than largestDiameter
// (inside the region, clear of existing particles and of the clearance test).
std::size_t countFreeSites(const Region& region, double largestDiameter,
                           const PlacementOptions& options);

// Places diameters[k] (k in order) on its own lattice site with random jitter;
// returns them in the same order.  With WhenRegionFull::PlaceWhatFits the
// result may be a leading part of the list.
std::vector<InsertedParticle> placeParticles(const Region& region,
                                             const std::vector<double>& diameters,
                                             const PlacementOptions& options);

// Draws the population of the request and places it.
std::vector<InsertedParticle> insertParticles(const Region& region,
                                              const SizeDistribution& distribution,
                                              const InsertionRequest& request);

}  // namespace dem
