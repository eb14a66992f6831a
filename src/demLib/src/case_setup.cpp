#include "demLib/case_setup.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "demLib/constants.hpp"
#include "demLib/error.hpp"
#include "demLib/triangle_mesh.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

std::string resolve(const std::string& caseDir, const std::string& file) {
    const fs::path p(file);
    return p.is_absolute() ? file : (fs::path(caseDir) / p).string();
}

// MemAvailable of /proc/meminfo in bytes; 0 where it cannot be read (not Linux).
double availableMemoryBytes() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    double kilobytes = 0.0;
    std::string unit;
    while (in >> key >> kilobytes >> unit)
        if (key == "MemAvailable:") return kilobytes * 1024.0;
    return 0.0;
}

[[noreturn]] void invalid(const Dictionary& d, const std::string& key, const std::string& expected) {
    throw InputError(d.describe(key) + ": " + expected);
}

// The results stay in the case folder, apart from its inputs: a directory '..', an
// absolute one, or one in constant/ or system/ (also through a link) would put particle
// files beside the case or among its inputs.
void requireOutputInsideCase(const Dictionary& o, const std::string& caseDir, const std::string& directory) {
    const fs::path given = fs::path(directory).lexically_normal();
    const std::string expected = "; expected a folder inside the case for the results, outside constant/ and system/, "
                                 "e.g. 'dem'";
    if (given.is_absolute()) invalid(o, "directory", "'" + directory + "' is an absolute path" + expected);
    const std::string first = given.begin() == given.end() ? std::string() : given.begin()->string();
    if (first == "..") invalid(o, "directory", "'" + directory + "' leaves the case folder" + expected);
    if (first == "constant" || first == "system")
        invalid(o, "directory", "'" + directory + "' lies in " + first + "/, among the case's inputs" + expected);
    std::error_code error;
    const fs::path caseReal = fs::weakly_canonical(fs::absolute(caseDir), error);
    const fs::path outReal = fs::weakly_canonical(fs::absolute(fs::path(caseDir) / given), error);
    if (error) return;
    auto within = [](const fs::path& path, const fs::path& folder) {
        const fs::path relative = path.lexically_relative(folder);
        return !relative.empty() && *relative.begin() != "..";
    };
    if (!within(outReal, caseReal) || outReal == caseReal)
        invalid(o, "directory", "'" + directory + "' leads (through a link) to '" + outReal.string() +
                                    "', outside the case folder" + expected);
    for (const char* inputs : {"constant", "system"})
        if (within(outReal, fs::weakly_canonical(caseReal / inputs, error)))
            invalid(o, "directory", "'" + directory + "' leads (through a link) into " + inputs + "/" + expected);
}

constexpr double maxYoungsModulus = 1e13;  // [Pa]
constexpr double maxRunSteps = 1e12;       // as CaseRunner::maxRunSteps
// Far beyond any solid (osmium: 22 590 kg/m^3), still room for tests that pin particles
// with a huge density (tests/diefillFoam/packedBed: 1e9).
constexpr double maxDensity = 1e12;  // [kg/m^3]

// Magnitudes whose consequences are absurd (a mass or weight that is not finite, a
// particle moved more than half its radius in one step by gravity or its insertion
// speed): the run would lose every particle and end as if it had succeeded.
void checkMagnitudes(const Dictionary& root, const Dictionary& d, const InsertionSpec& spec, const CaseSetup& setup,
                     double smallestRadius, double heaviestMass) {
    const SimulationSettings& s = setup.settings;
    const Material& material = setup.materials[spec.materialIndex];
    const Dictionary& materialDict = root.subDict("materials").subDict(material.name);
    const Dictionary& simulation = root.subDict("simulation");
    const double dt = s.timeStep;
    const double g = s.gravity.stableNorm();  // stableNorm: no overflow of the squares
    const double speed = spec.request.initialVelocity.stableNorm();
    std::ostringstream m;
    m << std::setprecision(3);
    if (!std::isfinite(heaviestMass)) {
        m << "the heaviest particle of '" << spec.name << "' would have a mass that is not a finite number; "
          << "expected the density of a solid in kg/m^3, got " << material.density;
        invalid(materialDict, "density", m.str());
    }
    if (!(0.5 * g * dt * dt <= 0.5 * smallestRadius)) {
        m << "|gravity| = " << g << " m/s^2 moves a particle at rest " << 0.5 * g * dt * dt << " m in one step of "
          << dt << " s, more than half the smallest radius of '" << spec.name << "' (" << smallestRadius
          << " m); expected a gravity in m/s^2, e.g. (0 0 -9.81)";
        invalid(simulation, "gravity", m.str());
    }
    if (!std::isfinite(heaviestMass * g)) {
        m << "the weight of the heaviest particle of '" << spec.name << "' (" << heaviestMass << " kg times "
          << g << " m/s^2) is not a finite number; expected the density of a solid in kg/m^3, got " << material.density;
        invalid(materialDict, "density", m.str());
    }
    if (!(speed * dt <= 0.5 * smallestRadius) || !std::isfinite(heaviestMass * speed * speed)) {
        m << "at " << speed << " m/s a particle moves " << speed * dt << " m in one step of " << dt
          << " s, more than half the smallest radius (" << smallestRadius
          << " m): its contacts would be missed; expected a speed in m/s below " << 0.5 * smallestRadius / dt;
        invalid(d, "velocity", m.str());
    }
}

// Wall and region names become column names of summary.csv (wallForce_<wall>_x,
// mass_<region>): a comma or a quote in one would shift every column after it.
void requireColumnName(const Dictionary& d, const std::string& name, const std::string& what) {
    const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
    });
    if (!plain)
        invalid(d, name, "a " + what + " name may hold letters, digits, '_', '-' and '.' only (it names columns of "
                         "summary.csv); expected e.g. 'dieBase'");
}

// Materials are referred to by name; the message lists the defined ones.
int materialByName(const Dictionary& d, const std::string& key, const std::vector<Material>& materials) {
    std::vector<std::string> names;
    for (const Material& m : materials) names.push_back(m.name);
    const std::string name = d.getChoice(key, names);
    return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
}

Vec3 unitVector(const Dictionary& d, const std::string& key) {
    const Vec3 v = d.get<Vec3>(key);
    if (!(v.norm() > 0.0)) invalid(d, key, "expected a non-zero direction vector");
    return v.normalized();
}

std::shared_ptr<const TriangleMesh> readStl(const Dictionary& d, const std::string& caseDir) {
    const std::string file = resolve(caseDir, d.get<std::string>("file"));
    const double scale = d.has("scale") ? d.getPositive("scale") : 1.0;
    if (!fs::exists(file)) invalid(d, "file", "the STL file '" + file + "' does not exist");
    if (!fs::is_regular_file(file)) invalid(d, "file", "'" + file + "' is not a file; expected an STL file");
    return std::make_shared<const TriangleMesh>(TriangleMesh::fromStl(file, scale));
}

std::shared_ptr<Region> readRegion(const Dictionary& d, const std::string& caseDir) {
    const std::string type = d.getChoice("type", {"box", "cylinder", "stl"});
    if (type == "box") {
        const Vec3 lo = d.get<Vec3>("min");
        const Vec3 hi = d.get<Vec3>("max");
        if (!((hi.array() > lo.array()).all())) invalid(d, "max", "expected max > min in every component");
        return std::make_shared<Region>(Region::box(lo, hi));
    }
    if (type == "cylinder") {
        const Vec3 point = d.get<Vec3>("axisPoint");
        const Vec3 axis = unitVector(d, "axis");
        const double radius = d.getPositive("radius");
        const std::vector<double> range = d.get<std::vector<double>>("range");
        if (range.size() != 2 || !(range[1] > range[0]))
            invalid(d, "range", "expected (axialMin axialMax) with axialMax > axialMin");
        return std::make_shared<Region>(Region::cylinder(point, axis, radius, range[0], range[1]));
    }
    auto mesh = readStl(d, caseDir);
    // Inside and outside mean nothing for an open surface (docs/walls.md).
    if (!mesh->isClosed())
        invalid(d, "file", "the STL surface is open (an edge bounds a single triangle); a region needs a closed "
                           "surface, expected a closed STL");
    const BoundingBox box = mesh->boundingBox();
    return std::make_shared<Region>(
        Region::predicate([mesh](const Vec3& x) { return mesh->containsPoint(x); }, box.lower, box.upper));
}

WallMotion readMotion(const Dictionary& wall) {
    WallMotion motion;
    if (wall.has("motion")) {
        const Dictionary& m = wall.subDict("motion");
        for (const std::string& segmentName : m.keys()) {
            const Dictionary& s = m.subDict(segmentName);
            const std::string type = s.getChoice("type", {"translate", "rotate", "load"});
            const double start = s.getNonNegative("start");
            if (type == "load") {
                // Lowered from `start`, resting under its weight, drawn back from `raise` (WallLoad).
                WallLoad load;
                load.tStart = start;
                load.tRaise = s.getPositive("raise");
                if (!(load.tRaise > start)) invalid(s, "raise", "expected raise > start");
                load.direction = unitVector(s, "direction");
                load.mass = s.getPositive("mass");
                load.speed = s.getPositive("speed");
                load.stroke = s.getPositive("stroke");
                motion.addLoad(load);
                continue;
            }
            const double end = s.getPositive("end");
            if (!(end > start)) invalid(s, "end", "expected end > start");
            if (type == "translate") {
                motion.addTranslation(start, end, s.get<Vec3>("velocity"));
            } else {
                const double degreesPerSecond = s.get<double>("angularVelocity");
                motion.addRotation(start, end, s.get<Vec3>("axisPoint"), unitVector(s, "axis"),
                                   degreesPerSecond * pi / 180.0);
            }
        }
    }
    if (wall.has("removeAt")) motion.setRemovalTime(wall.getNonNegative("removeAt"));
    return motion;
}

// A wall whose material moves faster than impactVelocity hits particles faster
// than the time step was checked for (the Hertz collision time shortens with the
// impact speed; Simulation::timeStepLimits): e.g. a velocity typed in mm/s as m/s.
void requireWallSpeedsChecked(const Dictionary& wall, const Wall& w, const SimulationSettings& settings) {
    if (settings.allowLargeTimeStep || !wall.has("motion")) return;
    const Dictionary& motion = wall.subDict("motion");
    const std::vector<std::string> segments = motion.keys();  // in the order readMotion added them
    const AxisAlignedBox* domain = settings.domain ? &*settings.domain : nullptr;
    if (w.motion.hasLoad() && w.motion.load().speed > settings.impactVelocity) {
        std::ostringstream e;
        e.precision(6);
        e << "the wall is lowered and raised at " << w.motion.load().speed << " m/s, faster than 'impactVelocity' ("
          << settings.impactVelocity << " m/s in simulation, the largest particle speed the time step is checked "
          << "for); expected a speed <= impactVelocity";
        for (const std::string& name : segments)
            if (motion.subDict(name).get<std::string>("type") == "load") invalid(motion.subDict(name), "speed", e.str());
    }
    std::size_t k = 0;
    for (const std::string& name : segments) {
        if (motion.subDict(name).get<std::string>("type") == "load") continue;
        if (k >= w.motion.segments().size()) break;
        const double speed = w.largestSpeed(k, domain);
        const bool turns = w.motion.segments()[k].kind == MotionSegment::Kind::Rotate;
        ++k;
        if (!(speed > settings.impactVelocity)) continue;
        std::ostringstream e;
        e.precision(6);
        if (turns && !std::isfinite(speed))
            e << "a turning plane reaches arbitrarily far from its axis, where it moves faster than 'impactVelocity' ("
              << settings.impactVelocity << " m/s, the largest particle speed the time step is checked for); "
              << "expected a simulation 'domain' box (particles touch the plane only inside it)";
        else
            e << (turns ? "the wall's point farthest from the axis moves at " : "the wall moves at ") << speed
              << " m/s, faster than 'impactVelocity' (" << settings.impactVelocity
              << " m/s in simulation, the largest particle speed the time step is checked for); expected a "
              << (turns ? "slower turn" : "speed") << " <= impactVelocity, or impactVelocity >= " << speed
              << " (the time step is then checked for impacts at that speed)";
        invalid(motion.subDict(name), turns ? "angularVelocity" : "velocity", e.str());
    }
}

std::vector<Wall> readWalls(const Dictionary& root, const std::string& caseDir,
                            const std::vector<Material>& materials, const SimulationSettings& settings) {
    std::vector<Wall> walls;
    if (!root.has("walls")) return walls;
    const Dictionary& all = root.subDict("walls");
    for (const std::string& name : all.keys()) {
        requireColumnName(all, name, "wall");
        const Dictionary& d = all.subDict(name);
        const int material = materialByName(d, "material", materials);
        const std::string type = d.getChoice("type", {"plane", "cylinder", "stl"});
        auto shape = [&]() -> WallShape {
            if (type == "plane") return PlaneWall(d.get<Vec3>("point"), unitVector(d, "normal"));
            if (type == "cylinder") {
                const std::vector<double> range = d.get<std::vector<double>>("range");
                if (range.size() != 2 || !(range[1] > range[0]))
                    invalid(d, "range", "expected (axialMin axialMax) with axialMax > axialMin");
                const std::string side = d.getChoice("side", {"inside", "outside"});
                return CylinderWall(d.get<Vec3>("axisPoint"), unitVector(d, "axis"), d.getPositive("radius"),
                                    range[0], range[1],
                                    side == "inside" ? CylinderWall::Side::Inside : CylinderWall::Side::Outside);
            }
            return MeshWall(readStl(d, caseDir));
        };
        Wall w{name, shape(), WallMotion(), material};
        try {
            w.motion = readMotion(d);
        } catch (const InputError& e) {
            // The segments' own checks know neither the file nor the wall.
            const std::string what = e.what();
            if (what.rfind("file '", 0) == 0) throw;
            throw InputError(d.describe("motion") + ": " + what);
        }
        requireWallSpeedsChecked(d, w, settings);
        walls.push_back(std::move(w));
    }
    return walls;
}

std::shared_ptr<SizeDistribution> readDistribution(const Dictionary& d, double scale, const std::string& context) {
    if (d.has("diameter") && d.has("sizeDistribution"))
        invalid(d, "diameter", "give either 'diameter' (monodisperse) or 'sizeDistribution', not both");
    if (d.has("diameter")) {
        const double diameter = d.get<double>("diameter");
        if (!(diameter > 0.0)) invalid(d, "diameter", "expected a positive diameter, got " + std::to_string(diameter));
        return std::make_shared<SizeDistribution>(SizeDistribution::monodisperse(diameter, scale, context));
    }
    if (!d.has("sizeDistribution"))
        invalid(d, "sizeDistribution", "missing; expected 'diameter <d>;' or 'sizeDistribution { classes ((dMin dMax massPercent) ...); }'");
    const Dictionary& s = d.subDict("sizeDistribution");
    const auto rows = s.get<std::vector<std::vector<double>>>("classes");
    std::vector<SizeClassPercent> table;
    for (const auto& row : rows) {
        if (row.size() != 3) invalid(s, "classes", "expected rows of three numbers (dMin dMax massPercent)");
        table.push_back({row[0], row[1], row[2]});
    }
    const std::string within = s.has("withinClass")
                                   ? s.getChoice("withinClass", {"uniformDiameter", "uniformVolume"})
                                   : std::string("uniformDiameter");
    return std::make_shared<SizeDistribution>(SizeDistribution::fromPercentages(
        table, scale, within == "uniformVolume" ? WithinClass::UniformVolume : WithinClass::UniformDiameter,
        s.describe("classes")));
}

// Bounds on the number of particles asked for, checked before the population is
// drawn: a mistyped mass (1e3 for 1e-3 kg) asks for hundreds of millions of
// particles, gigabytes of diameters before the placement could refuse them.
void checkPopulationSize(const Dictionary& d, const InsertionSpec& spec, const std::string& key) {
    const double count = expectedParticleCount(spec);
    std::ostringstream what;
    what << std::setprecision(3) << "about " << count << " particles";
    // A mass below that of one particle inserts nothing, silently.
    if (count < 0.5) {
        std::ostringstream m;
        m << std::setprecision(3) << "expected at least the mass of one particle: " << spec.request.targetMass
          << " kg is " << what.str() << " of the size distribution";
        invalid(d, key, m.str());
    }
    // At once (no waves), every particle must fit in the region: not even spheres of the
    // smallest size filling its whole volume reach this count.
    const double dMin = spec.distribution->dMin();
    const double capacity = spec.region->volumeBound() / (pi / 6.0 * dMin * dMin * dMin);
    if (spec.waveInterval <= 0.0 && count > capacity) {
        std::ostringstream m;
        m << std::setprecision(3) << "expected a population the region can hold at once (no 'waveInterval'): asked for "
          << what.str() << ", the region's volume holds fewer than " << capacity
          << " even of the smallest (d = " << dMin << " m)";
        invalid(d, key, m.str());
    }
    // Memory: every particle takes at least 400 bytes in the engine (docs/performance.md).
    const double available = availableMemoryBytes();
    if (available > 0.0 && count * 400.0 > available) {
        std::ostringstream m;
        m << std::setprecision(3) << "expected a population this machine can hold: asked for " << what.str() << ", at least "
          << count * 400.0 / 1e9 << " GB, and " << available / 1e9 << " GB are available";
        invalid(d, key, m.str());
    }
}

std::vector<InsertionSpec> readInsertions(const Dictionary& root, const CaseSetup& setup) {
    std::vector<InsertionSpec> out;
    if (!root.has("insertion")) return out;
    const Dictionary& all = root.subDict("insertion");
    for (const std::string& name : all.keys()) {
        const Dictionary& d = all.subDict(name);
        InsertionSpec spec;
        spec.name = name;
        spec.context = d.fileName() + ": insertion '" + name + "'";
        spec.materialIndex = materialByName(d, "material", setup.materials);
        spec.time = d.has("time") ? d.getNonNegative("time") : 0.0;
        if (d.has("positions")) {
            // Explicit particles: the user's positions, one diameter (times the
            // coarse-grain factor); checked against the walls on insertion.
            const double diameter = d.get<double>("diameter");
            if (!(diameter > 0.0)) invalid(d, "diameter", "expected a positive diameter, got " + std::to_string(diameter));
            for (const Vec3& x : d.get<std::vector<Vec3>>("positions"))
                spec.explicitParticles.push_back({x, 0.5 * diameter * setup.coarseGrain.factor});
            if (spec.explicitParticles.empty())
                invalid(d, "positions", "expected a list of at least one position, e.g. ((0 0 0.01))");
            spec.request.initialVelocity = d.getOrDefault<Vec3>("velocity", Vec3::Zero());
            const double radius = 0.5 * diameter * setup.coarseGrain.factor;
            checkMagnitudes(root, d, spec, setup, radius, sphereMass(2.0 * radius, setup.materials[spec.materialIndex].density));
            out.push_back(std::move(spec));
            continue;
        }
        spec.region = readRegion(d.subDict("region"), setup.caseDir);
        spec.distribution = readDistribution(d, setup.coarseGrain.factor, spec.context);
        const bool byMass = d.has("mass");
        const bool byCount = d.has("count");
        if (byMass == byCount) invalid(d, "mass", "give exactly one of 'mass' (kg) and 'count'");
        InsertionRequest& r = spec.request;
        if (byMass) r.targetMass = d.getPositive("mass");
        else {
            const long count = d.get<long>("count");
            if (count <= 0) invalid(d, "count", "expected a positive number of particles");
            r.targetCount = static_cast<std::size_t>(count);
        }
        r.density = setup.materials[spec.materialIndex].density;
        r.initialVelocity = d.getOrDefault<Vec3>("velocity", Vec3::Zero());
        const long seed = d.getOrDefault<long>("seed", 1L);
        if (seed < 0) invalid(d, "seed", "expected a non-negative integer");
        r.placement.seed = static_cast<std::uint64_t>(seed);
        r.placement.gapFraction = d.has("gapFraction") ? d.getNonNegative("gapFraction") : 0.05;
        const std::string lattice = d.has("lattice") ? d.getChoice("lattice", {"hexagonalClose", "simpleCubic"})
                                                     : std::string("hexagonalClose");
        r.placement.lattice = lattice == "simpleCubic" ? Lattice::SimpleCubic : Lattice::HexagonalClose;
        const std::string packing = d.has("packing") ? d.getChoice("packing", {"random", "settled"})
                                                     : std::string("settled");
        r.placement.settleDirection = packing == "settled" ? setup.settings.gravity : Vec3::Zero();
        r.placement.context = spec.context;
        if (d.has("waveInterval")) {
            spec.waveInterval = d.getPositive("waveInterval");
            r.placement.whenFull = WhenRegionFull::PlaceWhatFits;
        }
        checkPopulationSize(d, spec, byMass ? "mass" : "count");
        checkMagnitudes(root, d, spec, setup, 0.5 * spec.distribution->dMin(), sphereMass(spec.distribution->dMax(), r.density));
        out.push_back(std::move(spec));
    }
    return out;
}

}  // namespace

int CaseSetup::materialIndex(const std::string& name) const {
    for (std::size_t i = 0; i < materials.size(); ++i)
        if (materials[i].name == name) return static_cast<int>(i);
    return -1;
}

CaseSetup readCaseSetup(const std::string& caseDir) {
    const std::string file = (fs::path(caseDir) / "constant" / "demProperties").string();
    if (!fs::exists(file))
        throw InputError("case '" + caseDir + "': missing file constant/demProperties (expected the DEM setup of the case there)");
    if (!fs::is_regular_file(file))
        throw InputError("case '" + caseDir + "': constant/demProperties is not a plain file (a folder, a FIFO or a "
                         "device); expected the DEM setup of the case as a text file");
    return readCaseSetup(Dictionary::fromFile(file), caseDir);
}

CaseSetup readCaseSetup(const Dictionary& root, const std::string& caseDir) {
    CaseSetup c;
    c.caseDir = caseDir;
    c.propertiesFile = root.fileName();

    const Dictionary& sim = root.subDict("simulation");
    SimulationSettings& s = c.settings;
    s.source = root.fileName();
    s.timeStep = sim.getPositive("timeStep");
    c.endTime = sim.getPositive("endTime");
    if (!(c.endTime / s.timeStep <= maxRunSteps)) {
        std::ostringstream e;
        e << std::setprecision(3) << "the run to endTime " << c.endTime << " s would take " << c.endTime / s.timeStep
          << " steps; expected at most " << maxRunSteps
          << " steps (at ten million steps a second, more than a day): a time step in seconds";
        invalid(sim, "timeStep", e.str());
    }
    s.gravity = sim.get<Vec3>("gravity");
    if (sim.has("skinFraction")) s.skinFraction = sim.getInRange("skinFraction", 1e-3, 2.0);
    if (sim.has("maxRayleighFraction")) s.maxRayleighFraction = sim.getInRange("maxRayleighFraction", 1e-3, 1.0);
    s.allowLargeTimeStep = sim.getOrDefault<bool>("allowLargeTimeStep", false);
    if (sim.has("maxHertzFraction")) s.maxHertzFraction = sim.getInRange("maxHertzFraction", 1e-3, 1.0);
    if (sim.has("impactVelocity")) s.impactVelocity = sim.getPositive("impactVelocity");
    if (sim.has("maxCapillaryClusterFraction"))
        s.maxCapillaryClusterFraction = sim.getInRange("maxCapillaryClusterFraction", 1e-3, 1.0);
    if (sim.has("loadBalance")) {
        const Dictionary& balance = sim.subDict("loadBalance");
        if (balance.has("weight")) {
            const std::string weight = balance.getChoice("weight", {"particles", "work", "time"});
            s.loadBalanceWeight = weight == "work"   ? LoadBalanceWeight::Work
                                  : weight == "time" ? LoadBalanceWeight::Time
                                                     : LoadBalanceWeight::Particles;
        }
        if (balance.has("threshold")) s.loadBalanceThreshold = balance.getInRange("threshold", 1.0, 1e3);
        if (balance.has("axis")) {
            const std::string axis = balance.getChoice("axis", {"auto", "x", "y", "z"});
            s.decompositionAxis = axis == "auto" ? -1 : axis[0] - 'x';
        }
    }
    if (sim.has("domain")) {
        const Dictionary& box = sim.subDict("domain");
        AxisAlignedBox b{box.get<Vec3>("min"), box.get<Vec3>("max")};
        if (!((b.max.array() > b.min.array()).all())) invalid(box, "max", "expected max > min in every component");
        s.domain = b;
    }

    const Dictionary& model = root.subDict("contactModel");
    model.getChoice("normal", {"hertz"});
    model.getChoice("tangential", {"history"});
    const std::string rolling = model.getChoice("rolling", {"none", "cdt", "epsd", "epsd2"});
    s.forces.rolling = rolling == "cdt"     ? RollingModel::CDT
                       : rolling == "epsd"  ? RollingModel::EPSD
                       : rolling == "epsd2" ? RollingModel::EPSD2
                                            : RollingModel::None;

    if (root.has("coarseGrain")) {
        const Dictionary& cg = root.subDict("coarseGrain");
        c.coarseGrain.factor = cg.get<double>("factor");
        c.coarseGrain.capillaryExponent = cg.getOrDefault<double>("capillaryExponent", paperCapillaryExponent);
        // Each value's error names its own keyword.
        validateCoarseGrainSettings(c.coarseGrain, cg.describe("factor"), cg.describe("capillaryExponent"));
    }

    if (root.has("cohesion")) {
        const Dictionary& coh = root.subDict("cohesion");
        const std::string m = coh.getChoice("model", {"none", "capillary"});
        if (m == "capillary") {
            s.forces.cohesion = CohesionModel::Capillary;
            c.waterContent = coh.getInRange("waterContent", 0.0, 1.0);
            if (coh.has("wettingTime")) c.wettingTime = coh.getInRange("wettingTime", 0.0, 1e9);
            s.forces.capillary.surfaceTension = coh.getOrDefault<double>("surfaceTension", 0.072);
            const double degrees = coh.getOrDefault<double>("contactAngle", 0.0);
            if (!(degrees >= 0.0 && degrees < 90.0)) invalid(coh, "contactAngle", "expected degrees in [0, 90)");
            s.forces.capillary.contactAngle = degrees * pi / 180.0;
            validateCapillaryParameters(s.forces.capillary, coh.describe("surfaceTension"));
            s.bridges.contactAngle = s.forces.capillary.contactAngle;
            const std::string formation =
                coh.has("bridgeFormation")
                    ? coh.getChoice("bridgeFormation", {"withinDebondingDistance", "contactThenPersist"})
                    : std::string("withinDebondingDistance");
            s.bridges.formation = formation == "contactThenPersist" ? BridgeFormation::ContactThenPersist
                                                                     : BridgeFormation::WithinDebondingDistance;
            const std::string weight = coh.has("volumeWeight")
                                           ? coh.getChoice("volumeWeight", {"diameterProduct", "diameterSum"})
                                           : std::string("diameterProduct");
            s.bridges.weight = weight == "diameterSum" ? BridgeVolumeWeight::DiameterSumTimesDistance
                                                       : BridgeVolumeWeight::DiameterProductTimesDistance;
            s.forces.capillaryForceScale =
                coarseGrainCapillaryFactor(c.coarseGrain.factor, c.coarseGrain.capillaryExponent);
            // Particle-wall bridges (sphere-plane form), off by default: the paper
            // models particle-particle bridges only.
            s.forces.wallBridges = coh.getOrDefault<bool>("wallBridges", false);
        }
    }

    const Dictionary& mats = root.subDict("materials");
    for (const std::string& name : mats.keys()) {
        const Dictionary& m = mats.subDict(name);
        Material mat;
        mat.name = name;
        // Beyond any solid (diamond: 1.2e12 Pa) is a typo, not a stiff material; refused here
        // rather than by the time-step limit that it would shrink to nothing.
        mat.youngsModulus = m.getPositive("youngsModulus");
        if (mat.youngsModulus > maxYoungsModulus) {
            std::ostringstream e;
            e << "expected a Young's modulus of a solid, at most " << maxYoungsModulus
              << " Pa (diamond: 1.2e12 Pa), got " << mat.youngsModulus << " Pa";
            invalid(m, "youngsModulus", e.str());
        }
        mat.poissonRatio = m.getInRange("poissonRatio", 0.0, 0.5);
        mat.density = m.getPositive("density");
        if (mat.density > maxDensity) {
            std::ostringstream e;
            e << "expected a density in kg/m^3, at most " << maxDensity << " (the densest solid, osmium, has 22 590), got "
              << mat.density;
            invalid(m, "density", e.str());
        }
        c.materials.push_back(mat);
    }
    if (c.materials.empty()) invalid(root, "materials", "expected at least one material");

    c.interactions = InteractionTable(c.materials.size());
    const Dictionary& inter = root.subDict("interactions");
    for (const std::string& key : inter.keys()) {
        const std::size_t dash = key.find('-');
        const int a = dash == std::string::npos ? -1 : c.materialIndex(key.substr(0, dash));
        const int b = dash == std::string::npos ? -1 : c.materialIndex(key.substr(dash + 1));
        if (a < 0 || b < 0)
            invalid(inter, key, "expected an entry named '<material>-<material>' with defined materials");
        if (c.interactions.isSet(a, b)) invalid(inter, key, "this pair of materials is already defined");
        const Dictionary& p = inter.subDict(key);
        PairCoefficients coeff;
        coeff.restitution = p.getInRange("restitution", 1e-6, 1.0);
        coeff.friction = p.getNonNegative("friction");
        coeff.rollingFriction = p.getOrDefault<double>("rollingFriction", 0.0);
        coeff.rollingViscousDamping = p.getOrDefault<double>("rollingViscousDamping", 0.0);
        if (s.forces.rolling != RollingModel::None && !p.has("rollingFriction"))
            invalid(p, "rollingFriction", "missing; the rolling model '" + rolling + "' needs it");
        // Only EPSD has a viscous rolling term: given with another model the
        // damping the user asked for would be silently absent.
        if (p.has("rollingViscousDamping") && s.forces.rolling != RollingModel::EPSD)
            invalid(p, "rollingViscousDamping",
                    "is used by the rolling model 'epsd' only; the rolling model '" + rolling +
                        "' has no viscous rolling damping: expected the keyword removed, or 'rolling epsd'");
        c.interactions.set(c.materials, a, b, coeff);
    }
    try {
        c.interactions.requireComplete(c.materials);
    } catch (const InputError& e) {
        throw InputError(inter.describe("") + ": " + e.what());
    }

    c.walls = readWalls(root, caseDir, c.materials, c.settings);
    c.insertions = readInsertions(root, c);

    if (root.has("output")) {
        const Dictionary& o = root.subDict("output");
        c.output.directory = o.getOrDefault("directory", "dem");
        const fs::path outDir = fs::path(caseDir) / c.output.directory;
        std::error_code sameError;
        if (c.output.directory.find_first_not_of(" \t") == std::string::npos ||
            fs::equivalent(outDir, caseDir, sameError))
            invalid(o, "directory", "expected a folder for the results apart from the case folder itself, e.g. 'dem'");
        if (fs::exists(outDir) && !fs::is_directory(outDir))
            invalid(o, "directory", "'" + outDir.string() + "' is a file; expected a folder for the results");
        requireOutputInsideCase(o, caseDir, c.output.directory);
        c.output.fieldInterval = o.has("fieldInterval") ? o.getNonNegative("fieldInterval") : 0.0;
        c.output.logInterval = o.has("logInterval") ? o.getNonNegative("logInterval") : 0.0;
        c.output.restartInterval = o.has("restartInterval") ? o.getNonNegative("restartInterval") : 0.0;
        if (o.has("regions")) {
            const Dictionary& regions = o.subDict("regions");
            for (const std::string& name : regions.keys()) {
                requireColumnName(regions, name, "region");
                c.output.regions.push_back({name, readRegion(regions.subDict(name), caseDir)});
            }
        }
    }
    root.checkNoUnusedKeys();
    return c;
}

std::unique_ptr<Simulation> makeSimulation(const CaseSetup& setup) {
    return std::make_unique<Simulation>(setup.settings, setup.materials, setup.interactions, setup.walls);
}

double expectedParticleCount(const InsertionSpec& spec) {
    if (!spec.explicitParticles.empty()) return static_cast<double>(spec.explicitParticles.size());
    const InsertionRequest& r = spec.request;
    return r.targetMass > 0.0 ? r.targetMass / spec.distribution->meanParticleMass(r.density)
                              : static_cast<double>(r.targetCount);
}

std::vector<double> drawPopulation(const InsertionSpec& spec) {
    if (!spec.explicitParticles.empty()) {
        std::vector<double> d;
        for (const InsertedParticle& q : spec.explicitParticles) d.push_back(2.0 * q.radius);
        return d;
    }
    const InsertionRequest& r = spec.request;
    return r.targetMass > 0.0 ? drawDiametersForMass(*spec.distribution, r.targetMass, r.density, r.placement.seed)
                              : drawDiametersForCount(*spec.distribution, r.targetCount, r.placement.seed);
}

std::size_t performInsertion(Simulation& sim, const InsertionSpec& spec, const std::vector<double>& diameters,
                             std::size_t first, const ExistingParticles* existing) {
    if (!spec.explicitParticles.empty()) {
        sim.insert(spec.explicitParticles, spec.materialIndex, spec.request.initialVelocity, spec.context);
        return spec.explicitParticles.size();
    }
    PlacementOptions placement = spec.request.placement;
    const ParticleStore& p = sim.particles();
    placement.existing.positions = &p.position;
    placement.existing.radii = &p.radius;
    if (existing) placement.existing = *existing;
    // Each wave draws its own jitter and site order, reproducibly.
    placement.seed += first;
    const double time = sim.time();
    const std::vector<Wall>& walls = sim.walls();
    placement.clearance = [&walls, time](const Vec3& x, double r) {
        std::vector<WallContact> touching;
        for (const Wall& w : walls) {
            if (!w.isActive(time)) continue;
            w.findContacts(x, r, time, touching);
            for (const WallContact& c : touching)
                if (c.overlap > 0.0) return false;
            touching.clear();
        }
        return true;
    };
    const std::vector<double> remaining(diameters.begin() + static_cast<long>(first), diameters.end());
    const std::vector<InsertedParticle> placed = placeParticles(*spec.region, remaining, placement);
    sim.insert(placed, spec.materialIndex, spec.request.initialVelocity, spec.context);
    return placed.size();
}

double massInRegion(const ParticleStore& particles, const Region& region) {
    double m = 0.0;
    for (std::size_t i = 0; i < particles.size(); ++i)
        if (region.containsSphere(particles.position[i], 0.0)) m += particles.mass[i];
    return m;
}

}  // namespace dem
