// demBench: the performance benchmark driver of bench/run (issue 7).
//
//   demBench settle -case DIR -out PREFIX [-threads N] [-placement rsa|lattice|bed [-bed FILE]]
//                   [-packing PHI] [-gravityFactor G] [-settleTime T] [-relaxTime T]
//                   [-speedTolerance V] [-quietSamples Q]
//       Builds the bed of DIR/constant/demProperties (its first insertion
//       block: region, size distribution, count) and lets it settle; writes
//       PREFIX.bed (text: "x y z radius" per particle, the input of both demLib
//       and LIGGGHTS timing runs) and PREFIX.restart.h5.
//
//   demBench time -case DIR -bed FILE -steps K [-threads N | -ranks R] [-sample S]
//       Inserts the bed at rest (no contact history, exactly what LIGGGHTS gets
//       from read_data), applies the case's waterContent for the capillary
//       model, takes one untimed step (first pair list and forces, like the
//       LIGGGHTS 'run' setup) and times K steps.  Prints 'sample' lines (step,
//       coordination number, kinetic energy) every S steps and 'result' lines
//       (key value) that bench/run parses.  -ranks R: the bed on R ranks of the
//       domain decomposition that are threads of this process (each rank its
//       own slab and arrays, docs/engine.md), instead of N OpenMP threads on one
//       simulation (wet beds share their water over the ranks).
//       mpirun -np R demBench time ... -parallel: the same on R MPI ranks, one
//       thread each.  Both print, besides the rate: ghost_fraction (ghosts /
//       owned over all ranks, mean of the samples), bytes_per_particle_step
//       (payload all ranks sent over the timed steps / particle-steps; the
//       communicator's counters), communication_seconds (rank 0's time inside
//       collectives; _max the largest rank's; communication_share = rank 0's /
//       the timed wall time), imbalance_mean/_max/_end (max/mean owned), the
//       slab re-cuts of the load balance and the particles migrated.  The slabs
//       start at equal counts; the engine re-cuts them at list builds when
//       max/mean owned exceeds 1.10.
//
//   demBench copies -case DIR -bed FILE -steps K [-copies C]
//       C independent simulations of the bed at once, each on its own thread
//       with one OpenMP thread: what C cores give for work that shares
//       nothing, the ceiling of C threads on one simulation.
//
// Settling from a loose packing under gravity takes long in physical time
// (the top of the column falls by half the bed height); -gravityFactor G > 1
// shortens it (sqrt(G) times), after which the bed relaxes under 1 g for
// -relaxTime, so the stored bed carries the 1 g overlaps.  The relaxation ends
// early once the rms speed has stayed below -speedTolerance for Q samples in a
// row (default 4, 2000 steps).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "demLib/case_setup.hpp"
#include "demLib/command_line.hpp"
#include "demLib/communicator.hpp"
#include "demLib/constants.hpp"
#include "demLib/error.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/simulation.hpp"

#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

#include <cstring>

namespace {

// FNV-1a over the bits of positions, velocities and spins: two builds that
// claim bitwise identical results must print the same value.
unsigned long long stateHash(const dem::ParticleStore& p) {
    unsigned long long h = 1469598103934665603ULL;
    auto add = [&](const std::vector<dem::Vec3>& v) {
        for (const dem::Vec3& x : v)
            for (int c = 0; c < 3; ++c) {
                unsigned long long bits;
                const double value = x[c];
                std::memcpy(&bits, &value, sizeof bits);
                h = (h ^ bits) * 1099511628211ULL;
            }
    };
    add(p.position);
    add(p.velocity);
    add(p.omega);
    return h;
}



using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Peak and current resident set size in bytes (Linux /proc/self/status).
std::size_t procStatusBytes(const std::string& key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line)) {
        if (line.compare(0, key.size() + 1, key + ":") == 0) {
            std::istringstream s(line.substr(key.size() + 1));
            std::size_t kib = 0;
            s >> kib;
            return kib * 1024;
        }
    }
    return 0;
}

struct Options {
    std::map<std::string, std::string> values;
    bool has(const std::string& k) const { return values.count(k) > 0; }
    std::string get(const std::string& k, const std::string& fallback = "") const {
        const auto it = values.find(k);
        if (it != values.end()) return it->second;
        if (fallback.empty()) throw dem::InputError("option -" + k + " is required");
        return fallback;
    }
    double number(const std::string& k, double fallback) const {
        if (!has(k)) return fallback;
        const std::string& text = values.at(k);
        double v = 0.0;
        if (!dem::parseNumber(text, v))
            throw dem::InputError("option -" + k + " expects a number, got '" + text + "'");
        return v;
    }
    // A count: a whole number >= least.
    long wholeNumber(const std::string& k, long fallback, long least) const {
        const double v = number(k, static_cast<double>(fallback));
        if (v != std::floor(v) || v < static_cast<double>(least))
            throw dem::InputError("option -" + k + " expects a whole number >= " + std::to_string(least) + ", got '" +
                                  values.at(k) + "'");
        return static_cast<long>(v);
    }
};

struct BedParticle {
    dem::Vec3 position;
    double radius;
};

// Random sequential addition of the population into the insertion region's
// bounding box, largest first: a loose, isotropic, overlap-free packing that
// any size distribution reaches (the insertion lattice is spaced by the largest
// diameter, far too loose for a 1:5 size ratio).  The box height is cut to the
// one that holds the solid volume at the target packing fraction.
std::vector<dem::InsertedParticle> randomSequentialAddition(const dem::InsertionSpec& spec,
                                                            double packingFraction) {
    const dem::SizeDistribution& dist = *spec.distribution;
    std::size_t count = spec.request.targetCount;
    if (count == 0)
        throw dem::InputError("the benchmark case's insertion block must give 'count'");
    std::vector<double> d = dem::drawDiametersForCount(dist, count, spec.request.placement.seed);
    std::sort(d.begin(), d.end(), std::greater<double>());
    double solid = 0.0;
    for (double di : d) solid += dem::pi / 6.0 * di * di * di;
    const dem::Vec3 lo = spec.region->boundsMin();
    dem::Vec3 hi = spec.region->boundsMax();
    const double base = (hi.x() - lo.x()) * (hi.y() - lo.y());
    hi.z() = std::min(hi.z(), lo.z() + solid / (packingFraction * base));

    const double cell = d.front();
    const int nx = std::max(1, static_cast<int>((hi.x() - lo.x()) / cell));
    const int ny = std::max(1, static_cast<int>((hi.y() - lo.y()) / cell));
    const int nz = std::max(1, static_cast<int>((hi.z() - lo.z()) / cell));
    auto cellIndex = [&](const dem::Vec3& x, int& cx, int& cy, int& cz) {
        cx = std::clamp(static_cast<int>((x.x() - lo.x()) / (hi.x() - lo.x()) * nx), 0, nx - 1);
        cy = std::clamp(static_cast<int>((x.y() - lo.y()) / (hi.y() - lo.y()) * ny), 0, ny - 1);
        cz = std::clamp(static_cast<int>((x.z() - lo.z()) / (hi.z() - lo.z()) * nz), 0, nz - 1);
    };
    std::vector<std::vector<int>> grid(static_cast<std::size_t>(nx) * ny * nz);
    std::vector<dem::InsertedParticle> placed;
    placed.reserve(count);
    std::mt19937_64 random(spec.request.placement.seed + 0x9e3779b97f4a7c15ULL);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const long maxAttempts = 200000;
    for (double di : d) {
        const double r = 0.5 * di;
        bool done = false;
        for (long attempt = 0; attempt < maxAttempts && !done; ++attempt) {
            const dem::Vec3 x(lo.x() + r + unit(random) * (hi.x() - lo.x() - 2 * r),
                              lo.y() + r + unit(random) * (hi.y() - lo.y() - 2 * r),
                              lo.z() + r + unit(random) * (hi.z() - lo.z() - 2 * r));
            int cx, cy, cz;
            cellIndex(x, cx, cy, cz);
            bool free = true;
            for (int z = std::max(0, cz - 1); z <= std::min(nz - 1, cz + 1) && free; ++z)
                for (int y = std::max(0, cy - 1); y <= std::min(ny - 1, cy + 1) && free; ++y)
                    for (int xx = std::max(0, cx - 1); xx <= std::min(nx - 1, cx + 1) && free; ++xx)
                        for (int k : grid[(static_cast<std::size_t>(z) * ny + y) * nx + xx]) {
                            const double reach = r + placed[k].radius;
                            if ((placed[k].position - x).squaredNorm() < reach * reach) {
                                free = false;
                                break;
                            }
                        }
            if (!free) continue;
            grid[(static_cast<std::size_t>(cz) * ny + cy) * nx + cx].push_back(static_cast<int>(placed.size()));
            placed.push_back({x, r});
            done = true;
        }
        if (!done) {
            std::ostringstream s;
            s << "random sequential addition placed only " << placed.size() << " of " << count
              << " particles at packing fraction " << packingFraction
              << "; expected a lower -packing or a larger insertion region";
            throw dem::InputError(s.str());
        }
    }
    return placed;
}

double rmsSpeed(const dem::ParticleStore& p) {
    double s = 0.0;
    for (const dem::Vec3& v : p.velocity) s += v.squaredNorm();
    return p.empty() ? 0.0 : std::sqrt(s / p.size());
}

// The settled bed rests on the walls with micrometre overlaps, which
// Simulation::insert rejects (and read_data would turn into a kick): move each
// particle along the wall normals until it just touches.  The shift is the
// elastic overlap, ~1e-3 of a radius.
std::vector<dem::InsertedParticle> currentBed(const dem::ParticleStore& p, const std::vector<dem::Wall>& walls,
                                              double time) {
    std::vector<dem::InsertedParticle> bed(p.size());
    std::vector<dem::WallContact> touching;
    for (std::size_t i = 0; i < p.size(); ++i) {
        bed[i] = {p.position[i], p.radius[i]};
        for (int pass = 0; pass < 3; ++pass) {
            bool moved = false;
            for (const dem::Wall& w : walls) {
                if (!w.isActive(time)) continue;
                touching.clear();
                w.findContacts(bed[i].position, bed[i].radius, time, touching);
                for (const dem::WallContact& c : touching)
                    if (c.overlap > 0.0) {
                        bed[i].position += c.overlap * c.normal;
                        moved = true;
                    }
            }
            if (!moved) break;
        }
    }
    return bed;
}

// Runs until `time` has passed or, after a tenth of it, the rms speed has been
// below `tolerance` in `quietSamples` samples in a row (a sample every 500
// steps); returns the simulated time.  One quiet sample is not rest: a settled
// bed rings in its vertical mode (period about 0.01 s for the 50k bed), and a
// sample near a node of that mode reads low while the bed still moves.
double settleFor(dem::Simulation& sim, double time, double tolerance, int quietSamples, const std::string& phase) {
    const auto start = Clock::now();
    const long steps = static_cast<long>(std::ceil(time / sim.timeStep()));
    const long chunk = 500;
    long done = 0;
    int quiet = 0;
    while (done < steps) {
        const long k = std::min(chunk, steps - done);
        sim.step(k);
        done += k;
        const double v = rmsSpeed(sim.particles());
        quiet = v < tolerance ? quiet + 1 : 0;
        std::cout << phase << ": t " << std::setprecision(4) << done * sim.timeStep() << " s, rms speed " << v
                  << " m/s, coordination " << sim.coordinationNumber() << ", " << std::setprecision(3)
                  << secondsSince(start) << " s wall" << std::endl;
        if (done * sim.timeStep() > 0.1 * time && quiet >= quietSamples) break;
    }
    if (quiet < quietSamples)
        std::cout << phase << ": stopped at the time limit, not at rest (rms speed above " << tolerance
                  << " m/s in the last " << quietSamples << " samples)" << std::endl;
    return done * sim.timeStep();
}

std::vector<dem::InsertedParticle> readBed(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw dem::InputError("cannot open bed file '" + file + "'");
    std::vector<dem::InsertedParticle> bed;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        dem::InsertedParticle q;
        if (!(s >> q.position.x() >> q.position.y() >> q.position.z() >> q.radius))
            throw dem::InputError("bed file '" + file + "': expected 'x y z radius' in line '" + line + "'");
        bed.push_back(q);
    }
    return bed;
}

int settle(const Options& o) {
    const std::string caseDir = o.get("case");
    const std::string out = o.get("out");
    dem::CaseSetup setup = dem::readCaseSetup(caseDir);
    if (setup.insertions.empty())
        throw dem::InputError(setup.propertiesFile + ": demBench expects one insertion block");
    const dem::InsertionSpec& spec = setup.insertions.front();
    const std::string placement = o.get("placement", "rsa");

    dem::CaseSetup loose = setup;
    loose.settings.gravity *= o.number("gravityFactor", 1.0);
    std::unique_ptr<dem::Simulation> sim = dem::makeSimulation(loose);
    if (placement == "rsa") {
        sim->insert(randomSequentialAddition(spec, o.number("packing", 0.3)), spec.materialIndex,
                    dem::Vec3::Zero(), spec.context);
    } else if (placement == "lattice") {
        dem::performInsertion(*sim, spec);
    } else if (placement == "bed") {  // continue settling a stored bed
        sim->insert(readBed(o.get("bed")), spec.materialIndex, dem::Vec3::Zero(), "bed");
    } else {
        throw dem::InputError("-placement expects 'rsa', 'lattice' or 'bed'");
    }
    std::cout << "settle: " << sim->particles().size() << " particles placed (" << placement << ")" << std::endl;
    const double tolerance = o.number("speedTolerance", 2e-3);
    const int quietSamples = static_cast<int>(o.wholeNumber("quietSamples", 4, 1));
    settleFor(*sim, o.number("settleTime", 0.05), tolerance, 1, "settle");

    // Relax under the true gravity from rest, then store.
    std::unique_ptr<dem::Simulation> relaxed = dem::makeSimulation(setup);
    relaxed->insert(currentBed(sim->particles(), sim->walls(), sim->time()), spec.materialIndex, dem::Vec3::Zero(), spec.context);
    sim.reset();
    settleFor(*relaxed, o.number("relaxTime", 0.01), tolerance, quietSamples, "relax");

    const std::vector<dem::InsertedParticle> settled =
        currentBed(relaxed->particles(), relaxed->walls(), relaxed->time());
    std::ofstream bed(out + ".bed");
    bed << "# demBench settled bed: x y z radius [m]; " << settled.size() << " particles, coordination "
        << relaxed->coordinationNumber() << "\n";
    bed << std::setprecision(17);
    for (const dem::InsertedParticle& q : settled)
        bed << q.position.x() << ' ' << q.position.y() << ' ' << q.position.z() << ' ' << q.radius << '\n';
    if (!bed) throw dem::RuntimeError("cannot write '" + out + ".bed'");
    relaxed->writeRestart(out + ".restart.h5");
    std::cout << "settle: wrote " << out << ".bed and " << out << ".restart.h5" << std::endl;
    return 0;
}

// K independent copies of the bed's simulation at once, one thread each, in
// this process: what K cores give for work that shares nothing (the ceiling
// for K threads on one simulation; bench/run (d) prints it beside them).
int independentCopies(const Options& o) {
    const std::string caseDir = o.get("case");
    const int copies = static_cast<int>(o.wholeNumber("copies", 2, 1));
    const long steps = o.wholeNumber("steps", 1000, 0);
    if (copies < 1) throw dem::InputError("demBench copies: -copies expects an integer >= 1");
    const std::vector<dem::InsertedParticle> bed = readBed(o.get("bed"));
    std::vector<double> rate(copies, 0.0);
    std::vector<unsigned long long> hash(copies, 0);
    std::vector<std::string> errors(copies);
    std::atomic<int> ready{0};
    auto work = [&](int c) {
        try {
#ifdef _OPENMP
            omp_set_num_threads(1);  // a new thread starts from OMP_NUM_THREADS, not main's setting
#endif
            // Each copy is built by its own thread (its memory first touched there).
            dem::CaseSetup setup = dem::readCaseSetup(caseDir);
            const int material = setup.insertions.empty() ? 0 : setup.insertions.front().materialIndex;
            std::unique_ptr<dem::Simulation> sim = dem::makeSimulation(setup);
            sim->insert(bed, material, dem::Vec3::Zero(), "bed");
            if (setup.waterContent > 0.0) sim->setWaterContent(setup.waterContent);
            sim->step(1);
            ++ready;
            while (ready.load() < copies) std::this_thread::yield();  // start together
            const auto start = Clock::now();
            sim->step(steps);
            rate[c] = static_cast<double>(sim->particles().size()) * steps / secondsSince(start);
            hash[c] = stateHash(sim->particles());
        } catch (const std::exception& e) {
            errors[c] = e.what();
            ++ready;
        }
    };
    std::vector<std::thread> threads;
    for (int c = 0; c < copies; ++c) threads.emplace_back(work, c);
    for (auto& t : threads) t.join();
    for (const std::string& e : errors)
        if (!e.empty()) throw dem::RuntimeError("demBench copies: " + e);
    double total = 0.0;
    std::cout << std::setprecision(6);
    for (int c = 0; c < copies; ++c) {
        std::cout << "result copy" << c << "_particle_steps_per_s " << rate[c] << "\n"
                  << "result copy" << c << "_state_hash " << std::hex << hash[c] << std::dec << "\n";
        total += rate[c];
    }
    std::cout << "result copies " << copies << "\n"
              << "result aggregate_particle_steps_per_s " << total << std::endl;
    return 0;
}

// Advances `steps` steps in calls of `sample` steps, calling onSample(done)
// after each; returns the seconds spent stepping (the samples not counted).
// settle(), if given, runs after each call inside the timed interval (thread
// ranks: a barrier, so that the time is that of the slowest rank).
double timedSteps(dem::Simulation& sim, long steps, long sample, const std::function<void(long)>& onSample,
                  const std::function<void()>& settle = {}) {
    double stepping = 0.0;
    for (long done = 0; done < steps;) {
        const long k = std::min(sample, steps - done);
        const auto t0 = Clock::now();
        sim.step(k);
        if (settle) settle();
        stepping += secondsSince(t0);
        done += k;
        onSample(done);
    }
    return stepping;
}

// Slabs along the bed's longer horizontal extent, cut where they hold equal
// numbers of particles.
dem::SlabDecomposition equalCountSlabs(const std::vector<dem::InsertedParticle>& bed, int ranks) {
    dem::Vec3 lower = dem::Vec3::Constant(std::numeric_limits<double>::max());
    dem::Vec3 upper = -lower;
    for (const dem::InsertedParticle& q : bed) {
        lower = lower.cwiseMin(q.position);
        upper = upper.cwiseMax(q.position);
    }
    const int axis = upper.x() - lower.x() >= upper.y() - lower.y() ? 0 : 1;
    std::vector<double> c;
    c.reserve(bed.size());
    for (const dem::InsertedParticle& q : bed) c.push_back(q.position[axis]);
    std::sort(c.begin(), c.end());
    std::vector<double> cuts;
    for (int r = 1; r < ranks; ++r) cuts.push_back(c[c.size() * static_cast<std::size_t>(r) / static_cast<std::size_t>(ranks)]);
    return dem::SlabDecomposition(ranks, axis, cuts);
}

// What one timed run of the domain decomposition gave (rank 0's copy).
struct RankTiming {
    double seconds = 0.0, kineticEnergy = 0.0;
    long builds = 0;
    std::int64_t ghosts = 0, recuts = 0, migrated = 0;
    // Over the timed steps: bytes all ranks sent, rank 0's and the largest
    // rank's seconds in collectives, collective calls per step (rank 0).
    std::int64_t bytes = 0;
    double commSecondsRank0 = 0.0, commSecondsMax = 0.0, callsPerStep = 0.0;
    // Sampled after every timed call of steps: ghosts / owned over all ranks,
    // and max/mean owned; means over the samples and the largest imbalance.
    double ghostFraction = 0.0, imbalanceMean = 0.0, imbalanceMax = 0.0, imbalanceEnd = 0.0;
};

// The timing protocol on one rank of the domain decomposition: the bed
// inserted on slabs cut at equal counts (the engine's load balance re-cuts them
// at list builds when max/mean owned exceeds 1.10), the case's water shared
// over the ranks, one untimed step, then `steps` steps timed by rank 0 in calls
// of `sample` steps, each ended by a reduction (the time of the slowest rank).
// The communicator's counters cover the timed calls only (the samples'
// reductions between them are left out).  Collective.
RankTiming timeOnRank(const dem::Communicator& comm, const dem::CaseSetup& setup,
                      const std::vector<dem::InsertedParticle>& bed, const dem::SlabDecomposition& slabs, long steps,
                      long sample) {
    const int material = setup.insertions.empty() ? 0 : setup.insertions.front().materialIndex;
    std::unique_ptr<dem::Simulation> sim = dem::makeSimulation(setup);
    auto exchange = std::make_shared<dem::GhostExchange>(comm, slabs);
    sim->setDecomposition(exchange);
    sim->insert(bed, material, dem::Vec3::Zero(), "bed");
    if (setup.waterContent > 0.0) sim->setWaterContent(setup.waterContent);  // shared over the ranks
    sim->step(1);
    auto ownedEnergy = [&] { return comm.sum(sim->particles().kineticEnergy(sim->ownedCount())); };
    const double e0 = ownedEnergy();
    if (comm.rank() == 0) std::cout << "sample 0 - " << std::setprecision(8) << e0 << std::endl;
    const long buildsBefore = sim->pairList().buildCount();
    const std::size_t recutsBefore = exchange->recutCount(), migratedBefore = exchange->migratedCount();
    comm.sum(0.0);  // start together
    RankTiming t;
    dem::CommunicationCounters timed;
    double ghostFractionSum = 0.0, imbalanceSum = 0.0;
    long samples = 0;
    for (long done = 0; done < steps;) {
        const long k = std::min(sample, steps - done);
        const dem::CommunicationCounters before = comm.counters();
        const auto t0 = Clock::now();
        sim->step(k);
        comm.sum(0.0);  // the slowest rank's time
        t.seconds += secondsSince(t0);
        const dem::CommunicationCounters after = comm.counters();
        timed.seconds += after.seconds - before.seconds;
        timed.exchangeCalls += after.exchangeCalls - before.exchangeCalls;
        timed.reductionCalls += after.reductionCalls - before.reductionCalls;
        timed.exchangeBytes += after.exchangeBytes - before.exchangeBytes;
        timed.reductionBytes += after.reductionBytes - before.reductionBytes;
        done += k;
        const double e = ownedEnergy();
        const double owned = static_cast<double>(sim->ownedCount());
        const double ownedSum = comm.sum(owned);
        const double ghostSum = comm.sum(static_cast<double>(sim->decomposition()->ghostCount()));
        const double imbalance = ownedSum > 0.0 ? comm.max(owned) / (ownedSum / comm.size()) : 0.0;
        ghostFractionSum += ownedSum > 0.0 ? ghostSum / ownedSum : 0.0;
        imbalanceSum += imbalance;
        t.imbalanceMax = std::max(t.imbalanceMax, imbalance);
        t.imbalanceEnd = imbalance;
        ++samples;
        if (comm.rank() == 0) std::cout << "sample " << done << " - " << e << std::endl;
    }
    t.kineticEnergy = ownedEnergy();
    t.ghosts = comm.sum(static_cast<std::int64_t>(sim->decomposition()->ghostCount()));
    t.bytes = comm.sum(timed.bytesSent());
    t.commSecondsRank0 = timed.seconds;
    t.commSecondsMax = comm.max(timed.seconds);
    t.callsPerStep = steps > 0 ? static_cast<double>(timed.calls()) / steps : 0.0;
    t.builds = sim->pairList().buildCount() - buildsBefore;
    t.recuts = static_cast<std::int64_t>(exchange->recutCount() - recutsBefore);
    t.migrated = comm.sum(static_cast<std::int64_t>(exchange->migratedCount() - migratedBefore));
    if (samples > 0) {
        t.ghostFraction = ghostFractionSum / samples;
        t.imbalanceMean = imbalanceSum / samples;
    }
    return t;
}

void printRankTiming(const RankTiming& t, int ranks, bool mpi, std::size_t n, long steps) {
    const double particleSteps = static_cast<double>(n) * steps;
    std::cout << std::setprecision(6) << "result threads " << ranks << "\n"
              << "result ranks " << ranks << "\n"
              << "result rank_kind " << (mpi ? "mpi" : "threads") << "\n"
              << "result particles " << n << "\n"
              << "result ghosts " << t.ghosts << "\n"
              << "result steps " << steps << "\n"
              << "result seconds " << t.seconds << "\n"
              << "result particle_steps_per_s " << particleSteps / t.seconds << "\n"
              << "result list_builds " << t.builds << "\n"
              << "result kinetic_energy_end " << t.kineticEnergy << "\n"
              << "result ghost_fraction " << t.ghostFraction << "\n"
              << "result bytes_per_particle_step " << (particleSteps > 0 ? t.bytes / particleSteps : 0.0) << "\n"
              << "result communication_seconds " << t.commSecondsRank0 << "\n"
              << "result communication_seconds_max " << t.commSecondsMax << "\n"
              << "result communication_share " << (t.seconds > 0 ? t.commSecondsRank0 / t.seconds : 0.0) << "\n"
              << "result collectives_per_step " << t.callsPerStep << "\n"
              << "result imbalance_mean " << t.imbalanceMean << "\n"
              << "result imbalance_max " << t.imbalanceMax << "\n"
              << "result imbalance_end " << t.imbalanceEnd << "\n"
              << "result recuts " << t.recuts << "\n"
              << "result migrated " << t.migrated << std::endl;
}

// timeSteps with -ranks R: the same protocol on R thread ranks of the domain
// decomposition (timeOnRank).
int timeStepsOnRanks(const Options& o, int ranks) {
    const dem::CaseSetup setup = dem::readCaseSetup(o.get("case"));
    const long steps = o.wholeNumber("steps", 1000, 0);
    const long sample = std::max(1L, o.wholeNumber("sample", 100, 0));
    const std::vector<dem::InsertedParticle> bed = readBed(o.get("bed"));
    const dem::SlabDecomposition slabs = equalCountSlabs(bed, ranks);
    RankTiming timing;
    dem::Communicator::runThreadGroup(ranks, [&](const dem::Communicator& comm) {
        const RankTiming t = timeOnRank(comm, setup, bed, slabs, steps, sample);
        if (comm.rank() == 0) timing = t;
    });
    printRankTiming(timing, ranks, false, bed.size(), steps);
    return 0;
}

// timeSteps with -parallel: the same protocol on the ranks of an MPI launcher
// (mpirun -np R demBench time ... -parallel), one rank per process; rank 0
// prints.
int timeStepsOnMpiRanks(const Options& o, const dem::Communicator& comm) {
    const dem::CaseSetup setup = dem::readCaseSetup(o.get("case"));
    const long steps = o.wholeNumber("steps", 1000, 0);
    const long sample = std::max(1L, o.wholeNumber("sample", 100, 0));
    const std::vector<dem::InsertedParticle> bed = readBed(o.get("bed"));
    const dem::SlabDecomposition slabs = equalCountSlabs(bed, comm.size());
    const RankTiming t = timeOnRank(comm, setup, bed, slabs, steps, sample);
    if (comm.rank() == 0) printRankTiming(t, comm.size(), true, bed.size(), steps);
    return 0;
}

int timeSteps(const Options& o, const dem::Communicator* mpi) {
    if (mpi) {
        if (o.has("ranks") || o.has("threads"))
            throw dem::InputError("demBench time -parallel: one thread per MPI rank; give neither -ranks nor -threads");
        return timeStepsOnMpiRanks(o, *mpi);
    }
    if (o.has("ranks")) {
        const int ranks = static_cast<int>(o.wholeNumber("ranks", 1, 1));
        if (o.has("threads")) throw dem::InputError("demBench time: give -threads or -ranks, not both");
        return timeStepsOnRanks(o, ranks);
    }
    const std::string caseDir = o.get("case");
    dem::CaseSetup setup = dem::readCaseSetup(caseDir);
    const int material = setup.insertions.empty() ? 0 : setup.insertions.front().materialIndex;
    const long steps = o.wholeNumber("steps", 1000, 0);
    const long sample = std::max(1L, o.wholeNumber("sample", 100, 0));

    const std::size_t rssBefore = procStatusBytes("VmRSS");
    std::unique_ptr<dem::Simulation> sim = dem::makeSimulation(setup);
    {
        const std::vector<dem::InsertedParticle> bed = readBed(o.get("bed"));
        sim->insert(bed, material, dem::Vec3::Zero(), "bed");
    }
    if (setup.waterContent > 0.0) sim->setWaterContent(setup.waterContent);
    const std::size_t n = sim->particles().size();

    sim->step(1);  // first pair list and forces: LIGGGHTS does this in its run setup
    std::cout << "sample 0 " << std::setprecision(8) << sim->coordinationNumber() << ' '
              << sim->particles().kineticEnergy() << std::endl;
    double coordinationSum = 0.0;
    int samples = 0;
    const long buildsBefore = sim->pairList().buildCount();
    const double seconds = timedSteps(*sim, steps, sample, [&](long done) {
        coordinationSum += sim->coordinationNumber();
        ++samples;
        std::cout << "sample " << done << ' ' << sim->coordinationNumber() << ' ' << sim->particles().kineticEnergy()
                  << std::endl;
    });
    const dem::ParticleStore& p = sim->particles();

    std::cout << std::setprecision(6);
#ifdef _OPENMP
    std::cout << "result threads " << omp_get_max_threads() << "\n";
#else
    std::cout << "result threads 1\n";
#endif
    std::cout << "result particles " << n << "\n"
              << "result steps " << steps << "\n"
              << "result seconds " << seconds << "\n"
              << "result particle_steps_per_s " << static_cast<double>(n) * steps / seconds << "\n"
              << "result list_builds " << sim->pairList().buildCount() - buildsBefore << "\n"
              << "result coordination_mean " << coordinationSum / samples << "\n"
              << "result coordination_end " << sim->coordinationNumber() << "\n"
              << "result kinetic_energy_end " << p.kineticEnergy() << "\n"
              << "result liquid_coordination " << sim->liquidCoordinationNumber() << "\n"
              << "result particle_bytes_per_particle " << p.bytesPerParticle() << "\n"
              << "result pair_list_entries_per_particle " << static_cast<double>(sim->pairList().pairCount()) / n
              << "\n"
              << "result pair_list_bytes_per_particle " << static_cast<double>(sim->pairList().bytes()) / n << "\n"
              << "result rss_growth_bytes_per_particle "
              << (static_cast<double>(procStatusBytes("VmRSS")) - static_cast<double>(rssBefore)) / n << "\n"
              << "result vmhwm_bytes " << procStatusBytes("VmHWM") << "\n"
              << "result state_hash " << std::hex << stateHash(p) << std::dec << std::endl;
    return 0;
}

void usage(std::ostream& out) {
    out << "Usage: demBench settle -case DIR -out PREFIX [-threads N] [-placement rsa|lattice|bed -bed FILE]\n"
           "                       [-packing PHI]\n"
           "                       [-gravityFactor G] [-settleTime T] [-relaxTime T] [-speedTolerance V]\n"
           "                       [-quietSamples Q]\n"
           "       demBench time -case DIR -bed FILE -steps K [-threads N | -ranks R] [-sample S]\n"
           "       mpirun -np R demBench time -case DIR -bed FILE -steps K [-sample S] -parallel\n"
           "       demBench copies -case DIR -bed FILE -steps K [-copies C]   (C independent 1-thread runs at once)\n"
           "Benchmark driver of bench/run; see docs/performance.md.\n";
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || std::string(argv[1]) == "-help" || std::string(argv[1]) == "--help") {
        usage(argc < 2 ? std::cerr : std::cout);
        return argc < 2 ? 1 : 0;
    }
    const std::string command = argv[1];
    Options o;
    bool parallel = false;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-parallel") {
            parallel = true;
            continue;
        }
        if (a.size() < 2 || a[0] != '-' || i + 1 >= argc) {
            std::cerr << "demBench: expected '-option value' pairs, got '" << a << "'\n";
            usage(std::cerr);
            return 1;
        }
        o.values[a.substr(1)] = argv[++i];
    }
    if (parallel && command != "time") {
        std::cerr << "demBench: -parallel is an option of 'time' only\n";
        return 1;
    }
    // -parallel: MPI starts here, as in demRun; each rank one thread.
    std::unique_ptr<dem::Communicator> mpi;
    if (parallel) {
#if DEMLIB_HAS_MPI
        int provided = 0;
        MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
        mpi = std::make_unique<dem::Communicator>(dem::communicatorFromMpi(MPI_COMM_WORLD));
#ifdef _OPENMP
        omp_set_num_threads(1);
#endif
#else
        std::cerr << "demBench: -parallel needs demLib built with MPI (this build has none)\n";
        return 1;
#endif
    }
    // Ends the run: MPI_Abort when a rank failed, since the others may wait
    // for it in a collective.
    auto leave = [&](int status) {
#if DEMLIB_HAS_MPI
        if (mpi) {
            if (status == 0) MPI_Finalize();
            else MPI_Abort(MPI_COMM_WORLD, status);
        }
#endif
        return status;
    };
    try {
#ifdef _OPENMP
        if (o.has("threads")) omp_set_num_threads(static_cast<int>(std::max(1L, o.wholeNumber("threads", 1, 0))));
#endif
        if (command == "settle") return settle(o);
        if (command == "time") return leave(timeSteps(o, mpi.get()));
        if (command == "copies") return independentCopies(o);
        std::cerr << "demBench: unknown command '" << command << "'; expected 'settle', 'time' or 'copies'\n";
        usage(std::cerr);
        return 1;
    } catch (const dem::InputError& e) {
        std::cerr << "demBench: input error: " << e.what() << std::endl;
        return leave(1);
    } catch (const std::exception& e) {
        std::cerr << "demBench: error: " << e.what() << std::endl;
        return leave(2);
    }
}
