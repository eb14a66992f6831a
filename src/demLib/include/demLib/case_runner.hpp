#pragma once
// Runs a case to its end time: insertions at their times, particle fields
// (HDF5 + XDMF) and restart files at their intervals, a summary line per log
// interval in <output>/summary.csv, and progress with an ETA on the console.
// Used by the demRun front end and, one fluid step at a time, by diefillFoam.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>

#include "demLib/case_setup.hpp"
#include "demLib/communicator.hpp"
#include "demLib/field_output.hpp"
#include "demLib/progress_estimate.hpp"

namespace dem {

struct RunOptions {
    // Restart file to continue from; "latest" picks the newest of the case.
    std::string restartFrom;
    // Seconds of wall time between progress lines (0: none).
    double progressInterval = 5.0;
    // Set to true just before the run changes its first output file (until then a run
    // that stops has left an earlier run's results as they were).
    bool* outputsChanged = nullptr;
    // The ranks the DEM is spread over (docs/engine.md, "Domain decomposition"):
    // every rank constructs a CaseRunner with the same case and calls the same
    // methods; rank 0 writes the outputs and the log (give the other ranks a
    // stream that discards), all ranks take part in every collective.
    Communicator communicator = Communicator::serial();
};

// Throws RuntimeError (a filesystem failure, not an input error) when `file` cannot be
// written: its name taken by a folder, the file or its folder not writable.  Changes nothing.
void requireWritableFile(const std::filesystem::path& file, const std::string& what);

// The newest restart file of a case (<case>/<output>/restart/latest names it),
// or an empty string when there is none.
std::string latestRestartFile(const CaseSetup& setup);

// The restart file that `-restart ARG` names: 'latest' (the newest one of the
// case) or a file, whose relative path is taken from the current directory (as
// every path on a command line).  Throws InputError, naming the option, when
// there is none (and the case's file by that path, if it has one); the message
// starts with "tool: " (empty: the caller adds its own name, as demRun does).
std::string restartFileFor(const CaseSetup& setup, const std::string& arg, const std::string& tool);

class CaseRunner {
public:
    CaseRunner(CaseSetup setup, const RunOptions& options, std::ostream& log);

    // Advances to `time` (not beyond the case's end time).
    void advanceTo(double time);
    void runToEnd() { advanceTo(setup_.endTime); }
    // Writes the final fields, restart file and summary line.
    void finish();

    Simulation& simulation() { return *simulation_; }
    const CaseSetup& setup() const { return setup_; }
    std::string outputDirectory() const;

private:
    // Most steps advanceTo hands the engine in one call (keeps the progress
    // line, which is checked between calls, on time).
    static constexpr long maxStepsPerCall = 100;

    // Is output of this interval due at time t, the next one being number `next`?
    bool intervalDue(double interval, long next, double t) const;
    bool insertionDueAt(double time) const;  // would performDueInsertions insert at this time?
    bool wettingDueAt(double time) const;    // is the water of a later wettingTime to be added now?
    void performDueWetting();
    bool outputDueAt(double time) const;     // would writeDueOutput(false) write at this time?
    void performDueInsertions();
    void writeDueOutput(bool force);
    void writeSummaryHeader();
    void writeSummaryLine();
    void writeRestart();
    void readRunnerState(const std::string& restartFile);
    // Most steps a run may take: more is a mistyped time step, whose ETA would overflow.
    static constexpr double maxRunSteps = 1e12;
    void checkStepCount() const;  // throws InputError beyond maxRunSteps
    // Throws InputError when the `before` particles of the last slice were all lost in it.
    void requireParticlesKept(std::size_t before);
    // The message's end for a damaged restart file: the newest intact one before it.
    std::string intactRestartHint(const std::string& damaged) const;
    // Throws RuntimeError before anything is written when an output cannot be.
    void requireWritableOutputs(const std::filesystem::path& outputDirectory) const;
    // Throws InputError when the particle files asked for would not fit on the disk.
    void checkFieldOutputVolume(const std::filesystem::path& outputDirectory, std::size_t particlesNow) const;
    void progress(bool force);
    // With a decomposition: a log line for each re-cut of the DEM slabs since the last.
    void logRecuts();
    // Rank 0 writes the files (always true without a decomposition).
    bool writesFiles() const { return options_.communicator.rank() == 0; }
    // Particles of the run (all ranks; a collective with a decomposition).
    std::size_t particleCount() const;
    // The owned particles of all ranks on rank 0, for the particle files.
    ParticleStore gatheredParticles() const;
    // The particles of all ranks within `margin` of the region's bounds (every
    // rank the same list): what a new insertion must not overlap.
    void particlesNear(const Region& region, double margin, std::vector<Vec3>& positions,
                       std::vector<double>& radii) const;

    CaseSetup setup_;
    std::string caseText_;  // constant/demProperties as read at the start, kept with each restart file
    RunOptions options_;
    std::ostream& log_;
    std::unique_ptr<Simulation> simulation_;
    std::unique_ptr<FieldOutput> fields_;
    std::ofstream summary_;
    std::size_t insertionsDone_ = 0;
    bool wetted_ = false;  // the water was added (at once when wettingTime is 0)
    // The block being inserted in waves: its population and how much is placed.
    std::vector<double> population_;
    std::size_t placed_ = 0;
    double nextWaveTime_ = 0.0;
    long nextField_ = 0, nextLog_ = 0, nextRestart_ = 0;  // interval counters
    long lastFieldStep_ = -1, lastLogStep_ = -1, lastRestartStep_ = -1;
    double startTime_ = 0.0;
    std::chrono::steady_clock::time_point wallStart_, lastProgress_;
    long stepsAtStart_ = 0;
    std::size_t recutsLogged_ = 0;  // the DEM slabs' re-cuts said in the log so far
    long firstParticlesStep_ = -1;  // the step at which this run first held particles
    ProgressEstimate estimate_{0.0, 0.0};  // the ETA, from the pace of the last minutes
};

}  // namespace dem
