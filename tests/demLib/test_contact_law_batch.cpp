// The batched pair contact law (contact_law_batch.hpp, the pair loop's default)
// against the scalar loop it replaces, to the bit.
//
//   1. Lane level: ~2000 random touching contacts per rolling model (sand and
//      steel, radii 0.2-1 mm, overlaps 1e-4..5e-2 of the radius sum, random
//      velocities, spins and spring histories) go through evaluateContactBatch
//      in chunks of 1..128, filled as pairForcesBatched fills them, and through
//      the scalar pair-loop expressions around ContactLaw<Rolling>::evaluate
//      (copied from pairForces in contact_force_kernel.cpp).  Force, torques on
//      i and j and the updated springs must agree bit for bit, for batches of
//      one material pair (constants broadcast) and of mixed pairs (per lane).
//      The sample must contain sliding and sticking, rolling-limited and free
//      (EPSD, EPSD2), turning and resting (CDT) lanes, counted by the reference.
//   2. Engine level: a large sphere whose half-list row holds ~300 touching
//      pairs (> ContactBatch::capacity, so the row's sums are carried over
//      three batches), after a cluster whose pairs fill the first batch's
//      start.  50 steps with ForceFieldSettings::vectorizedPairLaw on (batched)
//      and off (the scalar reference loop) must leave the same state to the
//      bit, with 1 and 2 threads, dry and with capillary bridges (which also
//      act beyond contact as the satellites fly off).
//
// The scalar reference must round as demLib does (it is built with
// -ffp-contract=off): where the compiler could fuse multiply-adds (an FMA
// target), forbid it in this file too.
#if defined(__FMA__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=off")
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "demLib/contact_law.hpp"
#include "demLib/contact_law_batch.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"

namespace {

using dem::ContactBatch;
using dem::RollingModel;
using dem::Vec3;

constexpr double kPi = 3.14159265358979323846;

dem::Material sand() { return {"sand", 5e6, 0.3, 2650.0}; }
dem::Material steel() { return {"steel", 7e10, 0.3, 7800.0}; }

// Non-zero e, mu, mu_r and eta_r, different for each material pair, so that a
// lane reading another lane's constants changes its result.
dem::InteractionTable sandSteelTable() {
    const std::vector<dem::Material> mats{sand(), steel()};
    dem::InteractionTable table(2);
    table.set(mats, 0, 0, dem::PairCoefficients{0.5, 0.5, 0.3, 0.3});
    table.set(mats, 0, 1, dem::PairCoefficients{0.4, 0.6, 0.2, 0.5});
    table.set(mats, 1, 1, dem::PairCoefficients{0.9, 0.2, 0.1, 0.2});
    return table;
}

double sphereMass(double r, double density) { return density * 4.0 / 3.0 * kPi * r * r * r; }

std::uint64_t bitsOf(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

// ---------------------------------------------------------------------------
// 1. Lane level.

// What pairForces reads for one touching pair (i, j).
struct PairInput {
    Vec3 xi, xj, vi, vj, wi, wj;
    double ri, rj, mi, mj;
    int materialI, materialJ;
    dem::ContactHistory history;  // as stored (rolling part only kept by EPSD/EPSD2)
};

// What it produces, and which branch of the law each part took.
struct PairOutput {
    Vec3 force, torqueI, torqueJ, shear, rollingSpring;
    bool sliding = false;         // Coulomb limit reached
    bool rollingLimited = false;  // EPSD/EPSD2: |kr theta| > mu_r R* |Fn|
    bool resting = false;         // CDT: w_i = w_j (no rolling torque)
};

template <RollingModel Rolling>
constexpr bool keepsRolling() {
    return Rolling == RollingModel::EPSD || Rolling == RollingModel::EPSD2;
}

// The scalar path: the kinematics and torque lines of pairForces
// (contact_force_kernel.cpp, no cohesion) around ContactLaw<Rolling>::evaluate.
template <RollingModel Rolling>
PairOutput scalarReference(const PairInput& in, const dem::InteractionTable& table, double dt) {
    const Vec3 d = in.xi - in.xj;
    const double radiusSum = in.ri + in.rj;
    const double dist2 = d.squaredNorm();
    const double dist = std::sqrt(dist2);
    const Vec3 normal = d * (1.0 / dist);
    const double overlap = radiusSum - dist;
    const double ci = in.ri - 0.5 * overlap;
    const double cj = in.rj - 0.5 * overlap;
    dem::ContactKinematics kin;
    kin.normal = normal;
    kin.overlap = overlap;
    const double massSum = in.mi + in.mj;
    const double inverseSums = 1.0 / (radiusSum * massSum);
    kin.radiusEff = in.ri * in.rj * massSum * inverseSums;
    kin.massEff = in.mi * in.mj * radiusSum * inverseSums;
    kin.relVelocity = in.vi - in.vj - (ci * in.wi + cj * in.wj).cross(normal);
    kin.relOmega = in.wi - in.wj;
    kin.dt = dt;
    if constexpr (Rolling == RollingModel::EPSD)
        kin.rollingInertiaEff = dem::rollingInertiaEff(in.mi, in.ri, in.mj, in.rj);
    dem::ContactHistory history;
    history.shear = in.history.shear;
    if constexpr (keepsRolling<Rolling>()) history.rollingAngle = in.history.rollingAngle;
    const dem::InteractionProperties& props = table(in.materialI, in.materialJ);
    const double cohesiveForce = 0.0;

    // Which branches the law takes, from its own predicates (for the counts
    // that keep this test from passing on a sample that never slides).
    PairOutput out;
    {
        const double vn = kin.relVelocity.dot(normal);
        const Vec3 vt = kin.relVelocity - vn * normal;
        const dem::HertzNormal h = dem::hertzNormal(overlap, vn, kin.radiusEff, kin.massEff, props, false, true);
        Vec3 s = history.shear + vt * dt;
        s -= s.dot(normal) * normal;
        const double limit = props.friction * std::abs(h.force);
        out.sliding = h.tangentialStiffness * h.tangentialStiffness * s.squaredNorm() > limit * limit;
        if constexpr (keepsRolling<Rolling>()) {
            const double kr = Rolling == RollingModel::EPSD
                                  ? dem::epsdRollingStiffness(h.normalStiffness, props.rollingFriction, kin.radiusEff)
                                  : dem::epsd2RollingStiffness(h.tangentialStiffness, kin.radiusEff);
            const Vec3 wt = kin.relOmega - kin.relOmega.dot(normal) * normal;
            Vec3 angle = history.rollingAngle + wt * dt;
            angle -= angle.dot(normal) * normal;
            const Vec3 m = -kr * angle;
            const double torqueLimit = props.rollingFriction * kin.radiusEff * std::abs(h.force);
            out.rollingLimited = m.squaredNorm() > torqueLimit * torqueLimit;
        }
        out.resting = !(kin.relOmega.norm() > 0.0);
    }

    const dem::ContactForces f = dem::ContactLaw<Rolling>::evaluate(kin, props, history, cohesiveForce);
    const Vec3 nxFt = normal.cross(f.tangentialForce);
    out.force = f.force;
    out.torqueI = -ci * nxFt + f.rollingTorque;
    out.torqueJ = -cj * nxFt - f.rollingTorque;
    out.shear = history.shear;
    out.rollingSpring = history.rollingAngle;
    return out;
}

// Entry e of the batch from one pair, as pass 1 of pairForcesBatched fills it.
template <RollingModel Rolling>
void fillLane(ContactBatch& b, int e, int entry, const PairInput& in, const dem::InteractionTable& table) {
    const Vec3 d = in.xi - in.xj;
    const double dist2 = d.squaredNorm();
    b.entry[e] = entry;
    b.particleI[e] = 2 * entry;
    b.particleJ[e] = 2 * entry + 1;
    b.properties[e] = &table(in.materialI, in.materialJ);
    b.dx[e] = d.x();
    b.dy[e] = d.y();
    b.dz[e] = d.z();
    b.distanceSquared[e] = dist2;
    b.radiusI[e] = in.ri;
    b.radiusJ[e] = in.rj;
    b.massI[e] = in.mi;
    b.massJ[e] = in.mj;
    const Vec3 dv = in.vi - in.vj;
    b.dvx[e] = dv.x();
    b.dvy[e] = dv.y();
    b.dvz[e] = dv.z();
    b.wix[e] = in.wi.x();
    b.wiy[e] = in.wi.y();
    b.wiz[e] = in.wi.z();
    b.wjx[e] = in.wj.x();
    b.wjy[e] = in.wj.y();
    b.wjz[e] = in.wj.z();
    b.sx[e] = in.history.shear.x();
    b.sy[e] = in.history.shear.y();
    b.sz[e] = in.history.shear.z();
    if constexpr (keepsRolling<Rolling>()) {
        b.mx[e] = in.history.rollingAngle.x();
        b.my[e] = in.history.rollingAngle.y();
        b.mz[e] = in.history.rollingAngle.z();
    }
}

Vec3 randomUnit(std::mt19937_64& rng) {
    std::normal_distribution<double> g(0.0, 1.0);
    Vec3 u(g(rng), g(rng), g(rng));
    while (u.norm() < 1e-3) u = Vec3(g(rng), g(rng), g(rng));
    return u.normalized();
}

Vec3 randomInBall(std::mt19937_64& rng, double radius) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    return radius * std::cbrt(u(rng)) * randomUnit(rng);
}

// Random touching pairs.  uniform: all sand-sand (one properties object);
// else each particle sand or steel (four table entries, (0,1) and (1,0) distinct).
// Spring histories are scaled by the Coulomb and rolling limits of the pair,
// estimated from the elastic force: a quarter zero, a quarter well inside,
// half up to three times the limit (most of these slide or hit the limit).
// The rolling spring is an angle: its limit is the torque limit over the
// rolling stiffness of the model (rolling).
std::vector<PairInput> randomContacts(int count, bool uniform, const dem::InteractionTable& table,
                                      RollingModel rolling, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const std::vector<dem::Material> mats{sand(), steel()};
    std::vector<PairInput> contacts;
    contacts.reserve(count);
    for (int c = 0; c < count; ++c) {
        PairInput in;
        in.materialI = uniform ? 0 : static_cast<int>(u01(rng) < 0.5);
        in.materialJ = uniform ? 0 : static_cast<int>(u01(rng) < 0.5);
        in.ri = 2e-4 + 8e-4 * u01(rng);
        in.rj = 2e-4 + 8e-4 * u01(rng);
        in.mi = sphereMass(in.ri, mats[in.materialI].density);
        in.mj = sphereMass(in.rj, mats[in.materialJ].density);
        const double radiusSum = in.ri + in.rj;
        const double overlapFraction = 1e-4 * std::pow(500.0, u01(rng));  // 1e-4 .. 5e-2, log-uniform
        const Vec3 n = randomUnit(rng);
        in.xj = Vec3(0.02 * (u01(rng) - 0.5), 0.02 * (u01(rng) - 0.5), 0.02 * (u01(rng) - 0.5));
        in.xi = in.xj + (radiusSum * (1.0 - overlapFraction)) * n;
        in.vi = randomInBall(rng, 0.1);
        in.vj = randomInBall(rng, 0.1);
        in.wi = randomInBall(rng, 100.0);
        // One in twelve pairs spins together (CDT at rest, no rolling torque).
        in.wj = u01(rng) < 1.0 / 12.0 ? in.wi : randomInBall(rng, 100.0);

        const dem::InteractionProperties& props = table(in.materialI, in.materialJ);
        const double overlap = radiusSum * overlapFraction;
        const double radiusEff = in.ri * in.rj / radiusSum;
        const double elastic = props.normalStiffnessFactor * std::sqrt(radiusEff * overlap) * overlap;
        const double kt = props.tangentialStiffnessFactor * std::sqrt(radiusEff * overlap);
        const double shearLimit = props.friction * elastic / kt;
        const double torqueLimit = props.rollingFriction * radiusEff * elastic;
        const double rollingStiffness =
            rolling == RollingModel::EPSD
                ? dem::epsdRollingStiffness(props.normalStiffnessFactor * std::sqrt(radiusEff * overlap),
                                            props.rollingFriction, radiusEff)
                : dem::epsd2RollingStiffness(kt, radiusEff);
        auto level = [&]() {
            const double r = u01(rng);
            if (r < 0.25) return 0.0;
            if (r < 0.5) return 0.05 * u01(rng);
            return 3.0 * u01(rng);
        };
        // Not exactly tangential: the law projects the spring onto the plane.
        in.history.shear = level() * shearLimit * (randomUnit(rng) + 0.1 * n).normalized();
        in.history.rollingAngle = level() * (torqueLimit / rollingStiffness) * randomUnit(rng);
        contacts.push_back(in);
    }
    return contacts;
}

// Batch sizes: full batches, single lanes and the remainders of every vector
// width (2, 4, 8), then random sizes until the contacts are used up.
std::vector<int> chunkSizes(int total, std::mt19937_64& rng) {
    std::vector<int> sizes{ContactBatch::capacity, 1, 2, 3, 5, 7, 8, 9, 15, 16, 17, 31, 33, 63, 65,
                           ContactBatch::capacity - 1, ContactBatch::capacity};
    std::uniform_int_distribution<int> pick(1, ContactBatch::capacity);
    int used = 0;
    for (int s : sizes) used += s;
    while (used < total) {
        const int s = std::min(pick(rng), total - used);
        sizes.push_back(s);
        used += s;
    }
    return sizes;
}

struct LaneComparison {
    int lanes = 0, mismatches = 0;
    int sliding = 0, rollingLimited = 0, resting = 0;
    int uniformBatches = 0, mixedBatches = 0;
    std::string firstMismatch;
};

template <RollingModel Rolling>
LaneComparison compareBatchWithScalar(bool uniform, std::uint64_t seed) {
    const dem::InteractionTable table = sandSteelTable();
    std::mt19937_64 rng(seed);
    const int total = 2000;
    const std::vector<PairInput> contacts = randomContacts(total, uniform, table, Rolling, rng);
    const std::vector<int> sizes = chunkSizes(total, rng);
    const double dt = 1e-6;

    // Every byte starts as 0xff (every double a NaN): a lane that read an
    // unfilled field (or a history array that None/CDT leave alone) would show.
    auto batch = std::make_unique<ContactBatch>();
    std::memset(static_cast<void*>(batch.get()), 0xff, sizeof(ContactBatch));

    LaneComparison r;
    int next = 0;
    for (const int size : sizes) {
        if (next >= total) break;
        const int count = std::min(size, total - next);
        for (int e = 0; e < count; ++e) fillLane<Rolling>(*batch, e, next + e, contacts[next + e], table);
        bool sameProperties = true;
        for (int e = 1; e < count; ++e) sameProperties = sameProperties && batch->properties[e] == batch->properties[0];
        ++(sameProperties ? r.uniformBatches : r.mixedBatches);

        dem::evaluateContactBatch<Rolling, false>(*batch, count, dt);

        for (int e = 0; e < count; ++e) {
            const int c = next + e;
            const PairOutput ref = scalarReference<Rolling>(contacts[c], table, dt);
            r.sliding += ref.sliding;
            r.rollingLimited += ref.rollingLimited;
            r.resting += ref.resting;
            ++r.lanes;
            struct Field {
                const char* name;
                double batch, scalar;
            };
            std::vector<Field> fields{
                {"force.x", batch->fx[e], ref.force.x()},     {"force.y", batch->fy[e], ref.force.y()},
                {"force.z", batch->fz[e], ref.force.z()},     {"torqueI.x", batch->tix[e], ref.torqueI.x()},
                {"torqueI.y", batch->tiy[e], ref.torqueI.y()}, {"torqueI.z", batch->tiz[e], ref.torqueI.z()},
                {"torqueJ.x", batch->tjx[e], ref.torqueJ.x()}, {"torqueJ.y", batch->tjy[e], ref.torqueJ.y()},
                {"torqueJ.z", batch->tjz[e], ref.torqueJ.z()}, {"shear.x", batch->sx[e], ref.shear.x()},
                {"shear.y", batch->sy[e], ref.shear.y()},     {"shear.z", batch->sz[e], ref.shear.z()}};
            if constexpr (keepsRolling<Rolling>()) {
                fields.push_back({"rollingSpring.x", batch->mx[e], ref.rollingSpring.x()});
                fields.push_back({"rollingSpring.y", batch->my[e], ref.rollingSpring.y()});
                fields.push_back({"rollingSpring.z", batch->mz[e], ref.rollingSpring.z()});
            }
            bool same = true;
            for (const Field& f : fields) {
                if (bitsOf(f.batch) == bitsOf(f.scalar)) continue;
                if (same && r.firstMismatch.empty()) {
                    char text[256];
                    std::snprintf(text, sizeof text,
                                  "contact %d (lane %d of a batch of %d): %s batch %.17g (%016llx) scalar %.17g (%016llx)",
                                  c, e, count, f.name, f.batch, static_cast<unsigned long long>(bitsOf(f.batch)),
                                  f.scalar, static_cast<unsigned long long>(bitsOf(f.scalar)));
                    r.firstMismatch = text;
                }
                same = false;
            }
            r.mismatches += !same;
        }
        next += count;
    }
    return r;
}

template <RollingModel Rolling>
void expectBitwiseLanes(const char* model) {
    for (const bool uniform : {true, false}) {
        const LaneComparison r = compareBatchWithScalar<Rolling>(uniform, uniform ? 20240611u : 777u);
        std::printf("%s %s: %d lanes in %d uniform + %d mixed batches, %d mismatches; sliding %d, "
                    "rolling-limited %d, resting %d\n",
                    model, uniform ? "uniform" : "mixed", r.lanes, r.uniformBatches, r.mixedBatches, r.mismatches,
                    r.sliding, r.rollingLimited, r.resting);
        SCOPED_TRACE(std::string(model) + (uniform ? " uniform" : " mixed"));
        EXPECT_EQ(r.lanes, 2000);
        EXPECT_EQ(r.mismatches, 0) << "first: " << r.firstMismatch;
        // Both sides of every select were taken by a good share of lanes.
        EXPECT_GT(r.sliding, r.lanes / 20);
        EXPECT_GT(r.lanes - r.sliding, r.lanes / 20);
        if (keepsRolling<Rolling>()) {
            EXPECT_GT(r.rollingLimited, r.lanes / 20);
            EXPECT_GT(r.lanes - r.rollingLimited, r.lanes / 20);
        }
        if (Rolling == RollingModel::CDT) {
            EXPECT_GT(r.resting, r.lanes / 40);
        }
        if (uniform) {
            EXPECT_EQ(r.mixedBatches, 0);
        } else {
            // Single-lane batches are uniform by definition; all longer ones mix.
            EXPECT_GT(r.mixedBatches, 20);
        }
    }
}

TEST(ContactLawBatch, NoRollingLanesEqualScalarLawBitwise) { expectBitwiseLanes<RollingModel::None>("none"); }
TEST(ContactLawBatch, CdtLanesEqualScalarLawBitwise) { expectBitwiseLanes<RollingModel::CDT>("cdt"); }
TEST(ContactLawBatch, EpsdLanesEqualScalarLawBitwise) { expectBitwiseLanes<RollingModel::EPSD>("epsd"); }
TEST(ContactLawBatch, Epsd2LanesEqualScalarLawBitwise) { expectBitwiseLanes<RollingModel::EPSD2>("epsd2"); }

// ---------------------------------------------------------------------------
// 2. Engine level: a row longer than a batch.

constexpr double kBigRadius = 5e-3;
constexpr int kSatellites = 300;
constexpr int kClusterSide = 3;  // 27 spheres, 54 touching pairs
constexpr int kBig = kClusterSide * kClusterSide * kClusterSide;  // index of the large sphere

struct BigRowSetup {
    std::vector<dem::InsertedParticle> cluster, big, satellites;
    std::vector<Vec3> velocity, omega;  // per particle, in insertion order
};

// Material 0 sand (cluster, satellites), 1 steel (the large sphere).  The
// cluster comes first: its rows (sand-sand) and the start of the large
// sphere's row (sand-steel) share the first batch, a mixed one.  Satellites
// sit on the large sphere's surface (Fibonacci points), overlapping it by
// 0.2-1 % of their radius; with pairs listed as (i, j > i) the large sphere,
// inserted before them, owns all their pairs with it in one row.
BigRowSetup bigRowSetup() {
    BigRowSetup s;
    std::mt19937_64 rng(4242);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const Vec3 clusterOrigin(0.03, 0.0, 0.0);
    for (int z = 0; z < kClusterSide; ++z)
        for (int y = 0; y < kClusterSide; ++y)
            for (int x = 0; x < kClusterSide; ++x)
                s.cluster.push_back({clusterOrigin + 8e-4 * Vec3(x, y, z), 4.005e-4 + 3.5e-6 * u01(rng)});
    s.big.push_back({Vec3::Zero(), kBigRadius});
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < kSatellites; ++k) {
        const double z = 1.0 - (2.0 * k + 1.0) / kSatellites;
        const double rho = std::sqrt(1.0 - z * z);
        const Vec3 dir(rho * std::cos(golden * k), rho * std::sin(golden * k), z);
        const double r = 3e-4 + 2e-4 * u01(rng);
        const double overlap = (0.002 + 0.008 * u01(rng)) * r;
        s.satellites.push_back({(kBigRadius + r - overlap) * dir, r});
    }
    const std::size_t n = s.cluster.size() + s.big.size() + s.satellites.size();
    for (std::size_t i = 0; i < n; ++i) {
        const bool big = static_cast<int>(i) == kBig;
        s.velocity.push_back(big ? Vec3::Zero() : randomInBall(rng, 0.05));
        s.omega.push_back(big ? Vec3(0.0, 0.0, 20.0) : randomInBall(rng, 100.0));
    }
    return s;
}

dem::Simulation bigRowSimulation(const BigRowSetup& setup, RollingModel rolling, bool wet, bool vectorized) {
    const std::vector<dem::Material> mats{sand(), steel()};
    dem::SimulationSettings settings;
    settings.timeStep = 1e-6;
    settings.gravity = Vec3(0.0, 0.0, -9.81);
    settings.forces.rolling = rolling;
    settings.forces.vectorizedPairLaw = vectorized;
    if (wet) {
        settings.forces.cohesion = dem::CohesionModel::Capillary;
        settings.forces.capillary = {0.072, 0.0};
    }
    settings.source = "test_contact_law_batch";
    dem::Simulation sim(settings, mats, sandSteelTable(), {});
    sim.insert(setup.cluster, 0, Vec3::Zero());
    sim.insert(setup.big, 1, Vec3::Zero());
    sim.insert(setup.satellites, 0, Vec3::Zero());
    dem::ParticleStore& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        p.velocity[i] = setup.velocity[i];
        p.omega[i] = setup.omega[i];
    }
    if (wet) sim.setWaterContent(0.05);
    return sim;
}

// Touching pairs listed in particle i's row now.
int touchingInRow(const dem::Simulation& sim, int i) {
    const auto& p = sim.particles();
    const auto& offsets = sim.pairList().offsets();
    const auto& neighbors = sim.pairList().neighbors();
    int touching = 0;
    for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
        const int j = neighbors[k];
        const double reach = p.radius[i] + p.radius[j];
        touching += (p.position[i] - p.position[j]).squaredNorm() < reach * reach;
    }
    return touching;
}

// Number of differing doubles between the two runs' states (first one named).
int stateDifferences(const dem::Simulation& a, const dem::Simulation& b, std::string& first) {
    int differences = 0;
    auto note = [&](const std::string& what, double x, double y) {
        if (bitsOf(x) == bitsOf(y)) return;
        if (differences++ == 0) {
            std::ostringstream os;
            os.precision(17);
            os << what << ": batched " << x << " scalar " << y;
            first = os.str();
        }
    };
    const auto& p = a.particles();
    const auto& q = b.particles();
    if (p.size() != q.size()) {
        first = "particle counts differ";
        return 1;
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
        const std::string at = " of particle " + std::to_string(i);
        for (int c = 0; c < 3; ++c) {
            note("position" + at, p.position[i][c], q.position[i][c]);
            note("velocity" + at, p.velocity[i][c], q.velocity[i][c]);
            note("omega" + at, p.omega[i][c], q.omega[i][c]);
            note("force" + at, p.force[i][c], q.force[i][c]);
            note("torque" + at, p.torque[i][c], q.torque[i][c]);
        }
    }
    if (a.pairList().offsets() != b.pairList().offsets() || a.pairList().neighbors() != b.pairList().neighbors()) {
        if (differences++ == 0) first = "pair lists differ";
        return differences;
    }
    const dem::PairStateView sa = a.pairList().state(), sb = b.pairList().state();
    for (std::size_t k = 0; k < sa.size(); ++k) {
        const dem::PairState x = sa[k], y = sb[k];
        for (int c = 0; c < 3; ++c) {
            note("shear spring of pair entry " + std::to_string(k), x.contact.shear[c], y.contact.shear[c]);
            note("rolling spring of pair entry " + std::to_string(k), x.contact.rollingAngle[c],
                 y.contact.rollingAngle[c]);
        }
    }
    return differences;
}

void expectBatchedEngineEqualsScalar(RollingModel rolling, const char* model, int threads, bool wet = false) {
    ThreadCount threadCount(threads);
    const BigRowSetup setup = bigRowSetup();
    dem::Simulation batched = bigRowSimulation(setup, rolling, wet, true);
    dem::Simulation scalar = bigRowSimulation(setup, rolling, wet, false);
    batched.step(1);
    scalar.step(1);
    // The large sphere owns its row, and the row exceeds two batches.
    const int bigRow = touchingInRow(batched, kBig);
    ASSERT_GT(bigRow, 2 * ContactBatch::capacity) << "the large sphere's row does not span three batches";
    ASSERT_GT(touchingInRow(batched, 0), 0) << "the cluster does not start the first batch";
    std::string first;
    int differences = stateDifferences(batched, scalar, first);
    EXPECT_EQ(differences, 0) << model << ", " << threads << " thread(s), after 1 step: " << first;

    batched.step(49);
    scalar.step(49);
    differences = stateDifferences(batched, scalar, first);
    const std::size_t touching = batched.lastStep().contacts.touchingPairs;
    std::printf("%s%s, %d thread(s): big row %d touching pairs at step 1, %d at step 50; %zu touching pairs, "
                "%zu bridges; %d differing doubles after 50 steps; |F_big| = %.6e N\n",
                model, wet ? " wet" : "", threads, bigRow, touchingInRow(batched, kBig), touching,
                batched.lastStep().contacts.bridges, differences, batched.particles().force[kBig].norm());
    if (wet) {
        // Bridges held liquid, and some act beyond contact (more bridges than touching pairs).
        EXPECT_GT(batched.lastStep().contacts.bridges, touching);
        EXPECT_EQ(batched.lastStep().contacts.bridges, scalar.lastStep().contacts.bridges);
    }
    EXPECT_EQ(differences, 0) << model << ", " << threads << " thread(s), after 50 steps: " << first;
    EXPECT_EQ(touching, scalar.lastStep().contacts.touchingPairs);
    // Not a system at rest: the contacts pushed and turned the satellites
    // (the large sphere's net force from its contacts is non-zero).
    EXPECT_GT(touchingInRow(batched, kBig), ContactBatch::capacity);
    EXPECT_GT(batched.particles().force[kBig].norm(), 1e-6);
    double shear = 0.0;
    for (const dem::PairState s : batched.pairList().state()) shear = std::max(shear, s.contact.shear.norm());
    EXPECT_GT(shear, 0.0);
}

TEST(ContactLawBatch, EngineRowLongerThanBatchEqualsScalarPath) {
    expectBatchedEngineEqualsScalar(RollingModel::None, "none", 1);
    expectBatchedEngineEqualsScalar(RollingModel::CDT, "cdt", 1);
    expectBatchedEngineEqualsScalar(RollingModel::EPSD, "epsd", 1);
    expectBatchedEngineEqualsScalar(RollingModel::EPSD2, "epsd2", 1);
}

TEST(ContactLawBatch, EngineRowLongerThanBatchEqualsScalarPathTwoThreads) {
    expectBatchedEngineEqualsScalar(RollingModel::None, "none", 2);
    expectBatchedEngineEqualsScalar(RollingModel::EPSD, "epsd", 2);
}

TEST(ContactLawBatch, EngineWithCapillaryBridgesEqualsScalarPath) {
    expectBatchedEngineEqualsScalar(RollingModel::CDT, "cdt", 1, true);
    expectBatchedEngineEqualsScalar(RollingModel::EPSD2, "epsd2", 1, true);
    expectBatchedEngineEqualsScalar(RollingModel::CDT, "cdt", 2, true);
}

}  // namespace
