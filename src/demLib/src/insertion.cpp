// Seeded results must be bitwise identical across compilers and flags: keep
// every floating-point operation separately rounded (no fused multiply-add,
// which -march=native with GNU extensions would otherwise generate).
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "demLib/insertion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <utility>

#include "demLib/constants.hpp"
#include "demLib/error.hpp"

namespace dem {

namespace {

// ---------------------------------------------------------------------------
// Reproducible random numbers.  std::mt19937_64 is specified bit for bit by the
// standard; std::uniform_real_distribution and std::shuffle are not, so the
// conversions below are ours.
class SeededRandom {
public:
    explicit SeededRandom(std::uint64_t seed) : engine_(seed) {}

    // Uniform in [0, 1): the top 53 bits as the mantissa.
    double unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

    // Uniform in [0, n) without modulo bias (rejection of the short last block).
    std::uint64_t index(std::uint64_t n) {
        const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() -
                                    std::numeric_limits<std::uint64_t>::max() % n;
        std::uint64_t x = engine_();
        while (x >= limit) x = engine_();
        return x % n;
    }

    // Fisher-Yates.
    template <class T>
    void shuffle(std::vector<T>& v) {
        for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[index(i)]);
    }

    // Uniform in the ball of the given radius (rejection from the cube).
    Vec3 inBall(double radius) {
        if (radius <= 0.0) return Vec3::Zero();
        Vec3 v;
        do {
            // One statement per draw: argument evaluation order is unspecified.
            v.x() = 2.0 * unit() - 1.0;
            v.y() = 2.0 * unit() - 1.0;
            v.z() = 2.0 * unit() - 1.0;
        } while (v.squaredNorm() > 1.0);
        return radius * v;
    }

private:
    std::mt19937_64 engine_;
};

// The population and the placement use independent streams of one seed.
constexpr std::uint64_t placementStream = 0x9E3779B97F4A7C15ull;

// Sites may poke out of the region by this fraction of the spacing (rounding
// when a box is an exact multiple of the spacing); jitter is reduced by as much.
constexpr double siteTolerance = 1e-9;

// Never build more lattice points than this (about 0.5 GB): a bounding box far
// larger than the region or a tiny spacing is a user error.
constexpr std::size_t maxLatticePoints = 20'000'000;

std::string formatNumber(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

const char* latticeName(Lattice lattice) {
    return lattice == Lattice::SimpleCubic ? "simpleCubic" : "hexagonalClose";
}

// ---------------------------------------------------------------------------
// Lattice sites whose ball of radius spacing/2 lies in the bounding box of the
// region (the region test comes later), in lattice order.
std::vector<Vec3> latticeInBox(const Vec3& lo, const Vec3& hi, double spacing, Lattice lattice,
                               const std::string& context) {
    const double s = spacing;
    const Vec3 extent = hi - lo;
    // Layer (z), row (y) and in-row (x) pitches.
    const double dx = s;
    const double dy = lattice == Lattice::SimpleCubic ? s : s * std::sqrt(3.0) / 2.0;
    const double dz = lattice == Lattice::SimpleCubic ? s : s * std::sqrt(2.0 / 3.0);
    auto countAlong = [](double length, double pitch) -> std::size_t {
        return length <= 0.0 ? 0 : static_cast<std::size_t>(std::floor(length / pitch)) + 1;
    };
    const std::size_t nx = countAlong(extent.x(), dx), ny = countAlong(extent.y(), dy),
                      nz = countAlong(extent.z(), dz);
    const double points = static_cast<double>(nx) * static_cast<double>(ny) * static_cast<double>(nz);
    if (points > static_cast<double>(maxLatticePoints)) {
        std::ostringstream m;
        m << context << ": the region's bounding box would need " << points
          << " lattice sites at spacing " << s << "; expected at most " << maxLatticePoints
          << " (tighten the bounding box or use larger particles)";
        throw InputError(m.str());
    }
    std::vector<Vec3> sites;
    sites.reserve(nx * ny * nz);
    const Vec3 first = lo + Vec3::Constant(0.5 * s);
    const double tol = siteTolerance * s;
    for (std::size_t k = 0; k < nz; ++k) {
        // Hexagonal close packing: every second layer sits over triangle centroids.
        const bool shiftedLayer = lattice == Lattice::HexagonalClose && k % 2 == 1;
        const double layerX = shiftedLayer ? 0.5 * s : 0.0;
        const double layerY = shiftedLayer ? s * std::sqrt(3.0) / 6.0 : 0.0;
        const double z = first.z() + static_cast<double>(k) * dz;
        if (z > hi.z() - 0.5 * s + tol) continue;
        for (std::size_t j = 0; j < ny; ++j) {
            const bool shiftedRow = lattice == Lattice::HexagonalClose && j % 2 == 1;
            const double y = first.y() + layerY + static_cast<double>(j) * dy;
            if (y > hi.y() - 0.5 * s + tol) continue;
            const double rowX = layerX + (shiftedRow ? 0.5 * s : 0.0);
            for (std::size_t i = 0; i < nx; ++i) {
                const double x = first.x() + rowX + static_cast<double>(i) * dx;
                if (x > hi.x() - 0.5 * s + tol) break;
                sites.emplace_back(x, y, z);
            }
        }
    }
    return sites;
}

// ---------------------------------------------------------------------------
// Uniform cell grid over the existing particles near the region, so a site
// tests only its 27 neighbouring cells: O(sites + existing).
class ExistingGrid {
public:
    ExistingGrid(const ExistingParticles& existing, const Vec3& lo, const Vec3& hi,
                 double siteRadius, const std::string& context)
        : existing_(existing) {
        const std::size_t n = existing.size();
        if (n == 0) return;
        if (!existing.radii || existing.radii->size() != n) {
            std::ostringstream m;
            m << context << ": existing particles have " << n << " positions but "
              << (existing.radii ? existing.radii->size() : 0) << " radii; expected equal counts";
            throw InputError(m.str());
        }
        double rMax = 0.0;
        for (double r : *existing.radii) rMax = std::max(rMax, r);
        // A particle can block a site only if their centres are closer than this.
        reach_ = siteRadius + rMax;
        lo_ = lo - Vec3::Constant(reach_);
        const Vec3 extent = (hi + Vec3::Constant(reach_)) - lo_;
        cell_ = reach_;
        // Coarsen cells (still correct, only slower) if the grid would be huge.
        const double maxCells = std::max(1e6, 4.0 * static_cast<double>(n));
        while ((std::floor(extent.x() / cell_) + 1) * (std::floor(extent.y() / cell_) + 1) *
                   (std::floor(extent.z() / cell_) + 1) > maxCells)
            cell_ *= 1.5;
        for (int a = 0; a < 3; ++a) dims_[a] = static_cast<long>(std::floor(extent[a] / cell_)) + 1;
        const std::size_t cells = static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]);
        // Counting sort of the particles by cell.
        std::vector<long> cellOfParticle(n, -1);
        cellStart_.assign(cells + 1, 0);
        for (std::size_t p = 0; p < n; ++p) {
            const long c = cellIndexOf((*existing.positions)[p]);
            if (c < 0) continue;  // too far from the region to matter
            cellOfParticle[p] = c;
            ++cellStart_[static_cast<std::size_t>(c) + 1];
        }
        for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
        members_.resize(cellStart_[cells]);
        std::vector<std::uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
        for (std::size_t p = 0; p < n; ++p)
            if (cellOfParticle[p] >= 0)
                members_[fill[static_cast<std::size_t>(cellOfParticle[p])]++] =
                    static_cast<std::uint32_t>(p);
    }

    // true if a sphere of siteRadius at `site` overlaps an existing particle.
    bool blocks(const Vec3& site, double siteRadius) const {
        if (members_.empty()) return false;
        long c[3];
        for (int a = 0; a < 3; ++a) c[a] = static_cast<long>(std::floor((site[a] - lo_[a]) / cell_));
        for (long ix = c[0] - 1; ix <= c[0] + 1; ++ix) {
            if (ix < 0 || ix >= dims_[0]) continue;
            for (long iy = c[1] - 1; iy <= c[1] + 1; ++iy) {
                if (iy < 0 || iy >= dims_[1]) continue;
                for (long iz = c[2] - 1; iz <= c[2] + 1; ++iz) {
                    if (iz < 0 || iz >= dims_[2]) continue;
                    const std::size_t cell = static_cast<std::size_t>((ix * dims_[1] + iy) * dims_[2] + iz);
                    for (std::uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
                        const std::uint32_t p = members_[k];
                        const double contact = siteRadius + (*existing_.radii)[p];
                        if (((*existing_.positions)[p] - site).squaredNorm() < contact * contact)
                            return true;
                    }
                }
            }
        }
        return false;
    }

private:
    long cellIndexOf(const Vec3& x) const {
        long c[3];
        for (int a = 0; a < 3; ++a) {
            const double f = std::floor((x[a] - lo_[a]) / cell_);
            if (!(f >= 0.0) || f >= static_cast<double>(dims_[a])) return -1;
            c[a] = static_cast<long>(f);
        }
        return (c[0] * dims_[1] + c[1]) * dims_[2] + c[2];
    }

    const ExistingParticles& existing_;
    double reach_ = 0.0;
    double cell_ = 1.0;
    Vec3 lo_ = Vec3::Zero();
    long dims_[3] = {0, 0, 0};
    std::vector<std::uint32_t> cellStart_;
    std::vector<std::uint32_t> members_;
};

void validateOptions(const PlacementOptions& options) {
    if (!(options.gapFraction >= 0.0) || !std::isfinite(options.gapFraction))
        throw InputError(options.context + ": gapFraction must be a finite number >= 0, got " +
                         formatNumber(options.gapFraction));
    if (!options.settleDirection.allFinite())
        throw InputError(options.context + ": settleDirection must be finite");
}

// Free sites in lattice order: inside the region, clear of existing particles
// and accepted by the clearance test, each as a ball of radius spacing/2.
std::vector<Vec3> freeSites(const Region& region, double spacing, const PlacementOptions& options) {
    const double siteRadius = 0.5 * spacing;
    const double testRadius = siteRadius - siteTolerance * spacing;
    std::vector<Vec3> sites =
        latticeInBox(region.boundsMin(), region.boundsMax(), spacing, options.lattice, options.context);
    const ExistingGrid grid(options.existing, region.boundsMin(), region.boundsMax(), siteRadius,
                            options.context);
    std::size_t kept = 0;
    for (const Vec3& site : sites) {
        if (!region.containsSphere(site, testRadius)) continue;
        if (grid.blocks(site, siteRadius)) continue;
        if (options.clearance && !options.clearance(site, siteRadius)) continue;
        sites[kept++] = site;
    }
    sites.resize(kept);
    return sites;
}

double largestOf(const std::vector<double>& diameters, const std::string& context) {
    double largest = 0.0;
    for (std::size_t k = 0; k < diameters.size(); ++k) {
        if (!(diameters[k] > 0.0) || !std::isfinite(diameters[k])) {
            std::ostringstream m;
            m << context << ": particle " << k << " has diameter " << diameters[k]
              << "; expected a finite diameter > 0";
            throw InputError(m.str());
        }
        largest = std::max(largest, diameters[k]);
    }
    return largest;
}

// Called with the number of particles that fit when not all do; returns the message.
using ShortfallMessage = std::function<std::string(std::size_t fits, double spacing)>;

std::vector<InsertedParticle> placeWithMessage(const Region& region,
                                               const std::vector<double>& diameters,
                                               const PlacementOptions& options,
                                               const ShortfallMessage& shortfall) {
    validateOptions(options);
    if (diameters.empty()) return {};
    const double spacing = largestOf(diameters, options.context) * (1.0 + options.gapFraction);
    std::vector<Vec3> sites = freeSites(region, spacing, options);

    SeededRandom random(options.seed ^ placementStream);
    random.shuffle(sites);
    if (options.settleDirection.squaredNorm() > 0.0) {
        // Farthest along settleDirection first; the shuffle above breaks ties.
        const Vec3 down = options.settleDirection.normalized();
        std::stable_sort(sites.begin(), sites.end(),
                         [&](const Vec3& a, const Vec3& b) { return a.dot(down) > b.dot(down); });
    }

    std::size_t count = diameters.size();
    if (sites.size() < count) {
        if (options.whenFull == WhenRegionFull::Throw)
            throw InputError(shortfall(sites.size(), spacing));
        count = sites.size();
    }

    // Neighbouring sites are >= spacing apart; a particle moved by at most
    // (spacing - d)/2 from its site stays inside the site's ball, so it can
    // touch neither a neighbour nor the region's boundary.
    const double tol = siteTolerance * spacing;
    std::vector<InsertedParticle> placed;
    placed.reserve(count);
    for (std::size_t k = 0; k < count; ++k) {
        const double d = diameters[k];
        const double jitter = std::max(0.0, 0.5 * (spacing - d) - tol);
        placed.push_back({sites[k] + random.inBall(jitter), 0.5 * d});
    }
    return placed;
}

std::string describeLattice(const PlacementOptions& options, double spacing) {
    std::ostringstream m;
    m << "lattice spacing " << spacing << " m (" << latticeName(options.lattice)
      << ", gapFraction " << options.gapFraction << ")";
    return m.str();
}

std::string whatToChange(const PlacementOptions& options) {
    std::string advice = "enlarge the region";
    if (options.gapFraction > 0.0) advice += ", lower gapFraction";
    if (options.lattice == Lattice::SimpleCubic) advice += ", use the hexagonalClose lattice";
    return advice + ", or insert in waves (keyword 'waveInterval')";
}

}  // namespace

// ---------------------------------------------------------------------------
// Region

Region Region::box(const Vec3& min, const Vec3& max) {
    if (!min.allFinite() || !max.allFinite() || !(max.array() > min.array()).all()) {
        std::ostringstream m;
        m << "box region: expected max > min in x, y and z, got min = (" << min.transpose()
          << "), max = (" << max.transpose() << ")";
        throw InputError(m.str());
    }
    Region r;
    r.kind_ = Kind::Box;
    r.boundsMin_ = min;
    r.boundsMax_ = max;
    return r;
}

Region Region::cylinder(const Vec3& axisPoint, const Vec3& axis, double radius, double axialMin,
                        double axialMax) {
    if (!axisPoint.allFinite() || !axis.allFinite() || !(axis.norm() > 0.0))
        throw InputError("cylinder region: expected a finite axis point and a non-zero axis");
    if (!(radius > 0.0) || !std::isfinite(radius))
        throw InputError("cylinder region: expected radius > 0, got " + formatNumber(radius));
    if (!(axialMax > axialMin) || !std::isfinite(axialMin) || !std::isfinite(axialMax))
        throw InputError("cylinder region: expected axialMax > axialMin, got [" +
                         formatNumber(axialMin) + ", " + formatNumber(axialMax) + "]");
    Region r;
    r.kind_ = Kind::Cylinder;
    r.axisPoint_ = axisPoint;
    r.axis_ = axis.normalized();
    r.radius_ = radius;
    r.axialMin_ = axialMin;
    r.axialMax_ = axialMax;
    // Bounding box: the two end discs; a disc of normal a reaches r*sqrt(1 - a_i^2) along i.
    const Vec3 end0 = axisPoint + axialMin * r.axis_, end1 = axisPoint + axialMax * r.axis_;
    for (int i = 0; i < 3; ++i) {
        const double reach = radius * std::sqrt(std::max(0.0, 1.0 - r.axis_[i] * r.axis_[i]));
        r.boundsMin_[i] = std::min(end0[i], end1[i]) - reach;
        r.boundsMax_[i] = std::max(end0[i], end1[i]) + reach;
    }
    return r;
}

Region Region::predicate(InsidePredicate inside, const Vec3& boundsMin, const Vec3& boundsMax) {
    if (!inside) throw InputError("predicate region: expected an inside test, got none");
    Region r = box(boundsMin, boundsMax);
    r.kind_ = Kind::Predicate;
    r.inside_ = std::move(inside);
    return r;
}

double Region::volumeBound() const {
    if (kind_ == Kind::Cylinder) return pi * radius_ * radius_ * (axialMax_ - axialMin_);
    return (boundsMax_ - boundsMin_).prod();
}

bool Region::containsSphere(const Vec3& centre, double radius) const {
    const Vec3 reach = Vec3::Constant(radius);
    if (!((centre - reach).array() >= boundsMin_.array()).all() ||
        !((centre + reach).array() <= boundsMax_.array()).all())
        return false;
    switch (kind_) {
        case Kind::Box:
            return true;
        case Kind::Cylinder: {
            const Vec3 rel = centre - axisPoint_;
            const double t = rel.dot(axis_);
            if (t - radius < axialMin_ || t + radius > axialMax_) return false;
            const double radial = (rel - t * axis_).norm();
            return radial + radius <= radius_;
        }
        case Kind::Predicate: {
            if (!inside_(centre)) return false;
            for (int a = 0; a < 3; ++a)
                for (double sign : {-1.0, 1.0}) {
                    Vec3 probe = centre;
                    probe[a] += sign * radius;
                    if (!inside_(probe)) return false;
                }
            const double diagonal = radius / std::sqrt(3.0);
            for (double sx : {-1.0, 1.0})
                for (double sy : {-1.0, 1.0})
                    for (double sz : {-1.0, 1.0})
                        if (!inside_(centre + diagonal * Vec3(sx, sy, sz))) return false;
            return true;
        }
    }
    return false;
}

// ---------------------------------------------------------------------------
// Populations

std::vector<double> drawDiametersForMass(const SizeDistribution& distribution, double targetMass,
                                         double density, std::uint64_t seed) {
    if (!(targetMass > 0.0) || !std::isfinite(targetMass))
        throw InputError("insertion: targetMass must be a finite mass > 0 kg, got " +
                         formatNumber(targetMass));
    if (!(density > 0.0) || !std::isfinite(density))
        throw InputError("insertion: density must be > 0 kg/m^3, got " + formatNumber(density));
    const std::vector<SizeClass>& classes = distribution.classes();
    // Large classes first: a small class then corrects the running total with
    // fine steps, so the total ends within half a particle of the target.
    std::vector<std::size_t> order(classes.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return classes[a].dMax > classes[b].dMax;
    });

    SeededRandom random(seed);
    std::vector<double> diameters;
    diameters.reserve(static_cast<std::size_t>(targetMass / distribution.meanParticleMass(density) * 1.01) + 16);
    double fractionSoFar = 0.0;
    double massSoFar = 0.0;
    for (std::size_t i : order) {
        if (classes[i].massFraction <= 0.0) continue;
        fractionSoFar += classes[i].massFraction;
        const double quota = targetMass * fractionSoFar;  // cumulative target after class i
        for (;;) {
            const double d = distribution.diameterInClass(i, random.unit());
            const double m = sphereMass(d, density);
            if (massSoFar + m <= quota) {
                diameters.push_back(d);
                massSoFar += m;
                continue;
            }
            // The candidate would cross the quota: keep it only if that leaves
            // the total nearer the quota than stopping short (error <= m/2).
            if (massSoFar + m - quota <= quota - massSoFar) {
                diameters.push_back(d);
                massSoFar += m;
            }
            break;
        }
    }
    random.shuffle(diameters);
    return diameters;
}

std::vector<double> drawDiametersForCount(const SizeDistribution& distribution, std::size_t count,
                                          std::uint64_t seed) {
    const std::vector<double> fractions = distribution.numberFractions();
    // Largest-remainder rounding: counts sum to `count`, each within 1 of n*f_i.
    std::vector<std::size_t> counts(fractions.size());
    std::vector<std::pair<double, std::size_t>> remainders;
    std::size_t assigned = 0;
    for (std::size_t i = 0; i < fractions.size(); ++i) {
        const double exact = static_cast<double>(count) * fractions[i];
        counts[i] = static_cast<std::size_t>(std::floor(exact));
        assigned += counts[i];
        remainders.emplace_back(exact - std::floor(exact), i);
    }
    std::stable_sort(remainders.begin(), remainders.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t k = 0; assigned < count; ++k, ++assigned) ++counts[remainders[k % remainders.size()].second];

    SeededRandom random(seed);
    std::vector<double> diameters;
    diameters.reserve(count);
    for (std::size_t i = 0; i < counts.size(); ++i)
        for (std::size_t k = 0; k < counts[i]; ++k)
            diameters.push_back(distribution.diameterInClass(i, random.unit()));
    random.shuffle(diameters);
    return diameters;
}

// ---------------------------------------------------------------------------
// Placement

std::size_t countFreeSites(const Region& region, double largestDiameter,
                           const PlacementOptions& options) {
    validateOptions(options);
    if (!(largestDiameter > 0.0) || !std::isfinite(largestDiameter))
        throw InputError(options.context + ": largest diameter must be > 0, got " +
                         formatNumber(largestDiameter));
    return freeSites(region, largestDiameter * (1.0 + options.gapFraction), options).size();
}

std::vector<InsertedParticle> placeParticles(const Region& region,
                                             const std::vector<double>& diameters,
                                             const PlacementOptions& options) {
    return placeWithMessage(region, diameters, options, [&](std::size_t fits, double spacing) {
        std::ostringstream m;
        m << options.context << ": requested " << diameters.size()
          << " particles but the region has only " << fits << " free sites at "
          << describeLattice(options, spacing) << "; " << whatToChange(options);
        return m.str();
    });
}

std::vector<InsertedParticle> insertParticles(const Region& region,
                                              const SizeDistribution& distribution,
                                              const InsertionRequest& request) {
    const std::string& context = request.placement.context;
    const bool byMass = request.targetMass > 0.0, byCount = request.targetCount > 0;
    if (byMass == byCount)
        throw InputError(context + ": expected exactly one of targetMass (kg) and targetCount > 0, got " +
                         formatNumber(request.targetMass) + " and " +
                         std::to_string(request.targetCount));
    if (!(request.density > 0.0) || !std::isfinite(request.density))
        throw InputError(context + ": density must be > 0 kg/m^3, got " + formatNumber(request.density));
    const std::vector<double> diameters =
        byMass ? drawDiametersForMass(distribution, request.targetMass, request.density,
                                      request.placement.seed)
               : drawDiametersForCount(distribution, request.targetCount, request.placement.seed);
    if (diameters.empty())
        throw InputError(context + ": targetMass " + formatNumber(request.targetMass) +
                         " kg is less than half the mass of one particle; expected at least " +
                         formatNumber(0.5 * sphereMass(distribution.dMin(), request.density)) + " kg");

    return placeWithMessage(region, diameters, request.placement, [&](std::size_t fits, double spacing) {
        // The population is in random order, so its leading part is a fair sample.
        double fitMass = 0.0, drawnMass = 0.0;
        for (std::size_t k = 0; k < diameters.size(); ++k) {
            const double m = sphereMass(diameters[k], request.density);
            drawnMass += m;
            if (k < fits) fitMass += m;
        }
        std::ostringstream m;
        m << context << ": requested mass " << (byMass ? request.targetMass : drawnMass) << " kg ("
          << diameters.size() << " particles) but at most " << fitMass << " kg (" << fits
          << " particles) fits at " << describeLattice(request.placement, spacing) << "; "
          << whatToChange(request.placement);
        return m.str();
    });
}

}  // namespace dem
