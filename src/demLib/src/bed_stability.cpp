#include "demLib/bed_stability.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "demLib/cell_bins.hpp"
#include "demLib/contact_rolling_resistance.hpp"
#include "demLib/contact_stability.hpp"
#include "demLib/error.hpp"
#include "demLib/simulation.hpp"

namespace dem {

namespace {

// One contact: particle i, and particle j (-1 for a wall), normal from i
// towards j, lever arms, and its linearised springs and dashpots.
struct LinearisedContact {
    int i = 0;
    int j = -1;
    Eigen::Vector3d normal;
    double leverI = 0.0;
    double leverJ = 0.0;
    LinearContact law;
    bool fixedParticle = false;  // j is a particle outside the region, held fixed
};

// The contacts of the particles inside the region (their indices in
// `inside`, which lists them); a particle outside it that touches one inside is
// held fixed, as a wall.
std::vector<LinearisedContact> bedContacts(const Simulation& sim, const BedStabilityOptions& options,
                                           std::vector<int>& inside) {
    const ParticleStore& p = sim.particles();
    const int n = static_cast<int>(p.size());
    const RollingModel rolling = sim.settings().forces.rolling;
    std::vector<LinearisedContact> contacts;
    std::vector<int> local(p.size(), -1);  // particle -> its index among those inside
    inside.clear();
    for (int i = 0; i < n; ++i)
        if ((p.position[i].array() >= options.regionLower.array()).all() &&
            (p.position[i].array() <= options.regionUpper.array()).all()) {
            local[i] = static_cast<int>(inside.size());
            inside.push_back(i);
        }
    if (inside.empty()) return contacts;
    // Touching pairs from cells at least as wide as the largest diameter.
    const CellBins bins = binIntoCells(p.position, 2.0 * *std::max_element(p.radius.begin(), p.radius.end()));
    std::vector<WallContact> found;
    for (const int i : inside) {
        forEachInNeighbouringCells(bins, i, [&](int j) {
            if (j == i || (local[j] >= 0 && j < i)) return;  // a pair inside once
            const Vec3 d = p.position[j] - p.position[i];
            const double dist = d.norm();
            const double overlap = p.radius[i] + p.radius[j] - dist;
            if (!(overlap > 0.0)) return;
            const double radiusEff = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
            const double massEff = p.mass[i] * p.mass[j] / (p.mass[i] + p.mass[j]);
            LinearisedContact k;
            k.i = local[i];
            k.j = local[j];  // -1 outside: held fixed
            k.normal = d / dist;
            k.leverI = p.radius[i] - 0.5 * overlap;
            k.leverJ = p.radius[j] - 0.5 * overlap;
            k.law = linearHertzContact(sim.interactions()(p.material[i], p.material[j]), radiusEff, massEff, overlap,
                                       rolling, rollingInertiaEff(p.mass[i], p.radius[i], p.mass[j], p.radius[j]));
            k.fixedParticle = local[j] < 0;
            contacts.push_back(k);
        });
        for (const Wall& w : sim.walls()) {
            found.clear();
            w.findContacts(p.position[i], p.radius[i], sim.time(), found);
            for (const WallContact& c : found) {
                if (!(c.overlap > 0.0)) continue;
                LinearisedContact k;
                k.i = local[i];
                k.normal = -c.normal;  // the wall's normal points at the sphere
                k.leverI = p.radius[i] - 0.5 * c.overlap;
                k.law = linearHertzContact(sim.interactions()(p.material[i], w.materialIndex), p.radius[i],
                                           p.mass[i], c.overlap, rolling, rollingInertiaWall(p.mass[i], p.radius[i]));
                contacts.push_back(k);
            }
        }
    }
    return contacts;
}

// The generalised forces of all contacts on the bed's coordinates (per
// particle: translation, rotation) for displacements x and velocities u,
// contact by contact as the engine's law acts (no matrix is assembled):
// the contact point's relative motion (i's material minus j's) is
// dv - c_i n x w_i - c_j n x w_j, split into its normal and tangential parts,
// and the rolling part is the tangential part of w_i - w_j.
void addContactForces(const std::vector<LinearisedContact>& contacts, const Eigen::VectorXd& x,
                      const Eigen::VectorXd& u, Eigen::VectorXd& force) {
    force.setZero();
    for (const LinearisedContact& q : contacts) {
        const Eigen::Vector3d& n = q.normal;
        const bool moves = q.j >= 0;  // a wall does not
        const Eigen::Index a = 6 * static_cast<Eigen::Index>(q.i);
        const Eigen::Index b = moves ? 6 * static_cast<Eigen::Index>(q.j) : 0;
        // The spring (from x) and dashpot (from u) parts in one: s = k disp + c vel.
        auto generalised = [&](const Eigen::VectorXd& y, double normalCoefficient, double tangentialCoefficient,
                               double rollingCoefficient, Eigen::Vector3d& normalForce,
                               Eigen::Vector3d& tangentialForce, Eigen::Vector3d& rollingMoment) {
            Eigen::Vector3d d = y.segment<3>(a);
            Eigen::Vector3d slip = -q.leverI * n.cross(y.segment<3>(a + 3));
            Eigen::Vector3d roll = y.segment<3>(a + 3);
            if (moves) {
                d -= y.segment<3>(b);
                slip -= q.leverJ * n.cross(y.segment<3>(b + 3));
                roll -= y.segment<3>(b + 3);
            }
            slip += d;
            const double normalPart = n.dot(d);
            normalForce += normalCoefficient * normalPart * n;
            tangentialForce += tangentialCoefficient * (slip - n.dot(slip) * n);
            rollingMoment += rollingCoefficient * (roll - n.dot(roll) * n);
        };
        Eigen::Vector3d normalForce = Eigen::Vector3d::Zero();
        Eigen::Vector3d tangentialForce = Eigen::Vector3d::Zero();
        Eigen::Vector3d rollingMoment = Eigen::Vector3d::Zero();
        generalised(x, q.law.normalStiffness, q.law.tangentialStiffness, q.law.rollingStiffness, normalForce,
                    tangentialForce, rollingMoment);
        generalised(u, q.law.normalDamping, q.law.tangentialDamping, q.law.rollingDamping, normalForce,
                    tangentialForce, rollingMoment);
        // The transpose of the motion above: a force F at the contact acts on
        // i as (F, c_i n x F) and on j as (-F, c_j n x F).
        const Eigen::Vector3d linear = normalForce + tangentialForce;
        const Eigen::Vector3d nxF = n.cross(tangentialForce);
        force.segment<3>(a) += linear;
        force.segment<3>(a + 3) += q.leverI * nxF + rollingMoment;
        if (moves) {
            force.segment<3>(b) -= linear;
            force.segment<3>(b + 3) += q.leverJ * nxF - rollingMoment;
        }
    }
}

}  // namespace

BedStabilityReport analyseBedStability(const Simulation& sim, const BedStabilityOptions& options) {
    // Fewer iterations let a slowly growing mode pass as stable (threshold 10 /
    // iterations): 100 gave a step 4 % beyond the exact one; below 1e-6 the
    // bisection would reach the spacing of doubles.
    if (options.iterations < 1000)
        throw InputError("bed stability: iterations expects at least 1000, got " + std::to_string(options.iterations));
    if (!(options.relativeTolerance >= 1e-6 && options.relativeTolerance < 0.5))
        throw InputError("bed stability: relative tolerance expects a number in [1e-6, 0.5), got " +
                         std::to_string(options.relativeTolerance));
    const ParticleStore& p = sim.particles();
    BedStabilityReport report;
    report.runTimeStep = options.timeStep > 0.0 ? options.timeStep : sim.timeStep();
    std::vector<int> inside;
    const std::vector<LinearisedContact> contacts = bedContacts(sim, options, inside);
    report.particles = inside.size();
    std::vector<int> count(inside.size(), 0);
    for (const LinearisedContact& q : contacts) {
        ++count[q.i];
        if (q.j >= 0) {
            ++count[q.j];
            ++report.particleContacts;
        } else if (q.fixedParticle) {
            ++report.fixedParticleContacts;
        } else {
            ++report.wallContacts;
        }
    }
    for (int c : count) {
        if (static_cast<std::size_t>(c) >= report.contactsPerParticle.size()) report.contactsPerParticle.resize(c + 1, 0);
        ++report.contactsPerParticle[c];
    }
    if (contacts.empty()) {
        report.undampedLimit = report.stableTimeStep = std::numeric_limits<double>::infinity();
        return report;
    }
    const Eigen::Index dof = 6 * static_cast<Eigen::Index>(inside.size());
    Eigen::VectorXd inverseMass(dof);
    for (std::size_t k = 0; k < inside.size(); ++k) {
        const int i = inside[k];
        const double inertia = 0.4 * p.mass[i] * p.radius[i] * p.radius[i];
        inverseMass.segment<3>(6 * k).setConstant(1.0 / p.mass[i]);
        inverseMass.segment<3>(6 * k + 3).setConstant(1.0 / inertia);
    }
    const Eigen::VectorXd still = Eigen::VectorXd::Zero(dof);
    Eigen::VectorXd force(dof);

    // w_max^2, the largest eigenvalue of M^-1 K (power iteration on the
    // symmetric M^-1/2 K M^-1/2, whose eigenvalues are the same).
    {
        const Eigen::VectorXd root = inverseMass.cwiseSqrt();
        Eigen::VectorXd v = Eigen::VectorXd::Ones(dof).normalized();
        double lambda = 0.0;
        for (int it = 0; it < 500; ++it) {
            addContactForces(contacts, root.cwiseProduct(v), still, force);
            const Eigen::VectorXd w = root.cwiseProduct(force);
            const double next = v.dot(w);
            v = w.normalized();
            if (it > 50 && std::abs(next - lambda) <= 1e-6 * next) {
                lambda = next;
                break;
            }
            lambda = next;
        }
        if (!(lambda > 0.0) || !std::isfinite(lambda))
            throw std::runtime_error("bed stability: the largest eigenvalue of the bed's stiffness came out " +
                                     std::to_string(lambda) + " (non-finite or zero contact stiffness?)");
        report.undampedLimit = 2.0 / std::sqrt(lambda);
    }

    // Log growth per step of the velocity Verlet map (the half-step velocity
    // u, which the forces see: u' = u + dt a(x, u), x' = x + dt u') over the
    // second half of the iterations.  Neutral modes (a direction without a
    // spring) grow linearly, log 2 over the second half, so a mode counts as
    // growing above 10 / iterations per step.
    const double threshold = 10.0 / options.iterations;
    auto growthAt = [&](double dt) {
        std::mt19937 random(options.seed);
        std::normal_distribution<double> normal;
        Eigen::VectorXd x(dof), u(dof);
        for (Eigen::Index k = 0; k < dof; ++k) {
            x(k) = normal(random) * dt;
            u(k) = normal(random);
        }
        double logGrowth = 0.0;
        double atHalf = 0.0;
        for (int it = 1; it <= options.iterations; ++it) {
            addContactForces(contacts, x, u, force);
            u -= dt * inverseMass.cwiseProduct(force);
            x += dt * u;
            if (it % 32 == 0 || it == options.iterations / 2 || it == options.iterations) {
                const double size = std::sqrt(x.squaredNorm() / (dt * dt) + u.squaredNorm());
                if (!(size > 0.0) || !std::isfinite(size)) return std::numeric_limits<double>::infinity();
                logGrowth += std::log(size);
                x /= size;
                u /= size;
            }
            if (it == options.iterations / 2) atHalf = logGrowth;
        }
        return (logGrowth - atHalf) / (options.iterations - options.iterations / 2);
    };
    // Trials: the judged step, about two to bracket the limit, then the bisection
    // from [w/8, w] (w the undamped bound) down to the tolerance of the limit,
    // which has been 3.4-4.8 times below w.
    int trials = 0;
    int expectedTrials = 3 + static_cast<int>(std::ceil(std::log2(0.875 * 4.0 / options.relativeTolerance)));
    auto growth = [&](double dt) {
        const double g = growthAt(dt);
        ++trials;
        expectedTrials = std::max(expectedTrials, trials);
        if (options.onTrial) options.onTrial(trials, expectedTrials, dt, g, g > threshold);
        return g;
    };
    report.growthAtRunStep = growth(report.runTimeStep);
    report.stableAtRunStep = report.growthAtRunStep <= threshold;

    // Bisection between a stable and a growing step; the undamped limit bounds
    // the damped one from above (damping only lowers it).
    double high = report.undampedLimit;
    bool bracketed = false;
    for (int k = 0; k < 10 && !(bracketed = growth(high) > threshold); ++k) high *= 2.0;
    double low = high / 8.0;
    bool stableLow = false;
    for (int k = 0; k < 20 && !(stableLow = growth(low) <= threshold); ++k) {
        high = low;
        low /= 4.0;
    }
    if (!bracketed || !stableLow)
        throw std::runtime_error("bed stability: no step found between a stable and a growing one (from " +
                                 std::to_string(low) + " to " + std::to_string(high) + " s)");
    while (high - low > options.relativeTolerance * high) {
        const double mid = 0.5 * (low + high);
        if (mid <= low || mid >= high) break;  // the doubles' spacing
        (growth(mid) <= threshold ? low : high) = mid;
    }
    report.stableTimeStep = low;
    return report;
}

}  // namespace dem
