#include "demLib/case_runner.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "demLib/byte_buffer.hpp"
#include "demLib/command_line.hpp"
#include "demLib/error.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/liquid_bridges_over_ranks.hpp"
#include "demLib/particle_message.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

std::string formatDuration(double seconds) {
    std::ostringstream s;
    if (!(seconds < 1e9)) return "> 30 years";  // no overflow of the long below
    const long t = static_cast<long>(std::lround(seconds));
    if (t >= 3600) s << t / 3600 << "h" << std::setw(2) << std::setfill('0') << (t % 3600) / 60 << "m";
    else if (t >= 60) s << t / 60 << "m" << std::setw(2) << std::setfill('0') << t % 60 << "s";
    else s << t << "s";
    return s.str();
}

// Index of the first multiple of `interval` strictly after `time`.
long firstIndexAfter(double time, double interval) {
    return interval > 0.0 ? static_cast<long>(std::floor(time / interval + 1e-9)) + 1 : 0;
}

constexpr const char* caseTextMarker = "constant/demProperties as this run read it:";

std::string readText(const fs::path& file) {
    std::ifstream in(file);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::vector<std::string> linesOf(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        while (!line.empty() && (line.back() == ' ' || line.back() == '\t' || line.back() == '\r')) line.pop_back();
        lines.push_back(line);
    }
    return lines;
}

// The lines removed ("- ") and added ("+ ") from `before` to `after`, in file order
// (a longest-common-subsequence diff; case files are a few hundred lines).
std::vector<std::string> changedLines(const std::vector<std::string>& before, const std::vector<std::string>& after) {
    const std::size_t n = before.size(), m = after.size();
    std::vector<std::vector<int>> common(n + 1, std::vector<int>(m + 1, 0));
    for (std::size_t i = n; i-- > 0;)
        for (std::size_t j = m; j-- > 0;)
            common[i][j] = before[i] == after[j] ? common[i + 1][j + 1] + 1 : std::max(common[i + 1][j], common[i][j + 1]);
    std::vector<std::string> out;
    std::size_t i = 0, j = 0;
    while (i < n || j < m) {
        if (i < n && j < m && before[i] == after[j]) { ++i; ++j; }
        else if (j < m && (i == n || common[i][j + 1] >= common[i + 1][j])) out.push_back("+ " + after[j++]);
        else out.push_back("- " + before[i++]);
    }
    return out;
}

}  // namespace

CaseRunner::CaseRunner(CaseSetup setup, const RunOptions& options, std::ostream& log)
    : setup_(std::move(setup)), options_(options), log_(log) {
    caseText_ = readText(fs::path(setup_.caseDir) / "constant" / "demProperties");
    simulation_ = makeSimulation(setup_);
    const Communicator& comm = options_.communicator;
    if (!comm.isSerial()) {
        // First slabs: equal widths along loadBalance's axis, by default the
        // longest side of the domain box (or of the insertion regions); the
        // load balance re-cuts them by particle count at the first list build
        // and whenever the powder moves.
        Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
        if (setup_.settings.domain) {
            low = setup_.settings.domain->min;
            high = setup_.settings.domain->max;
        }
        if (!(low.array() < high.array()).all() || !high.allFinite() || !low.allFinite()) {
            low = Vec3::Constant(std::numeric_limits<double>::infinity());
            high = -low;
            for (const InsertionSpec& spec : setup_.insertions)
                if (spec.region) {
                    low = low.cwiseMin(spec.region->boundsMin());
                    high = high.cwiseMax(spec.region->boundsMax());
                }
        }
        if (!(low.array() < high.array()).all() || !high.allFinite() || !low.allFinite()) {
            low = Vec3::Constant(-1.0);
            high = Vec3::Constant(1.0);
        }
        int axis = setup_.settings.decompositionAxis;
        if (axis < 0) {
            axis = 0;
            for (int d = 1; d < 3; ++d)
                if (high[d] - low[d] > high[axis] - low[axis]) axis = d;
        }
        simulation_->setDecomposition(std::make_shared<GhostExchange>(
            comm, SlabDecomposition::uniform(comm.size(), axis, low[axis], high[axis]),
            setup_.settings.loadBalanceThreshold));
    }
    wetted_ = !(setup_.wettingTime > 0.0);
    const fs::path out = outputDirectory();

    const std::string restart =
        options_.restartFrom.empty() ? std::string() : restartFileFor(setup_, options_.restartFrom, "");
    if (!restart.empty()) {
        bool checked = false;
        try {
            checked = simulation_->readRestart(restart);
        } catch (const DamagedFileError& e) {
            throw DamagedFileError(std::string(e.what()) + "; refused: a continued run would not be the run it " +
                                   "continues. " + intactRestartHint(restart));
        }
        startTime_ = simulation_->time();
        readRunnerState(restart);
        // Wetting happens after the step that reaches wettingTime and before that
        // step's output, so a restart file at or after it holds the water.
        wetted_ = wetted_ || setup_.wettingTime <= startTime_ + 1e-12;
        // The file it was read from is this step's restart: finish() must not write it
        // again (a run continued at its end would rewrite the one file it has).
        lastRestartStep_ = simulation_->stepCount();
        if (setup_.endTime < startTime_ - 0.5 * simulation_->timeStep())
            throw InputError("end time " + std::to_string(setup_.endTime) + " s (keyword 'endTime' or -endTime) is " +
                             "before the restart time " + std::to_string(startTime_) +
                             " s; expected an end time after it");
        // Said once the restart is accepted: a refused one must not first say that it continues.
        if (!checked)
            log_ << "Warning: restart file " << restart << " carries no checksums (written before they existed); "
                 << "read without checking its data\n";
        log_ << "Continuing from restart file " << restart << " at t = " << startTime_ << " s, step "
             << simulation_->stepCount() << ", " << particleCount() << " particles"
             << (comm.isSerial() ? std::string() : " on " + std::to_string(comm.size()) + " ranks") << "\n";
        logRecuts();  // cut by count at the restart when read on another rank count
    }
    if (const GhostExchange* d = simulation_->decomposition(); d && !comm.isSerial()) {
        log_ << "DEM over " << comm.size() << " ranks: slabs across " << "xyz"[d->slabs().axis()] << " ("
             << (setup_.settings.decompositionAxis < 0 ? "the domain's longest side" : "keyword 'loadBalance/axis'")
             << "), cuts at";
        for (double c : d->slabs().interiorCuts()) log_ << " " << c;
        log_ << " m\n";
    }
    checkStepCount();
    for (const InsertionSpec& spec : setup_.insertions)
        if (spec.time > setup_.endTime)
            log_ << "Note: " << spec.context << " starts at t = " << spec.time << " s, after the end time "
                 << setup_.endTime << " s: this run inserts none of it\n";
    // A new run places its first particles before it opens any output: an error in
    // them (a particle in a wall, a step too large for the stiffness) must leave the
    // results of an earlier run in the case as they are.
    if (restart.empty()) {
        performDueInsertions();
        performDueWetting();
    }
    // Every output must be writable before the first of an earlier run's files changes.
    const std::size_t particlesNow = particleCount();
    if (writesFiles()) {
        requireWritableOutputs(out);
        checkFieldOutputVolume(out, particlesNow);
    }
    if (options_.outputsChanged) *options_.outputsChanged = true;
    if (writesFiles())
        fields_ = std::make_unique<FieldOutput>(out.string(), "particles", restart.empty() ? -1.0 : startTime_);

    // The summary keeps the lines up to the restart time and continues after them.
    const fs::path summaryPath = out / "summary.csv";
    std::vector<std::string> kept;
    if (writesFiles() && !restart.empty() && fs::exists(summaryPath)) {
        std::ifstream in(summaryPath);
        std::string line;
        bool lineAtRestart = false;
        for (std::size_t lineNumber = 1; std::getline(in, line); ++lineNumber) {
            if (kept.empty()) { kept.push_back(line); continue; }
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;  // a blank line holds nothing
            double t = 0.0;
            if (!parseNumber(line.substr(0, line.find(',')), t))
                throw InputError("'" + summaryPath.string() + "' line " + std::to_string(lineNumber) + ": '" +
                                 line.substr(0, 40) + "' does not start with a time; expected the lines demRun " +
                                 "wrote (time,step,...): mend or remove the line to continue the run");
            if (t <= startTime_ + 1e-12) {
                kept.push_back(line);
                lineAtRestart = t >= startTime_ - 1e-12;
            }
        }
        // A line at the restart time is this step's: finish() must not add it twice.
        if (lineAtRestart) lastLogStep_ = simulation_->stepCount();
    }
    // Every rank follows rank 0's bookkeeping of the summary (whether this
    // step's line exists), so that all take part in the same summary lines.
    if (!comm.isSerial())
        lastLogStep_ = comm.anyTrue(writesFiles() && lastLogStep_ == simulation_->stepCount())
                           ? simulation_->stepCount() : lastLogStep_;
    if (!writesFiles()) {
        // the other ranks write no files
    } else if (kept.empty()) {
        summary_.open(summaryPath, std::ios::trunc);
        if (!summary_) throw RuntimeError("cannot write '" + summaryPath.string() + "': " + std::strerror(errno));
        summary_ << std::setprecision(10);
        writeSummaryHeader();
    } else {
        // The kept lines go to a new file that replaces the old one only once it
        // is complete: a run stopped right after it started (before the stream
        // would have been flushed) must not leave the history truncated.
        const fs::path keptPath = summaryPath.string() + ".writing";
        {
            std::ofstream rewrite(keptPath, std::ios::trunc);
            for (const std::string& l : kept) rewrite << l << "\n";
            rewrite.flush();
            if (!rewrite) throw RuntimeError("cannot write '" + keptPath.string() + "': " + std::strerror(errno));
        }
        fs::rename(keptPath, summaryPath);
        summary_.open(summaryPath, std::ios::app);
        if (!summary_) throw RuntimeError("cannot write '" + summaryPath.string() + "': " + std::strerror(errno));
        summary_ << std::setprecision(10);
    }

    nextField_ = firstIndexAfter(startTime_, setup_.output.fieldInterval);
    nextLog_ = firstIndexAfter(startTime_, setup_.output.logInterval);
    nextRestart_ = firstIndexAfter(startTime_, setup_.output.restartInterval);

    if (restart.empty()) writeDueOutput(true);
    wallStart_ = lastProgress_ = std::chrono::steady_clock::now();
    stepsAtStart_ = simulation_->stepCount();
    // A gap of more than three report intervals between progress lines is a
    // stop (the engine returns every 100 steps at most, seconds even on large beds).
    estimate_ = ProgressEstimate(startTime_, setup_.endTime, 600.0, options_.progressInterval);
}

void CaseRunner::readRunnerState(const std::string& restartFile) {
    if (fs::exists(restartFile + ".runner") && !fs::is_regular_file(restartFile + ".runner"))
        throw InputError("restart file '" + restartFile + "': its companion '" + restartFile +
                         ".runner' is not a plain file; expected the file written by demRun");
    std::ifstream in(restartFile + ".runner");
    long done = -1, placed = -1;
    if (!(in >> done >> placed >> nextWaveTime_) || done < 0 || placed < 0 || !std::isfinite(nextWaveTime_))
        throw InputError("restart file '" + restartFile + "' has no readable companion '" + restartFile +
                         ".runner' (insertion progress: blocks done, particles placed, next wave time); expected "
                         "the pair written by demRun");
    insertionsDone_ = static_cast<std::size_t>(done);
    placed_ = static_cast<std::size_t>(placed);
    const std::size_t blocks = setup_.insertions.size();
    if (insertionsDone_ > blocks || (placed_ > 0 && insertionsDone_ == blocks))
        throw InputError("restart file '" + restartFile + "' was written " +
                         (placed_ > 0 ? "in the middle of insertion block " + std::to_string(insertionsDone_ + 1)
                                      : "after " + std::to_string(insertionsDone_) + " insertion block(s)") +
                         " (" + restartFile + ".runner), but constant/demProperties now defines " +
                         std::to_string(blocks) + "; expected the case's insertion blocks as they were (a block " +
                         "not yet inserted may change)");
    if (placed_ > 0) {
        const InsertionSpec& spec = setup_.insertions[insertionsDone_];
        population_ = drawPopulation(spec);
        if (placed_ > population_.size())
            throw InputError(spec.context + ": the restart file '" + restartFile + "' was written after " +
                             std::to_string(placed_) + " of its particles were placed, but the block now asks for " +
                             std::to_string(population_.size()) +
                             "; expected the block being inserted at the restart time unchanged");
    }
    // Changing the case file between the pieces of a run is allowed (as in OpenFOAM);
    // saying so keeps it from going unnoticed.
    std::string line;
    while (std::getline(in, line) && line != caseTextMarker) {
    }
    if (line != caseTextMarker) return;  // written before the case file was kept with it
    std::ostringstream before;
    before << in.rdbuf();
    const std::vector<std::string> changes = changedLines(linesOf(before.str()), linesOf(caseText_));
    if (changes.empty()) return;
    log_ << "Note: constant/demProperties has changed since this restart file was written; the run goes on with "
            "it as it is now (- then, + now):\n";
    const std::size_t shown = std::min<std::size_t>(changes.size(), 12);
    for (std::size_t k = 0; k < shown; ++k) log_ << "    " << changes[k] << "\n";
    if (changes.size() > shown) log_ << "    (" << changes.size() - shown << " more changed lines)\n";
}

std::string CaseRunner::outputDirectory() const {
    return (fs::path(setup_.caseDir) / setup_.output.directory).string();
}

namespace {
fs::path restartDirectory(const CaseSetup& setup) {
    return fs::path(setup.caseDir) / setup.output.directory / "restart";
}

// The file name that the folder's `latest` names, or empty when there is no `latest`.
std::string nameInLatest(const fs::path& restartDir) {
    std::ifstream in(restartDir / "latest");
    std::string name;
    return (in >> name) ? name : std::string();
}
}  // namespace

// A FIFO or a device would block the reading, or never end it.
static std::string requireRestartFileIsFile(const std::string& file, const std::string& who) {
    if (!fs::is_regular_file(file))
        throw InputError(who + "-restart '" + file + "': not a plain file (a folder, a FIFO or a device); expected a "
                         "restart file of <output>/restart/");
    return file;
}

std::string latestRestartFile(const CaseSetup& setup) {
    const fs::path dir = restartDirectory(setup);
    const std::string name = nameInLatest(dir);
    if (name.empty()) return {};
    const fs::path file = dir / name;
    return fs::exists(file) ? file.string() : std::string();
}

std::string restartFileFor(const CaseSetup& setup, const std::string& arg, const std::string& tool) {
    const std::string who = tool.empty() ? std::string() : tool + ": ";
    if (arg == "latest") {
        const fs::path dir = restartDirectory(setup);
        const std::string named = nameInLatest(dir);
        if (named.empty()) {
            // Restart files without the pointer (it was removed, or the run was stopped
            // before it wrote one): name them instead of saying there are none.
            std::vector<std::string> files;
            std::error_code error;
            for (const fs::directory_entry& e : fs::directory_iterator(dir, error)) {
                const std::string name = e.path().filename().string();
                if (name.rfind("restart_", 0) == 0 && e.path().extension() == ".h5") files.push_back(name);
            }
            std::sort(files.begin(), files.end());
            if (files.empty())
                throw InputError(who + "-restart latest: no restart file found in '" + dir.string() +
                                 "' (run the case first, or give -restart FILE)");
            throw InputError(who + "-restart latest: '" + (dir / "latest").string() + "', the pointer to the newest "
                             "restart file, is missing, but the folder holds " + std::to_string(files.size()) +
                             " restart file(s), the newest by step '" + (dir / files.back()).string() +
                             "'; expected the pointer: give the file to continue from as -restart FILE");
        }
        if (!fs::exists(dir / named))
            throw InputError(who + "-restart latest: '" + (dir / "latest").string() + "' names '" + named +
                             "', which is not there; expected a restart file of that folder (give it as "
                             "-restart FILE)");
        return requireRestartFileIsFile((dir / named).string(), who);
    }
    if (fs::exists(arg)) return requireRestartFileIsFile(arg, who);
    std::string message = who + "-restart '" + arg + "': no such file";
    const fs::path path(arg);
    if (path.is_relative()) {
        message += " (a relative path is taken from the current directory, " + fs::current_path().string() + ")";
        const fs::path inCase = fs::path(setup.caseDir) / path;
        if (fs::exists(inCase)) message += "; did you mean '" + inCase.string() + "'?";
    }
    throw InputError(message + "; expected a restart file or 'latest' (the newest one of the case)");
}

void CaseRunner::checkStepCount() const {
    const double dt = simulation_->timeStep();
    const double steps = (setup_.endTime - startTime_) / dt;
    if (!(steps <= maxRunSteps)) {
        std::ostringstream m;
        m << std::setprecision(3) << "file '" << setup_.propertiesFile << "', keyword 'simulation/timeStep' = " << dt
          << " s: the run to t = " << setup_.endTime << " s (endTime or -endTime) would take " << steps
          << " steps; expected at most " << maxRunSteps << " (at ten million steps a second, more than a day)";
        throw InputError(m.str());
    }
}

std::string CaseRunner::intactRestartHint(const std::string& damaged) const {
    // The user chooses the fallback: the message names it, nothing is read from it here.
    const fs::path dir = fs::path(damaged).parent_path();
    std::vector<fs::path> candidates;
    std::error_code error;
    for (const fs::directory_entry& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, error)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("restart_", 0) == 0 && e.path().extension() == ".h5" && e.is_regular_file() &&
            !fs::equivalent(e.path(), damaged, error))
            candidates.push_back(e.path());
    }
    std::sort(candidates.rbegin(), candidates.rend());  // newest step first (zero-padded names)
    for (const fs::path& candidate : candidates) {
        if (candidate.filename().string() > fs::path(damaged).filename().string()) continue;
        try {
            makeSimulation(setup_)->readRestart(candidate.string());
            if (!fs::is_regular_file(candidate.string() + ".runner")) continue;
            return "The newest intact restart file before it is '" + candidate.string() +
                   "': continue from it with -restart " + candidate.string() + ", or start the run afresh";
        } catch (const std::exception&) {
        }
    }
    return "No intact restart file before it is left in '" + dir.string() + "': start the run afresh";
}

namespace {

// A folder the run writes into: there, a folder, and a file can be created in it.
void requireWritableFolder(const fs::path& dir) {
    const fs::path probe = dir / (".diefill-write-test." + std::to_string(::getpid()));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0)
        throw RuntimeError("cannot write in the folder '" + dir.string() + "': " + std::strerror(errno));
    ::close(fd);
    ::unlink(probe.c_str());
}

[[noreturn]] void takenName(const fs::path& path, const std::string& what) {
    throw RuntimeError("cannot write '" + path.string() + "': the name is taken by " +
                       (fs::is_directory(path) ? "a folder" : "something that is not a plain file") +
                       "; expected " + what + " there (move it out of the way)");
}

}  // namespace

void requireWritableFile(const fs::path& file, const std::string& what) {
    std::error_code error;
    const fs::file_status status = fs::symlink_status(file, error);
    if (fs::exists(status)) {
        if (!fs::is_regular_file(status)) takenName(file, what);
        // Opened for appending, not created, not cut: the file is as it was.
        const int fd = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC | O_NONBLOCK);
        if (fd < 0) throw RuntimeError("cannot write '" + file.string() + "': " + std::strerror(errno));
        ::close(fd);
    }
    requireWritableFolder(file.parent_path().empty() ? fs::path(".") : file.parent_path());
}

void CaseRunner::requireWritableOutputs(const fs::path& out) const {
    const fs::path restartDir = out / "restart";
    for (const fs::path& dir : {out, restartDir}) {
        std::error_code error;
        if (fs::exists(fs::symlink_status(dir, error)) && !fs::is_directory(dir)) takenName(dir, "a folder of results");
    }
    std::error_code error;
    fs::create_directories(restartDir, error);
    if (error)
        throw RuntimeError("cannot create the output folder '" + restartDir.string() + "': " + error.message());
    requireWritableFile(out / "summary.csv", "the run's summary.csv");
    requireWritableFile(out / "particles.xdmf", "the index of the particle files");
    requireWritableFile(out / "particles.series", "the list of the particle files");
    requireWritableFile(restartDir / "latest", "the pointer to the newest restart file");
    // Files of later steps are written under a temporary name and renamed: a folder of that
    // name would stop the run after it had started.
    for (const fs::path& dir : {out, restartDir})
        for (const fs::directory_entry& e : fs::directory_iterator(dir, error)) {
            const std::string name = e.path().filename().string();
            const bool ours = (name.rfind("particles_", 0) == 0 || name.rfind("restart_", 0) == 0) &&
                              name.find(".h5") != std::string::npos;
            if (ours && !fs::is_regular_file(e.symlink_status())) takenName(e.path(), "a file of results");
        }
}

void CaseRunner::checkFieldOutputVolume(const fs::path& out, std::size_t particlesNow) const {
    // A fieldInterval below the time step writes a file every step (6 MB a step for
    // 49 000 particles): a run that would fill the disk is refused before it writes,
    // so that it cannot stop other runs' restart files from being written.
    const OutputSpec& o = setup_.output;
    double particles = 0.0;
    for (const InsertionSpec& spec : setup_.insertions) particles += expectedParticleCount(spec);
    particles = std::max(particles, static_cast<double>(particlesNow));
    const double interval = std::max(o.fieldInterval, simulation_->timeStep());
    const double files = o.fieldInterval > 0.0 ? std::floor((setup_.endTime - startTime_) / interval) + 1.0 : 1.0;
    const double bytes = files * particles * 120.0;  // measured 124 bytes per particle and file
    std::error_code error;
    const fs::space_info space = fs::space(out, error);
    if (!error && bytes > static_cast<double>(space.available)) {
        std::ostringstream m;
        m << std::setprecision(3) << setup_.caseDir << "/constant/demProperties: keyword 'output/fieldInterval' = "
          << o.fieldInterval << " s writes about " << files << " particle files of " << particles
          << " particles until t = " << setup_.endTime << " s, at least " << bytes / 1e9 << " GB, and the disk of '"
          << out.string() << "' has " << static_cast<double>(space.available) / 1e9
          << " GB free; expected a fieldInterval whose output fits";
        throw InputError(m.str());
    }
}

void CaseRunner::performDueInsertions() {
    while (insertionDueAt(simulation_->time())) {
        const InsertionSpec& spec = setup_.insertions[insertionsDone_];
        const double now = simulation_->time();
        if (placed_ == 0) population_ = drawPopulation(spec);
        const ParticleStore& p = simulation_->particles();
        const std::size_t before = particleCount();
        const std::int64_t firstNewId = simulation_->nextId();
        std::size_t n = 0;
        if (options_.communicator.isSerial() || !spec.region) {
            n = performInsertion(*simulation_, spec, population_, placed_);
        } else {
            // Every rank places the same particles around those of all ranks.
            double largest = 0.0;
            for (double d : population_) largest = std::max(largest, d);
            for (std::size_t i = 0; i < simulation_->ownedCount(); ++i) largest = std::max(largest, 2.0 * p.radius[i]);
            std::vector<Vec3> positions;
            std::vector<double> radii;
            particlesNear(*spec.region, 2.0 * options_.communicator.max(largest), positions, radii);
            ExistingParticles existing;
            existing.positions = &positions;
            existing.radii = &radii;
            n = performInsertion(*simulation_, spec, population_, placed_, &existing);
        }
        double mass = 0.0;
        for (std::size_t i = 0; i < simulation_->ownedCount(); ++i)
            if (p.id[i] >= firstNewId) mass += p.mass[i];
        if (!options_.communicator.isSerial()) mass = options_.communicator.sum(mass);
        placed_ += n;
        log_ << "Inserted " << n << " particles (" << mass * 1e3 << " g) of '" << spec.name << "' at t = " << now
             << " s";
        if (setup_.waterContent > 0.0 && n > 0 && wetted_) {
            // The water belongs to the dry mass now present: w m_dry of liquid,
            // shared out again at the next contact-list update.
            simulation_->setWaterContent(setup_.waterContent);
            log_ << ", liquid now " << simulation_->liquid().totalVolume << " m^3 (w = " << setup_.waterContent << ")";
        }
        if (n > 0) {
            // How close the run is to the time-step limits (docs/engine.md), and which one binds.
            const Simulation::TimeStepLimits limits = simulation_->timeStepLimits();
            const double allowed = limits.smallest();
            const char* binding = allowed == limits.capillary ? "wet-bed"
                                  : allowed == limits.hertz   ? "Hertz"
                                                              : "Rayleigh";
            log_ << "; time step " << simulation_->timeStep() / allowed << " of the largest allowed, " << allowed
                 << " s (" << binding << " limit)";
        }
        if (placed_ < population_.size()) {
            if (n == 0 && particleCount() == before && spec.waveInterval <= 0.0)
                throw InputError(spec.context + ": no particle fits in the region");
            nextWaveTime_ = now + spec.waveInterval;
            log_ << "; " << population_.size() - placed_ << " more in the next wave at t = " << nextWaveTime_
                 << " s" << std::endl;
            break;
        }
        log_ << std::endl;
        ++insertionsDone_;
        placed_ = 0;
        population_.clear();
    }
}

void CaseRunner::writeSummaryHeader() {
    summary_ << "time,step,particles,kineticEnergy,coordinationNumber,wallContacts,lostCount,lostMass";
    if (setup_.waterContent > 0.0)
        summary_ << ",liquidTotal,liquidInBridges,liquidPool,liquidRelativeError,bridges,liquidCoordinationNumber";
    for (const MonitorRegion& r : setup_.output.regions) summary_ << ",mass_" << r.name;
    // Force of the particles on each wall [N] (contacts and liquid bridges).
    for (const Wall& w : simulation_->walls())
        for (const char* axis : {"x", "y", "z"}) summary_ << ",wallForce_" << w.name << "_" << axis;
    // Where each wall under load stands: its offset along the load's direction [m].
    for (const Wall& w : simulation_->walls())
        if (w.motion.hasLoad()) summary_ << ",wallOffset_" << w.name;
    summary_ << "\n";
}

void CaseRunner::writeSummaryLine() {
    const Simulation& s = *simulation_;
    const ParticleStore& p = s.particles();
    const Communicator& comm = options_.communicator;
    // Every value of the run (collectives with a decomposition), then rank 0 writes.
    const RunTotals totals = s.totalsOverRanks();
    simulation_->restartWallForceMeans();  // the next line's wall forces: the mean over its interval
    const LiquidState l = s.liquidOverRanks();
    const bool wet = setup_.waterContent > 0.0;
    const double inBridges = wet ? s.liquidInBridges() : 0.0;
    const double liquidCoordination = wet ? s.liquidCoordinationNumber() : 0.0;
    std::vector<double> regionMass;
    for (const MonitorRegion& r : setup_.output.regions) {
        double m = 0.0;
        for (std::size_t i = 0; i < s.ownedCount(); ++i)
            if (r.region->containsSphere(p.position[i], 0.0)) m += p.mass[i];
        regionMass.push_back(m);
    }
    if (!comm.isSerial()) regionMass = sumOverRanksInRankOrder(comm, regionMass);
    lastLogStep_ = s.stepCount();
    if (!writesFiles()) return;
    summary_ << s.time() << "," << s.stepCount() << "," << totals.particles << "," << totals.kineticEnergy << ","
             << totals.coordinationNumber() << "," << totals.wallContacts << "," << totals.lost << ","
             << totals.lostMass;
    if (wet) {
        const double error = l.totalVolume > 0.0 ? (inBridges + l.poolVolume - l.totalVolume) / l.totalVolume : 0.0;
        summary_ << "," << l.totalVolume << "," << inBridges << "," << l.poolVolume << "," << error << ","
                 << l.bridgeCount << "," << liquidCoordination;
    }
    for (double m : regionMass) summary_ << "," << m;
    for (const Vec3& f : totals.wallForces) summary_ << "," << f.x() << "," << f.y() << "," << f.z();
    for (const Wall& w : s.walls())  // the same on every rank
        if (w.motion.hasLoad()) summary_ << "," << w.motion.loadState().offset;
    summary_ << "\n";
    summary_.flush();
}

void CaseRunner::writeRestart() {
    const fs::path dir = fs::path(outputDirectory()) / "restart";
    std::ostringstream name;
    name << "restart_" << std::setw(9) << std::setfill('0') << simulation_->stepCount() << ".h5";
    simulation_->writeRestart((dir / name.str()).string());  // collective with a decomposition
    lastRestartStep_ = simulation_->stepCount();
    if (!writesFiles()) return;
    {
        // What the engine's restart file does not know: the insertion progress, and the
        // case file it ran with, so that a continued run can say what changed since.  Written
        // whole or not at all, as the restart file is (a run killed while writing it, or a
        // full disk, must not leave a cut file that a continued run reads as a changed case).
        const std::string state = (dir / name.str()).string() + ".runner";
        {
            std::ofstream out(state + ".writing");
            out << std::setprecision(17) << insertionsDone_ << " " << placed_ << " " << nextWaveTime_ << "\n";
            out << caseTextMarker << "\n" << caseText_;
            out.flush();
            if (!out) throw RuntimeError("cannot write '" + state + ".writing' (disk full?)");
        }
        fs::rename(state + ".writing", state);
    }
    const fs::path pointer = dir / "latest";
    {
        std::ofstream out(pointer.string() + ".writing");
        out << name.str() << "\n";
    }
    fs::rename(pointer.string() + ".writing", pointer);
}

bool CaseRunner::intervalDue(double interval, long next, double t) const {
    return interval > 0.0 && t >= next * interval - 0.5 * simulation_->timeStep();
}

void CaseRunner::writeDueOutput(bool force) {
    const double t = simulation_->time();
    const double eps = 0.5 * simulation_->timeStep();
    const OutputSpec& o = setup_.output;
    const long step = simulation_->stepCount();
    if (intervalDue(o.fieldInterval, nextField_, t) || (force && lastFieldStep_ != step)) {
        if (options_.communicator.isSerial()) {
            fields_->write(*simulation_);
        } else {
            const ParticleStore all = gatheredParticles();  // collective; rank 0 holds them
            if (writesFiles()) fields_->write(all, t, step);
        }
        lastFieldStep_ = step;
        nextField_ = firstIndexAfter(t + eps, o.fieldInterval);
    }
    if (intervalDue(o.logInterval, nextLog_, t) || (force && lastLogStep_ != step)) {
        writeSummaryLine();
        nextLog_ = firstIndexAfter(t + eps, o.logInterval);
    }
    if (intervalDue(o.restartInterval, nextRestart_, t)) {
        writeRestart();
        nextRestart_ = firstIndexAfter(t + eps, o.restartInterval);
    }
}

void CaseRunner::progress(bool force) {
    if (options_.progressInterval <= 0.0 && !force) return;
    const auto now = std::chrono::steady_clock::now();
    const double sinceLast = std::chrono::duration<double>(now - lastProgress_).count();
    bool due = force || sinceLast >= options_.progressInterval;
    // Rank 0's clock decides, so that every rank joins the totals below.
    const Communicator& comm = options_.communicator;
    if (!comm.isSerial()) due = comm.anyTrue(comm.rank() == 0 && due);
    if (!due) return;
    lastProgress_ = now;
    const Simulation& s = *simulation_;
    const RunTotals totals = s.totalsOverRanks();
    if (!writesFiles()) return;
    const double elapsed = std::chrono::duration<double>(now - wallStart_).count();
    estimate_.add(elapsed, s.time());
    const double eta = estimate_.secondsLeft();
    const double particleSteps = static_cast<double>(s.stepCount() - stepsAtStart_) * totals.particles;
    log_ << std::fixed << std::setprecision(4) << "t = " << s.time() << " s (" << std::setprecision(1)
         << 100.0 * s.time() / setup_.endTime << " %)" << std::defaultfloat << std::setprecision(6)
         << "  step " << s.stepCount() << "  particles " << totals.particles << "  KE "
         << totals.kineticEnergy << " J  lost " << totals.lost << "  "
         << std::setprecision(3) << (elapsed > 0 ? particleSteps / elapsed : 0.0) << " particle-steps/s"
         << "  elapsed " << formatDuration(elapsed) << "  ETA " << (eta >= 0.0 ? formatDuration(eta) : "-")
         << std::endl;
}

bool CaseRunner::insertionDueAt(double now) const {
    if (insertionsDone_ >= setup_.insertions.size()) return false;
    if (setup_.insertions[insertionsDone_].time > now + 1e-12) return false;
    return !(placed_ > 0 && now < nextWaveTime_ - 1e-12);  // the last wave is still settling
}

bool CaseRunner::wettingDueAt(double now) const {
    return !wetted_ && setup_.waterContent > 0.0 && setup_.wettingTime <= now + 1e-12;
}

void CaseRunner::performDueWetting() {
    if (!wettingDueAt(simulation_->time())) return;
    simulation_->setWaterContent(setup_.waterContent);
    wetted_ = true;
    log_ << "Wetted at t = " << simulation_->time() << " s (keyword 'wettingTime'): liquid "
         << simulation_->liquid().totalVolume << " m^3 (w = " << setup_.waterContent << ") on "
         << particleCount() << " particles" << std::endl;
}

bool CaseRunner::outputDueAt(double t) const {
    const OutputSpec& o = setup_.output;
    return intervalDue(o.fieldInterval, nextField_, t) || intervalDue(o.logInterval, nextLog_, t) ||
           intervalDue(o.restartInterval, nextRestart_, t);
}

void CaseRunner::advanceTo(double time) {
    const double target = std::min(time, setup_.endTime);
    Simulation& s = *simulation_;
    const double dt = s.timeStep();
    while (s.time() < target - 0.5 * dt) {
        // The steps up to the next one after which the runner has something
        // to do (an insertion, output, the target), taken in one call: the
        // engine then fuses each step's closing half kick with the next one's
        // drift (one pass over the particles instead of two), with the same
        // results as single steps.  The same time tests as after each single
        // step (time = step count x dt, as the engine computes it).
        long steps = 0;
        for (long next = s.stepCount() + 1; steps < maxStepsPerCall; ++next) {
            ++steps;
            const double t = static_cast<double>(next) * dt;
            if (!(t < target - 0.5 * dt) || insertionDueAt(t) || wettingDueAt(t) || outputDueAt(t)) break;
        }
        const std::size_t before = particleCount();
        s.step(steps);
        logRecuts();
        requireParticlesKept(before);
        performDueInsertions();
        performDueWetting();
        writeDueOutput(false);
        progress(false);
    }
}

void CaseRunner::requireParticlesKept(std::size_t before) {
    // Every particle lost in the first interval after the run's first particles (its
    // first log interval, 100 to 10 000 steps): no bed leaves its domain so soon;
    // magnitudes that are not physics (a gravity, speed or density near the largest
    // double) do.  Stopped with an error, not ended as if the run had succeeded.
    const Simulation& s = *simulation_;
    if (firstParticlesStep_ < 0 && before > 0) firstParticlesStep_ = s.stepCount();
    if (before == 0 || firstParticlesStep_ < 0 || particleCount() > 0) return;
    const double interval = setup_.output.logInterval / s.timeStep();
    const double window = std::clamp(std::isfinite(interval) ? interval : 0.0, 100.0, 10000.0);
    if (static_cast<double>(s.stepCount() - firstParticlesStep_) > window) return;
    std::ostringstream m;
    m << std::setprecision(3) << "file '" << setup_.propertiesFile << "': every particle (" << s.totalsOverRanks().lost
      << ") was lost by t = " << s.time() << " s, within " << s.stepCount() - firstParticlesStep_
      << " steps of the first ones (they left the domain, or their state became infinite or NaN); expected "
         "magnitudes of physics: check the keywords 'simulation/gravity' (|g| = "
      << setup_.settings.gravity.norm() << " m/s^2), the insertions' 'velocity', the materials' 'density' and "
         "'youngsModulus', and 'simulation/domain'";
    throw InputError(m.str());
}

void CaseRunner::logRecuts() {
    const GhostExchange* d = simulation_->decomposition();
    if (!d || d->recutCount() == recutsLogged_) return;
    // The report holds the run's values (reductions), the same on every rank.
    const GhostExchange::RebalanceReport& r = d->lastRecut();
    log_ << "DEM slabs re-cut at t = " << simulation_->time() << " s (" << d->recutCount() - recutsLogged_
         << " since the last line): owned particles max " << r.maxOwned << " / mean " << r.meanOwned
         << " = " << static_cast<double>(r.maxOwned) / r.meanOwned << " before, max/mean "
         << r.imbalanceAfter << " after";
    if (r.weighted)
        log_ << (setup_.settings.loadBalanceWeight == LoadBalanceWeight::Time
                     ? "; busy time (step() less its collectives, per rank since the last check) max/mean "
                     : "; work (1 + listed pairs + wall contacts per particle) max/mean ")
             << r.imbalance << " before, " << r.loadImbalanceAfter << " after";
    log_ << "; cuts along " << "xyz"[d->slabs().axis()] << " now at";
    for (double c : r.cuts) log_ << " " << c;
    log_ << " m" << std::endl;
    recutsLogged_ = d->recutCount();
}

std::size_t CaseRunner::particleCount() const {
    const Communicator& comm = options_.communicator;
    const std::size_t owned = simulation_->ownedCount();
    return comm.isSerial() ? owned : static_cast<std::size_t>(comm.sum(static_cast<std::int64_t>(owned)));
}

ParticleStore CaseRunner::gatheredParticles() const {
    const Communicator& comm = options_.communicator;
    const ParticleStore& p = simulation_->particles();
    std::vector<std::vector<char>> send(comm.size());
    ByteWriter out{send[0]};
    for (std::size_t i = 0; i < simulation_->ownedCount(); ++i) packParticle(out, p, i);
    const std::vector<std::vector<char>> received = comm.exchange(send);
    ParticleStore all;
    if (comm.rank() != 0) return all;
    for (const std::vector<char>& part : received)
        for (ByteReader in{part}; !in.done();) unpackParticle(in, all);
    return all;
}

void CaseRunner::particlesNear(const Region& region, double margin, std::vector<Vec3>& positions,
                               std::vector<double>& radii) const {
    const ParticleStore& p = simulation_->particles();
    const Vec3 low = region.boundsMin() - Vec3::Constant(margin), high = region.boundsMax() + Vec3::Constant(margin);
    std::vector<double> mine;
    for (std::size_t i = 0; i < simulation_->ownedCount(); ++i) {
        const Vec3& x = p.position[i];
        if ((x.array() < low.array()).any() || (x.array() > high.array()).any()) continue;
        mine.insert(mine.end(), {x.x(), x.y(), x.z(), p.radius[i]});
    }
    positions.clear();
    radii.clear();
    for (const std::vector<double>& part : gatherFromAllRanks(options_.communicator, mine))
        for (std::size_t k = 0; k + 3 < part.size(); k += 4) {
            positions.emplace_back(part[k], part[k + 1], part[k + 2]);
            radii.push_back(part[k + 3]);
        }
}

void CaseRunner::finish() {
    writeDueOutput(true);
    if (lastRestartStep_ != simulation_->stepCount()) writeRestart();
    progress(true);
}

}  // namespace dem
