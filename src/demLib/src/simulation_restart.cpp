// Restart files: the whole state of a Simulation, contact history included, so
// that a continued run is bitwise identical to an uninterrupted one (same
// thread count).  Written to a temporary name and renamed, so an interrupted
// write never corrupts the previous restart file.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include "demLib/byte_buffer.hpp"
#include "demLib/error.hpp"
#include "demLib/hdf5_file.hpp"
#include "demLib/simulation.hpp"

namespace dem {

namespace {
constexpr const char* restartFormat = "diefill-demLib-restart-1";

// The EPSD/EPSD2 rolling springs of group ("pairs" or "wallContacts"), kept as
// rolled angles [rad] in "<group>/rollingAngle".  Files written before the
// springs became angles hold "<group>/rollingTorque" instead (the spring as a
// torque [N m]); it is zero in every run without EPSD/EPSD2 (CDT, none), and
// such files continue as before.  A non-zero torque cannot be continued: its
// angle would need the stiffness the old build used, and the run would not
// continue as it would have with that build.
std::vector<Vec3> readRollingSprings(const Hdf5File& f, const std::string& group) {
    const std::string angle = group + "/rollingAngle";
    if (f.exists(angle)) return f.readVec3(angle);
    const std::string torque = group + "/rollingTorque";
    std::vector<Vec3> springs = f.readVec3(torque);
    for (const Vec3& m : springs)
        if (!m.isZero(0.0))
            throw InputError("restart file '" + f.path() + "' was written by a build that kept the EPSD/EPSD2 "
                             "rolling springs as torques (non-zero dataset '" + torque + "'); this build keeps "
                             "them as angles ('" + angle + "'): continue the run with the build that wrote the "
                             "file, or start it again");
    return springs;  // all zero: the same as zero angles
}
}

namespace {

// The datasets of a restart file, as written: one rank's part or the whole run.
struct RestartData {
    std::vector<std::int64_t> id;
    std::vector<Vec3> position, velocity, omega, force, torque, externalForce, positionAtBuild;
    std::vector<double> radius, mass;
    std::vector<int> material;
    // Pair state by global ids (two per pair), only where there is something to remember.
    std::vector<std::int64_t> pairIds;
    std::vector<Vec3> pairShear, pairRolling;
    std::vector<double> pairBridge;
    // Wall contact records: (particle id, wall, feature) keys.
    std::vector<std::int64_t> wallKeys;
    std::vector<Vec3> wallShear, wallRolling, wallForce;
    std::vector<double> wallBridge;
};

// Every field, in one order for packing and unpacking.
template <class F>
void forEachField(RestartData& d, F&& f) {
    f(d.id), f(d.position), f(d.velocity), f(d.omega), f(d.force), f(d.torque), f(d.externalForce);
    f(d.positionAtBuild), f(d.radius), f(d.mass), f(d.material);
    f(d.pairIds), f(d.pairShear), f(d.pairRolling), f(d.pairBridge);
    f(d.wallKeys), f(d.wallShear), f(d.wallRolling), f(d.wallForce), f(d.wallBridge);
}

void writeRestartDatasets(Hdf5File& f, const RestartData& d) {
    f.createGroup("particles");
    f.write("particles/id", d.id);
    f.write("particles/position", d.position);
    f.write("particles/velocity", d.velocity);
    f.write("particles/omega", d.omega);
    f.write("particles/force", d.force);
    f.write("particles/torque", d.torque);
    f.write("particles/externalForce", d.externalForce);
    f.write("particles/radius", d.radius);
    f.write("particles/mass", d.mass);
    f.write("particles/material", d.material);
    f.write("particles/positionAtListBuild", d.positionAtBuild);
    f.createGroup("pairs");
    f.write("pairs/ids", d.pairIds, 2);
    f.write("pairs/shear", d.pairShear);
    f.write("pairs/rollingAngle", d.pairRolling);
    f.write("pairs/bridgeVolume", d.pairBridge);
    f.createGroup("wallContacts");
    f.write("wallContacts/keys", d.wallKeys, 3);
    f.write("wallContacts/shear", d.wallShear);
    f.write("wallContacts/rollingAngle", d.wallRolling);
    f.write("wallContacts/bridgeVolume", d.wallBridge);
    f.write("wallContacts/force", d.wallForce);
}

// History vectors are defined for the first particle of a pair: seen from the
// other one they change sign.
PairState seenFromOther(PairState s) {
    s.contact.shear = -s.contact.shear;
    s.contact.rollingAngle = -s.contact.rollingAngle;
    return s;
}

// What `byId` maps a contact's particle id to (an index, a rank); an id the
// file's particles lack is an input error naming the file.
int contactParticle(const std::unordered_map<std::int64_t, int>& byId, std::int64_t id, const std::string& path) {
    const auto it = byId.find(id);
    if (it == byId.end())
        throw InputError("restart file '" + path + "': contact refers to unknown particle id " + std::to_string(id));
    return it->second;
}

}  // namespace

void Simulation::writeRestart(const std::string& path) const {
    // This rank's part: its owned particles, the pairs it accounts for (a
    // pair across a slab face once), the wall contacts of its particles.
    const std::size_t owned = ownedCount();
    const ParticleStore& p = particles_;
    RestartData d;
    d.id.assign(p.id.begin(), p.id.begin() + owned);
    d.position.assign(p.position.begin(), p.position.begin() + owned);
    d.velocity.assign(p.velocity.begin(), p.velocity.begin() + owned);
    d.omega.assign(p.omega.begin(), p.omega.begin() + owned);
    d.force.assign(p.force.begin(), p.force.begin() + owned);
    d.torque.assign(p.torque.begin(), p.torque.begin() + owned);
    d.externalForce = p.externalForce.toVector();
    d.externalForce.resize(owned);
    d.radius.assign(p.radius.begin(), p.radius.begin() + owned);
    d.mass.assign(p.mass.begin(), p.mass.begin() + owned);
    d.material.assign(p.material.begin(), p.material.begin() + owned);
    const std::vector<Vec3>& atBuild = pairs_.positionsAtBuild();
    if (decomposition_ && atBuild.size() < owned)
        d.positionAtBuild = d.position;  // forces invalid: the next step lists again anyway
    else if (decomposition_)
        d.positionAtBuild.assign(atBuild.begin(), atBuild.begin() + owned);
    else
        d.positionAtBuild = atBuild;
    const std::vector<std::uint8_t> counted = countedPairs();
    const auto& offsets = pairs_.offsets();
    const auto& neighbors = pairs_.neighbors();
    const PairStateView state = pairs_.state();
    for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
        for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
            const PairState s = state[k];
            if (!counted[k] ||
                (s.bridgeVolume == 0.0 && s.contact.shear.isZero(0.0) && s.contact.rollingAngle.isZero(0.0)))
                continue;
            d.pairIds.push_back(p.id[i]);
            d.pairIds.push_back(p.id[neighbors[k]]);
            d.pairShear.push_back(s.contact.shear);
            d.pairRolling.push_back(s.contact.rollingAngle);
            d.pairBridge.push_back(s.bridgeVolume);
        }
    for (const WallContactRecord& r : wallContacts_.records()) {
        if (static_cast<std::size_t>(r.particle) >= owned) continue;  // a ghost's: its owner writes it
        d.wallKeys.push_back(p.id[r.particle]);
        d.wallKeys.push_back(r.wall);
        d.wallKeys.push_back(r.feature);
        d.wallShear.push_back(r.history.shear);
        d.wallRolling.push_back(r.history.rollingAngle);
        d.wallBridge.push_back(r.bridgeVolume);
        d.wallForce.push_back(r.force);
    }

    // The run's values; with a decomposition rank 0 gathers the parts (in
    // rank order) and writes the one file, which any rank count can read.
    LiquidState liquid = liquid_;
    std::int64_t lost = static_cast<std::int64_t>(lost_);
    double lostMass = lostMass_;
    bool writer = true;
    if (decomposition_) {
        const Communicator& comm = decomposition_->communicator();
        liquid = liquidOverRanks();
        lost = comm.sum(lost);
        lostMass = comm.sum(lostMass);
        std::vector<std::vector<char>> send(comm.size());
        ByteWriter w{send[0]};
        forEachField(d, [&](const auto& v) { w.putVector(v); });
        const std::vector<std::vector<char>> received = comm.exchange(send);
        writer = comm.rank() == 0;
        if (writer) {
            RestartData all;
            for (const std::vector<char>& part : received) {
                ByteReader in{part};
                forEachField(all, [&](auto& v) { in.appendVector(v); });
                if (!in.done()) throw RuntimeError("restart gather: malformed message");
            }
            d = std::move(all);
        }
    }
    std::string failure;
    if (writer) {
        try {
            const std::string tmp = path + ".writing";
            {
                Hdf5File f(tmp, Hdf5File::Mode::Create);
                f.setAttribute("format", std::string(restartFormat));
                f.setAttribute("time", time_);
                f.setAttribute("step", static_cast<std::int64_t>(step_));
                f.setAttribute("timeStep", settings_.timeStep);
                f.setAttribute("nextId", static_cast<std::int64_t>(nextId_));
                f.setAttribute("lostCount", lost);
                f.setAttribute("lostMass", lostMass);
                f.setAttribute("forcesValid", static_cast<std::int64_t>(forcesValid_));
                f.setAttribute("materialCount", static_cast<std::int64_t>(materials_.size()));
                f.setAttribute("wallCount", static_cast<std::int64_t>(walls_.size()));
                f.setAttribute("liquidTotal", liquid.totalVolume);
                f.setAttribute("liquidPool", liquid.poolVolume);
                f.setAttribute("waterContent", liquid.waterContent);
                f.setAttribute("bridgeCount", static_cast<std::int64_t>(liquid.bridgeCount));
                f.setAttribute("hasLiquid", static_cast<std::int64_t>(liquidNetwork_ != nullptr));
                f.setAttribute("largestBridge", largestBridge_);
                f.setAttribute("listBridgeListingLimit", pairs_.bridgeListingLimit());
                f.setAttribute("nextBridgeListingLimit", bridgeListingLimit_);
                f.setAttribute("wallBridgeCount", static_cast<std::int64_t>(liquid.wallBridgeCount));
                f.setAttribute("wallBridgeReach", wallContacts_.bridgeReach());
                f.setAttribute("listSkin", pairs_.skin());
                f.setAttribute("listExtraRange", pairs_.extraRange());
                f.setAttribute("listBuildCount", static_cast<std::int64_t>(pairs_.buildCount()));
                if (decomposition_) {
                    // The slabs of the last list build: read on as many ranks,
                    // they give each rank its particles back in their order.
                    const SlabDecomposition& slabs = decomposition_->slabs();
                    f.setAttribute("decompositionRanks", static_cast<std::int64_t>(slabs.ranks()));
                    f.setAttribute("decompositionAxis", static_cast<std::int64_t>(slabs.axis()));
                }
                f.sealAttributes();  // every dataset below carries its own checksum
                writeRestartDatasets(f, d);
                if (std::any_of(walls_.begin(), walls_.end(), [](const Wall& w) { return w.motion.hasLoad(); })) {
                    // Where each wall under load is: its position follows the forces, not the clock.
                    std::vector<double> loads;
                    for (const Wall& w : walls_)
                        loads.insert(loads.end(), {w.motion.loadState().offset, w.motion.loadState().velocity});
                    f.createGroup("walls");
                    f.write("walls/loadState", loads);
                }
                if (decomposition_) {
                    f.createGroup("decomposition");
                    f.write("decomposition/cuts", decomposition_->slabs().interiorCuts());
                }
            }
            if (std::rename(tmp.c_str(), path.c_str()) != 0)
                throw RuntimeError("cannot rename restart file '" + tmp + "' to '" + path + "'");
        } catch (const std::exception& e) {
            if (!decomposition_) throw;
            failure = e.what();
        }
    }
    // Every rank learns whether the file was written.
    if (decomposition_ && decomposition_->communicator().anyTrue(!failure.empty()))
        throw RuntimeError(!failure.empty() ? failure : "restart file '" + path + "' was not written (rank 0 failed)");
}

namespace {

// A restart file read and checked, before any of it is applied.
struct LoadedRestart {
    RestartData data;
    bool checked = false;  // sealed, and every dataset had its checksum
    double time = 0.0, lostMass = 0.0, liquidTotal = 0.0, liquidPool = 0.0, waterContent = 0.0;
    double largestBridge = 0.0, wallBridgeReach = 0.0, listSkin = 0.0, listExtraRange = 0.0;
    double listBridgeListingLimit = std::numeric_limits<double>::infinity();
    double nextBridgeListingLimit = std::numeric_limits<double>::infinity();
    std::int64_t step = 0, nextId = 0, lostCount = 0, forcesValid = 0, bridgeCount = 0, hasLiquid = 0;
    std::int64_t wallBridgeCount = 0, listBuildCount = 0, decompositionRanks = 0, decompositionAxis = 0;
    std::vector<double> wallLoads;  // per wall: offset, velocity (WallLoadState); empty in files without loads
    std::vector<double> cuts;

    // The scalars as one message (integers below 2^53 pass exactly as doubles).
    std::vector<double> header() const {
        std::vector<double> h{static_cast<double>(checked), time, lostMass, liquidTotal, liquidPool, waterContent,
                              largestBridge, wallBridgeReach, listSkin, listExtraRange, listBridgeListingLimit,
                              nextBridgeListingLimit, static_cast<double>(step), static_cast<double>(nextId),
                              static_cast<double>(lostCount), static_cast<double>(forcesValid),
                              static_cast<double>(bridgeCount), static_cast<double>(hasLiquid),
                              static_cast<double>(wallBridgeCount), static_cast<double>(listBuildCount),
                              static_cast<double>(decompositionRanks), static_cast<double>(decompositionAxis),
                              static_cast<double>(wallLoads.size())};
        h.insert(h.end(), wallLoads.begin(), wallLoads.end());
        h.insert(h.end(), cuts.begin(), cuts.end());
        return h;
    }
    void setHeader(const std::vector<double>& h) {
        constexpr std::size_t fixed = 23;
        if (h.size() < fixed || h.size() < fixed + static_cast<std::size_t>(h[fixed - 1]))
            throw RuntimeError("restart: malformed header message");
        std::size_t k = 0;
        checked = h[k++] != 0.0;
        for (double* v : {&time, &lostMass, &liquidTotal, &liquidPool, &waterContent, &largestBridge,
                          &wallBridgeReach, &listSkin, &listExtraRange, &listBridgeListingLimit,
                          &nextBridgeListingLimit})
            *v = h[k++];
        for (std::int64_t* v : {&step, &nextId, &lostCount, &forcesValid, &bridgeCount, &hasLiquid,
                                &wallBridgeCount, &listBuildCount, &decompositionRanks, &decompositionAxis})
            *v = static_cast<std::int64_t>(h[k++]);
        const std::size_t loads = static_cast<std::size_t>(h[k++]);
        wallLoads.assign(h.begin() + fixed, h.begin() + fixed + loads);
        cuts.assign(h.begin() + fixed + loads, h.end());
    }
};

LoadedRestart loadRestart(const std::string& path, std::size_t materialCount, std::size_t wallCount,
                          double timeStep, bool wallBridges) {
    Hdf5File f(path, Hdf5File::Mode::Read);
    // A damaged file is refused before any of it is believed (its format, its counts).
    const bool sealed = f.checkAttributes();
    if (!f.hasAttribute("format"))
        throw InputError("'" + path + "' is not a restart file (an HDF5 file without the attribute 'format'" +
                         (f.hasAttribute("step") ? ": a particle output file?" : "") +
                         "); expected a file of <output>/restart/, e.g. restart_000002000.h5, or 'latest'");
    const std::string format = f.stringAttribute("format");
    if (format != restartFormat)
        throw InputError("restart file '" + path + "': format '" + format + "', expected '" + restartFormat + "'");
    if (f.intAttribute("materialCount") != static_cast<std::int64_t>(materialCount) ||
        f.intAttribute("wallCount") != static_cast<std::int64_t>(wallCount))
        throw InputError("restart file '" + path + "' was written for " +
                         std::to_string(f.intAttribute("materialCount")) + " materials and " +
                         std::to_string(f.intAttribute("wallCount")) + " walls; the case defines " +
                         std::to_string(materialCount) + " and " + std::to_string(wallCount));
    if (f.doubleAttribute("timeStep") != timeStep)
        throw InputError("restart file '" + path + "' was written with timeStep " +
                         std::to_string(f.doubleAttribute("timeStep")) + "; the case now says " +
                         std::to_string(timeStep) + " (continue with the same time step)");

    LoadedRestart r;
    RestartData& d = r.data;
    d.id = f.readInt64("particles/id");
    d.position = f.readVec3("particles/position");
    d.velocity = f.readVec3("particles/velocity");
    d.omega = f.readVec3("particles/omega");
    d.force = f.readVec3("particles/force");
    d.torque = f.readVec3("particles/torque");
    d.externalForce = f.readVec3("particles/externalForce");
    d.radius = f.readDoubles("particles/radius");
    d.mass = f.readDoubles("particles/mass");
    d.material = f.readInts("particles/material");
    d.positionAtBuild = f.readVec3("particles/positionAtListBuild");
    const std::size_t n = d.id.size();
    if (d.position.size() != n || d.radius.size() != n || d.mass.size() != n || d.material.size() != n ||
        d.externalForce.size() != n)
        throw InputError("restart file '" + path + "': particle datasets have different lengths");
    for (std::size_t i = 0; i < n; ++i) {
        if (d.material[i] < 0 || d.material[i] >= static_cast<int>(materialCount))
            throw InputError("restart file '" + path + "': particle material index out of range");
    }
    r.time = f.doubleAttribute("time");
    r.step = f.intAttribute("step");
    r.nextId = f.intAttribute("nextId");
    r.lostCount = f.intAttribute("lostCount");
    r.lostMass = f.doubleAttribute("lostMass");
    r.forcesValid = f.intAttribute("forcesValid");
    r.liquidTotal = f.doubleAttribute("liquidTotal");
    r.liquidPool = f.doubleAttribute("liquidPool");
    r.waterContent = f.doubleAttribute("waterContent");
    r.bridgeCount = f.intAttribute("bridgeCount");
    r.largestBridge = f.doubleAttribute("largestBridge");
    r.hasLiquid = f.intAttribute("hasLiquid");
    // Written by every version that has wall bridges; files from before them
    // can only continue runs without the option.
    if (wallBridges) {
        r.wallBridgeCount = f.intAttribute("wallBridgeCount");
        r.wallBridgeReach = f.doubleAttribute("wallBridgeReach");
    }
    r.listSkin = f.doubleAttribute("listSkin");
    r.listExtraRange = f.doubleAttribute("listExtraRange");
    r.listBuildCount = f.intAttribute("listBuildCount");
    // Files from before the bridge listing limit: the whole range (the limit
    // only leaves out pairs without a bridge, so the run continues the same).
    if (f.hasAttribute("listBridgeListingLimit")) r.listBridgeListingLimit = f.doubleAttribute("listBridgeListingLimit");
    if (f.hasAttribute("nextBridgeListingLimit")) r.nextBridgeListingLimit = f.doubleAttribute("nextBridgeListingLimit");
    if (f.hasAttribute("decompositionRanks")) {
        r.decompositionRanks = f.intAttribute("decompositionRanks");
        r.decompositionAxis = f.intAttribute("decompositionAxis");
        if (r.decompositionRanks > 1) r.cuts = f.readDoubles("decomposition/cuts");
    }
    if (f.exists("walls/loadState")) {
        r.wallLoads = f.readDoubles("walls/loadState");
        if (r.wallLoads.size() != 2 * wallCount)
            throw InputError("restart file '" + path + "': walls/loadState has " + std::to_string(r.wallLoads.size()) +
                             " values; expected 2 per wall (" + std::to_string(2 * wallCount) + ")");
    }
    d.pairIds = f.readInt64("pairs/ids");
    d.pairShear = f.readVec3("pairs/shear");
    d.pairRolling = readRollingSprings(f, "pairs");
    d.pairBridge = f.readDoubles("pairs/bridgeVolume");
    d.wallKeys = f.readInt64("wallContacts/keys");
    d.wallShear = f.readVec3("wallContacts/shear");
    d.wallRolling = readRollingSprings(f, "wallContacts");
    d.wallBridge = f.readDoubles("wallContacts/bridgeVolume");
    // Files from before the wall forces were kept: zero until the next step.
    if (f.exists("wallContacts/force")) d.wallForce = f.readVec3("wallContacts/force");
    d.wallForce.resize(d.wallShear.size(), Vec3::Zero());
    if (d.pairIds.size() != 2 * d.pairShear.size() || d.pairRolling.size() != d.pairShear.size() ||
        d.pairBridge.size() != d.pairShear.size() || d.wallKeys.size() != 3 * d.wallShear.size() ||
        d.wallRolling.size() != d.wallShear.size() || d.wallBridge.size() != d.wallShear.size())
        throw InputError("restart file '" + path + "': contact datasets have different lengths");
    r.checked = sealed && f.uncheckedDatasets() == 0;
    return r;
}

}  // namespace

namespace {

// The wall contact records of the particles `lookup` finds (index, or -1 for
// another rank's); without wall bridges their liquid goes to `pool`.
template <class Lookup>
void restoreWallRecords(const RestartData& d, const Lookup& lookup, bool wallBridges, ParticleWallContacts& walls,
                        double& pool) {
    auto& records = walls.records();
    records.clear();
    for (std::size_t k = 0; k < d.wallShear.size(); ++k) {
        WallContactRecord r;
        r.particle = lookup(d.wallKeys[3 * k]);
        if (r.particle < 0) continue;  // another rank's particle
        r.wall = static_cast<int>(d.wallKeys[3 * k + 1]);
        r.feature = static_cast<int>(d.wallKeys[3 * k + 2]);
        r.history.shear = d.wallShear[k];
        r.history.rollingAngle = d.wallRolling[k];
        r.bridgeVolume = d.wallBridge[k];
        r.force = d.wallForce[k];
        // A run continued without wall bridges: their liquid waits in the pool.
        if (!wallBridges) {
            pool += r.bridgeVolume;
            r.bridgeVolume = 0.0;
        }
        records.push_back(r);
    }
    std::sort(records.begin(), records.end());
}

}  // namespace

bool Simulation::readRestart(const std::string& path) {
    if (decomposition_) return readRestartDecomposed(path);
    LoadedRestart loaded = loadRestart(path, materials_.size(), walls_.size(), settings_.timeStep,
                                       settings_.forces.wallBridges);
    RestartData& d = loaded.data;
    const std::size_t n = d.id.size();
    ParticleStore p;
    p.id = std::move(d.id);
    p.position = std::move(d.position);
    p.velocity = std::move(d.velocity);
    p.omega = std::move(d.omega);
    p.force = std::move(d.force);
    p.torque = std::move(d.torque);
    p.externalForce.assign(std::move(d.externalForce));
    p.radius = std::move(d.radius);
    p.mass = std::move(d.mass);
    p.material = std::move(d.material);
    particles_ = std::move(p);
    applyRestartScalars(loaded.header());

    std::unordered_map<std::int64_t, int> indexOf;
    indexOf.reserve(n);
    for (std::size_t i = 0; i < n; ++i) indexOf[particles_.id[i]] = static_cast<int>(i);
    auto lookup = [&](std::int64_t id) { return contactParticle(indexOf, id, path); };

    pairs_.restore(particles_, d.positionAtBuild, loaded.listBuildCount);
    for (std::size_t k = 0; k < d.pairShear.size(); ++k) {
        PairState s;
        s.contact.shear = d.pairShear[k];
        s.contact.rollingAngle = d.pairRolling[k];
        s.bridgeVolume = d.pairBridge[k];
        int a = lookup(d.pairIds[2 * k]), b = lookup(d.pairIds[2 * k + 1]);
        // A file gathered from MPI ranks keeps the ranks' orientation of a pair.
        if (a > b) {
            std::swap(a, b);
            s = seenFromOther(s);
        }
        if (!pairs_.setState(a, b, s))
            throw InputError("restart file '" + path + "': saved pair (" + std::to_string(d.pairIds[2 * k]) + ", " +
                             std::to_string(d.pairIds[2 * k + 1]) + ") is not in the rebuilt neighbour list");
    }
    restoreWallRecords(d, [&](std::int64_t id) { return lookup(id); }, settings_.forces.wallBridges, wallContacts_,
                       liquid_.poolVolume);
    rebuildWallCandidates();
    // A case written before a limit was added (or tightened) is not continued beyond it.
    requireAllowedTimeStep("restart file '" + path + "'");
    return loaded.checked;
}

void Simulation::applyRestartScalars(const std::vector<double>& header) {
    LoadedRestart r;
    r.setHeader(header);
    time_ = r.time;
    step_ = r.step;
    nextId_ = r.nextId;
    lost_ = static_cast<std::size_t>(r.lostCount);
    lostMass_ = r.lostMass;
    forcesValid_ = r.forcesValid != 0;
    liquid_.totalVolume = r.liquidTotal;
    liquid_.poolVolume = r.liquidPool;
    liquid_.waterContent = r.waterContent;
    liquid_.bridgeCount = static_cast<std::size_t>(r.bridgeCount);
    largestBridge_ = r.largestBridge;
    liquid_.wallBridgeCount = static_cast<std::size_t>(r.wallBridgeCount);
    wallContacts_.setBridgeReach(r.wallBridgeReach);
    liquidNetwork_.reset();
    if (r.hasLiquid) {
        liquidNetwork_ = std::make_unique<LiquidBridgeNetwork>(liquid_.totalVolume, settings_.bridges);
        pairs_.setStateFields({pairs_.stateFields().rollingSpring, true});
    }
    pairs_.setRanges(r.listSkin, r.listExtraRange);
    pairs_.setBridgeListing(settings_.bridges, r.listBridgeListingLimit);
    bridgeListingLimit_ = r.nextBridgeListingLimit;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        WallMotion& motion = walls_[w].motion;
        if (!motion.hasLoad()) continue;
        if (r.wallLoads.empty()) {
            // A file without the walls' loads: only a run that had not reached them continues.
            if (time_ > motion.load().tStart)
                throw InputError(settings_.source + ": wall '" + walls_[w].name + "' is under load from t = " +
                                 std::to_string(motion.load().tStart) + " s, and the restart file (t = " +
                                 std::to_string(time_) + " s) does not say where it is; expected a restart file "
                                 "written with this wall's load, or one from before it");
            motion.setLoadState({});
            continue;
        }
        motion.setLoadState({r.wallLoads[2 * w], r.wallLoads[2 * w + 1]});
    }
}


bool Simulation::readRestartDecomposed(const std::string& path) {
    const Communicator& comm = decomposition_->communicator();
    if (!particles_.empty() || nextId_ != 0)
        throw InputError(settings_.source + ": with a domain decomposition a restart file is read into a "
                                            "simulation without particles (read it before any insertion)");
    const int ranks = comm.size();
    // Rank 0 reads and checks the file and sends each rank its particles
    // (owner: the slab holding the position at the last list build), the pair
    // records of its particles and their wall contacts.
    std::vector<std::vector<char>> send(ranks);
    std::string failure;
    bool failedAsInput = false;
    auto onRankZero = [&](auto&& work) {
        if (comm.rank() != 0) return;
        try {
            work();
        } catch (const InputError& e) {
            failure = e.what();
            failedAsInput = true;
        } catch (const std::exception& e) {
            failure = e.what();
        }
    };
    auto stopIfFailed = [&]() {
        if (!comm.anyTrue(!failure.empty())) return;
        if (comm.rank() != 0) throw InputError("restart file '" + path + "' could not be read (see rank 0)");
        if (failedAsInput) throw InputError(failure);
        throw RuntimeError(failure);
    };
    std::optional<LoadedRestart> loaded;
    onRankZero([&]() {
        loaded.emplace(loadRestart(path, materials_.size(), walls_.size(), settings_.timeStep,
                                   settings_.forces.wallBridges));
    });
    stopIfFailed();
    // Written on as many ranks, cut across the same axis: its slabs give every
    // particle back to its rank, in its order (a bitwise continuation).
    // Otherwise the slabs are cut here by particle count over the file's
    // particles (when the load balance is on): a run continued on another rank
    // count must not leave the powder on the ranks the set-up slabs give it
    // until the next list build, which a bed at rest may not reach for seconds.
    const int axis = decomposition_->slabs().axis();
    const bool keepFileCuts = comm.anyTrue(comm.rank() == 0 && ranks > 1 &&
                                           loaded->decompositionRanks == ranks &&
                                           loaded->decompositionAxis == axis);
    const bool recut =
        !keepFileCuts &&
        decomposition_->balanceUndistributed(comm.rank() == 0 ? loaded->data.positionAtBuild : std::vector<Vec3>())
            .recut;
    onRankZero([&]() {
        const RestartData& d = loaded->data;
        const SlabDecomposition slabs = keepFileCuts
                                            ? SlabDecomposition(ranks, axis, loaded->cuts)
                                            : decomposition_->slabs();
        loaded->cuts = slabs.interiorCuts();
        loaded->decompositionAxis = slabs.axis();
        loaded->decompositionRanks = ranks;
        const std::size_t n = d.id.size();
        std::vector<RestartData> part(ranks);
        std::unordered_map<std::int64_t, int> ownerOf;
        ownerOf.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            const int r = slabs.ownerOf(d.positionAtBuild[i], 0);
            ownerOf[d.id[i]] = r;
            RestartData& q = part[r];
            q.id.push_back(d.id[i]);
            q.position.push_back(d.position[i]);
            q.velocity.push_back(d.velocity[i]);
            q.omega.push_back(d.omega[i]);
            q.force.push_back(d.force[i]);
            q.torque.push_back(d.torque[i]);
            q.externalForce.push_back(d.externalForce[i]);
            q.positionAtBuild.push_back(d.positionAtBuild[i]);
            q.radius.push_back(d.radius[i]);
            q.mass.push_back(d.mass[i]);
            q.material.push_back(d.material[i]);
        }
        auto owner = [&](std::int64_t id) { return contactParticle(ownerOf, id, path); };
        for (std::size_t k = 0; k < d.pairShear.size(); ++k) {
            const int a = owner(d.pairIds[2 * k]), b = owner(d.pairIds[2 * k + 1]);
            // To both ranks that list the pair (once when they are one).
            for (int r : {a, b}) {
                RestartData& q = part[r];
                q.pairIds.push_back(d.pairIds[2 * k]);
                q.pairIds.push_back(d.pairIds[2 * k + 1]);
                q.pairShear.push_back(d.pairShear[k]);
                q.pairRolling.push_back(d.pairRolling[k]);
                q.pairBridge.push_back(d.pairBridge[k]);
                if (a == b) break;
            }
        }
        for (std::size_t k = 0; k < d.wallShear.size(); ++k) {
            RestartData& q = part[owner(d.wallKeys[3 * k])];
            for (int c = 0; c < 3; ++c) q.wallKeys.push_back(d.wallKeys[3 * k + c]);
            q.wallShear.push_back(d.wallShear[k]);
            q.wallRolling.push_back(d.wallRolling[k]);
            q.wallBridge.push_back(d.wallBridge[k]);
            q.wallForce.push_back(d.wallForce[k]);
        }
        const std::vector<double> header = loaded->header();
        for (int r = 0; r < ranks; ++r) {
            ByteWriter w{send[r]};
            w.putVector(header);
            forEachField(part[r], [&](const auto& v) { w.putVector(v); });
        }
    });
    stopIfFailed();
    const std::vector<std::vector<char>> received = comm.exchange(send);
    std::vector<double> header;
    RestartData d;
    {
        ByteReader in{received[0]};
        in.appendVector(header);
        forEachField(d, [&](auto& v) { in.appendVector(v); });
        if (!in.done()) throw RuntimeError("restart: malformed message from rank 0");
    }
    LoadedRestart scalars;
    scalars.setHeader(header);
    if (ranks > 1)
        decomposition_->setSlabs(SlabDecomposition(ranks, static_cast<int>(scalars.decompositionAxis), scalars.cuts));

    ParticleStore p;
    p.id = d.id;
    p.position = d.positionAtBuild;  // the list is rebuilt where it was built (below)
    p.velocity = d.velocity;
    p.omega = d.omega;
    p.force = d.force;
    p.torque = d.torque;
    p.externalForce.assign(d.externalForce);
    p.radius = d.radius;
    p.mass = d.mass;
    p.material = d.material;
    particles_ = std::move(p);
    applyRestartScalars(header);
    // Lost particles and their mass are counted once: on rank 0.
    if (comm.rank() != 0) {
        lost_ = 0;
        lostMass_ = 0.0;
    }
    const std::size_t owned = particles_.size();
    if (recut) decomposition_->noteBalanceAfterMigration(particles_);

    // The ghosts and the list as at the last build: ghosts chosen at the
    // build positions over the same halo, the list built from them; then the
    // owned particles move to where they are now and the ghosts follow.
    double rMax = 0.0;
    for (double r : particles_.radius) rMax = std::max(rMax, r);
    rMax = comm.max(rMax);
    decomposition_->appendGhosts(particles_, rMax + pairs_.skin() + pairs_.extraRange());
    pairs_.restore(particles_, particles_.position, scalars.listBuildCount, owned);
    std::copy(d.position.begin(), d.position.end(), particles_.position.begin());
    decomposition_->updateGhosts(particles_);

    std::unordered_map<std::int64_t, int> indexOf;
    indexOf.reserve(particles_.size());
    for (std::size_t i = 0; i < particles_.size(); ++i) indexOf.emplace(particles_.id[i], static_cast<int>(i));
    // Pair states by (smaller id, larger id), seen from the smaller.
    std::unordered_map<std::int64_t, std::vector<std::pair<std::int64_t, PairState>>> stateOf;
    for (std::size_t k = 0; k < d.pairShear.size(); ++k) {
        PairState s;
        s.contact.shear = d.pairShear[k];
        s.contact.rollingAngle = d.pairRolling[k];
        s.bridgeVolume = d.pairBridge[k];
        std::int64_t a = d.pairIds[2 * k], b = d.pairIds[2 * k + 1];
        if (a > b) {
            std::swap(a, b);
            s = seenFromOther(s);
        }
        stateOf[a].emplace_back(b, s);
    }
    std::size_t restored = 0, expected = 0;
    {
        const auto& offsets = pairs_.offsets();
        const auto& neighbors = pairs_.neighbors();
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
            for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
                const std::int64_t a = particles_.id[i], b = particles_.id[neighbors[k]];
                const auto it = stateOf.find(std::min(a, b));
                if (it == stateOf.end()) continue;
                for (const auto& [other, s] : it->second)
                    if (other == std::max(a, b)) {
                        pairs_.setStateAt(static_cast<std::size_t>(k), a < b ? s : seenFromOther(s));
                        ++restored;
                        break;
                    }
            }
        // Every record sent here belongs to a listed pair of an owned particle.
        for (const auto& [first, list] : stateOf) expected += list.size();
    }
    const std::size_t ownedIds = owned;
    auto ownedIndex = [&](std::int64_t id) {
        const auto it = indexOf.find(id);
        return it != indexOf.end() && static_cast<std::size_t>(it->second) < ownedIds ? it->second : -1;
    };
    restoreWallRecords(d, ownedIndex, settings_.forces.wallBridges, wallContacts_, liquid_.poolVolume);
    const bool allPairsFound = !comm.anyTrue(restored != expected);
    if (!allPairsFound)
        throw InputError("restart file '" + path + "': saved pairs are not in the rebuilt neighbour list");
    rebuildWallCandidates();
    requireAllowedTimeStep("restart file '" + path + "'");
    return scalars.checked;
}

}  // namespace dem
