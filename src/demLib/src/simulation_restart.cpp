// Restart files: the whole state of a Simulation, contact history included, so
// that a continued run is bitwise identical to an uninterrupted one (same
// thread count).  Written to a temporary name and renamed, so an interrupted
// write never corrupts the previous restart file.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <unordered_map>

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

void Simulation::writeRestart(const std::string& path) const {
    requireNoDecomposition("writeRestart");
    const std::string tmp = path + ".writing";
    {
        Hdf5File f(tmp, Hdf5File::Mode::Create);
        f.setAttribute("format", std::string(restartFormat));
        f.setAttribute("time", time_);
        f.setAttribute("step", static_cast<std::int64_t>(step_));
        f.setAttribute("timeStep", settings_.timeStep);
        f.setAttribute("nextId", static_cast<std::int64_t>(nextId_));
        f.setAttribute("lostCount", static_cast<std::int64_t>(lost_));
        f.setAttribute("lostMass", lostMass_);
        f.setAttribute("forcesValid", static_cast<std::int64_t>(forcesValid_));
        f.setAttribute("materialCount", static_cast<std::int64_t>(materials_.size()));
        f.setAttribute("wallCount", static_cast<std::int64_t>(walls_.size()));
        f.setAttribute("liquidTotal", liquid_.totalVolume);
        f.setAttribute("liquidPool", liquid_.poolVolume);
        f.setAttribute("waterContent", liquid_.waterContent);
        f.setAttribute("bridgeCount", static_cast<std::int64_t>(liquid_.bridgeCount));
        f.setAttribute("hasLiquid", static_cast<std::int64_t>(liquidNetwork_ != nullptr));
        f.setAttribute("largestBridge", largestBridge_);
        f.setAttribute("listBridgeListingLimit", pairs_.bridgeListingLimit());
        f.setAttribute("nextBridgeListingLimit", bridgeListingLimit_);
        f.setAttribute("wallBridgeCount", static_cast<std::int64_t>(liquid_.wallBridgeCount));
        f.setAttribute("wallBridgeReach", wallContacts_.bridgeReach());
        f.setAttribute("listSkin", pairs_.skin());
        f.setAttribute("listExtraRange", pairs_.extraRange());
        f.setAttribute("listBuildCount", static_cast<std::int64_t>(pairs_.buildCount()));
        f.sealAttributes();  // every dataset below carries its own checksum

        const ParticleStore& p = particles_;
        f.createGroup("particles");
        f.write("particles/id", p.id);
        f.write("particles/position", p.position);
        f.write("particles/velocity", p.velocity);
        f.write("particles/omega", p.omega);
        f.write("particles/force", p.force);
        f.write("particles/torque", p.torque);
        f.write("particles/externalForce", p.externalForce.toVector());
        f.write("particles/radius", p.radius);
        f.write("particles/mass", p.mass);
        f.write("particles/material", p.material);
        f.write("particles/positionAtListBuild", pairs_.positionsAtBuild());

        // Pair state by global ids, only where there is something to remember.
        std::vector<std::int64_t> ids;
        std::vector<Vec3> shear, rolling;
        std::vector<double> bridge;
        const auto& offsets = pairs_.offsets();
        const auto& neighbors = pairs_.neighbors();
        const PairStateView state = pairs_.state();
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
            for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
                const PairState s = state[k];
                if (s.bridgeVolume == 0.0 && s.contact.shear.isZero(0.0) && s.contact.rollingAngle.isZero(0.0))
                    continue;
                ids.push_back(p.id[i]);
                ids.push_back(p.id[neighbors[k]]);
                shear.push_back(s.contact.shear);
                rolling.push_back(s.contact.rollingAngle);
                bridge.push_back(s.bridgeVolume);
            }
        f.createGroup("pairs");
        f.write("pairs/ids", ids, 2);
        f.write("pairs/shear", shear);
        f.write("pairs/rollingAngle", rolling);
        f.write("pairs/bridgeVolume", bridge);

        std::vector<std::int64_t> wallKeys;
        std::vector<Vec3> wShear, wRolling, wForce;
        std::vector<double> wBridge;
        for (const WallContactRecord& r : wallContacts_.records()) {
            wallKeys.push_back(p.id[r.particle]);
            wallKeys.push_back(r.wall);
            wallKeys.push_back(r.feature);
            wShear.push_back(r.history.shear);
            wRolling.push_back(r.history.rollingAngle);
            wBridge.push_back(r.bridgeVolume);
            wForce.push_back(r.force);
        }
        f.createGroup("wallContacts");
        f.write("wallContacts/keys", wallKeys, 3);
        f.write("wallContacts/shear", wShear);
        f.write("wallContacts/rollingAngle", wRolling);
        f.write("wallContacts/bridgeVolume", wBridge);
        f.write("wallContacts/force", wForce);
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
        throw RuntimeError("cannot rename restart file '" + tmp + "' to '" + path + "'");
}

bool Simulation::readRestart(const std::string& path) {
    requireNoDecomposition("readRestart");
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
    if (f.intAttribute("materialCount") != static_cast<std::int64_t>(materials_.size()) ||
        f.intAttribute("wallCount") != static_cast<std::int64_t>(walls_.size()))
        throw InputError("restart file '" + path + "' was written for " +
                         std::to_string(f.intAttribute("materialCount")) + " materials and " +
                         std::to_string(f.intAttribute("wallCount")) + " walls; the case defines " +
                         std::to_string(materials_.size()) + " and " + std::to_string(walls_.size()));
    if (f.doubleAttribute("timeStep") != settings_.timeStep)
        throw InputError("restart file '" + path + "' was written with timeStep " +
                         std::to_string(f.doubleAttribute("timeStep")) + "; the case now says " +
                         std::to_string(settings_.timeStep) + " (continue with the same time step)");

    ParticleStore p;
    p.id = f.readInt64("particles/id");
    p.position = f.readVec3("particles/position");
    p.velocity = f.readVec3("particles/velocity");
    p.omega = f.readVec3("particles/omega");
    p.force = f.readVec3("particles/force");
    p.torque = f.readVec3("particles/torque");
    p.externalForce.assign(f.readVec3("particles/externalForce"));
    p.radius = f.readDoubles("particles/radius");
    p.mass = f.readDoubles("particles/mass");
    p.material = f.readInts("particles/material");
    const std::size_t n = p.id.size();
    if (p.position.size() != n || p.radius.size() != n || p.mass.size() != n || p.material.size() != n ||
        p.externalForce.size() != n)
        throw InputError("restart file '" + path + "': particle datasets have different lengths");
    for (std::size_t i = 0; i < n; ++i) {
        if (p.material[i] < 0 || p.material[i] >= static_cast<int>(materials_.size()))
            throw InputError("restart file '" + path + "': particle material index out of range");
    }
    particles_ = std::move(p);

    time_ = f.doubleAttribute("time");
    step_ = f.intAttribute("step");
    nextId_ = f.intAttribute("nextId");
    lost_ = f.intAttribute("lostCount");
    lostMass_ = f.doubleAttribute("lostMass");
    forcesValid_ = f.intAttribute("forcesValid") != 0;
    liquid_.totalVolume = f.doubleAttribute("liquidTotal");
    liquid_.poolVolume = f.doubleAttribute("liquidPool");
    liquid_.waterContent = f.doubleAttribute("waterContent");
    liquid_.bridgeCount = f.intAttribute("bridgeCount");
    largestBridge_ = f.doubleAttribute("largestBridge");
    // Written by every version that has wall bridges; files from before them
    // can only continue runs without the option.
    liquid_.wallBridgeCount = 0;
    wallContacts_.setBridgeReach(0.0);
    if (settings_.forces.wallBridges) {
        liquid_.wallBridgeCount = f.intAttribute("wallBridgeCount");
        wallContacts_.setBridgeReach(f.doubleAttribute("wallBridgeReach"));
    }
    liquidNetwork_.reset();
    if (f.intAttribute("hasLiquid")) {
        liquidNetwork_ = std::make_unique<LiquidBridgeNetwork>(liquid_.totalVolume, settings_.bridges);
        pairs_.setStateFields({pairs_.stateFields().rollingSpring, true});
    }

    std::unordered_map<std::int64_t, int> indexOf;
    indexOf.reserve(n);
    for (std::size_t i = 0; i < n; ++i) indexOf[particles_.id[i]] = static_cast<int>(i);
    auto lookup = [&](std::int64_t id) {
        const auto it = indexOf.find(id);
        if (it == indexOf.end())
            throw InputError("restart file '" + path + "': contact refers to unknown particle id " +
                             std::to_string(id));
        return it->second;
    };

    pairs_.setRanges(f.doubleAttribute("listSkin"), f.doubleAttribute("listExtraRange"));
    // Files from before the bridge listing limit: the whole range (the limit
    // only leaves out pairs without a bridge, so the run continues the same).
    constexpr double unlimited = std::numeric_limits<double>::infinity();
    pairs_.setBridgeListing(settings_.bridges, f.hasAttribute("listBridgeListingLimit")
                                                   ? f.doubleAttribute("listBridgeListingLimit") : unlimited);
    bridgeListingLimit_ = f.hasAttribute("nextBridgeListingLimit") ? f.doubleAttribute("nextBridgeListingLimit")
                                                                   : unlimited;
    pairs_.restore(particles_, f.readVec3("particles/positionAtListBuild"), f.intAttribute("listBuildCount"));
    const auto ids = f.readInt64("pairs/ids");
    const auto shear = f.readVec3("pairs/shear");
    const auto rolling = readRollingSprings(f, "pairs");
    const auto bridge = f.readDoubles("pairs/bridgeVolume");
    for (std::size_t k = 0; k < shear.size(); ++k) {
        PairState s;
        s.contact.shear = shear[k];
        s.contact.rollingAngle = rolling[k];
        s.bridgeVolume = bridge[k];
        if (!pairs_.setState(lookup(ids[2 * k]), lookup(ids[2 * k + 1]), s))
            throw InputError("restart file '" + path + "': saved pair (" + std::to_string(ids[2 * k]) + ", " +
                             std::to_string(ids[2 * k + 1]) + ") is not in the rebuilt neighbour list");
    }

    auto& records = wallContacts_.records();
    records.clear();
    const auto keys = f.readInt64("wallContacts/keys");
    const auto wShear = f.readVec3("wallContacts/shear");
    const auto wRolling = readRollingSprings(f, "wallContacts");
    const auto wBridge = f.readDoubles("wallContacts/bridgeVolume");
    // Files from before the wall forces were kept: zero until the next step.
    const auto wForce = f.exists("wallContacts/force") ? f.readVec3("wallContacts/force") : std::vector<Vec3>();
    for (std::size_t k = 0; k < wShear.size(); ++k) {
        WallContactRecord r;
        r.particle = lookup(keys[3 * k]);
        r.wall = static_cast<int>(keys[3 * k + 1]);
        r.feature = static_cast<int>(keys[3 * k + 2]);
        r.history.shear = wShear[k];
        r.history.rollingAngle = wRolling[k];
        r.bridgeVolume = wBridge[k];
        if (k < wForce.size()) r.force = wForce[k];
        // A run continued without wall bridges: their liquid waits in the pool.
        if (!settings_.forces.wallBridges) {
            liquid_.poolVolume += r.bridgeVolume;
            r.bridgeVolume = 0.0;
        }
        records.push_back(r);
    }
    std::sort(records.begin(), records.end());
    rebuildWallCandidates();
    // A case written before a limit was added (or tightened) is not continued beyond it.
    requireAllowedTimeStep("restart file '" + path + "'");
    return sealed && f.uncheckedDatasets() == 0;
}

}  // namespace dem
