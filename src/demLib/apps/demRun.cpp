// demRun: runs a DEM-only case (no air), e.g. the calibration tutorials.
//   demRun [-case DIR] [-restart FILE|latest] [-threads N] [-parallel] [-help]
// Reads DIR/constant/demProperties, writes DIR/<output>/ (particle fields as
// HDF5 + XDMF for ParaView, summary.csv, restart files) and DIR/log.demRun.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "demLib/case_lock.hpp"
#include "demLib/case_runner.hpp"
#include "demLib/command_line.hpp"
#include "demLib/config.hpp"
#include "demLib/error.hpp"
#include "demLib/stop_signal.hpp"
#include "demLib/version.hpp"
#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

namespace {

// Writes to the console and to the case's log file at once.
class TeeBuffer : public std::streambuf {
public:
    TeeBuffer(std::streambuf* a, std::streambuf* b) : a_(a), b_(b) {}
    void setSecond(std::streambuf* b) { b_ = b; }

protected:
    int overflow(int c) override {
        if (c == EOF) return !EOF;
        const int r1 = a_->sputc(static_cast<char>(c));
        const int r2 = b_ ? b_->sputc(static_cast<char>(c)) : c;
        return (r1 == EOF || r2 == EOF) ? EOF : c;
    }
    int sync() override {
        const int r1 = a_->pubsync();
        const int r2 = b_ ? b_->pubsync() : 0;
        return (r1 == 0 && r2 == 0) ? 0 : -1;
    }

private:
    std::streambuf* a_;
    std::streambuf* b_;
};

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
    return text;
}

void usage(std::ostream& out) {
    out << "Usage: demRun [OPTIONS]\n"
           "Runs a DEM-only diefill case (demLib " << dem::versionString << ").\n\n"
           "Options:\n"
           "  -case DIR          case directory (default: current directory); reads DIR/constant/demProperties\n"
           "  -restart FILE      continue from a restart file; 'latest' takes the newest one of the case\n"
           "  -threads N         OpenMP threads (default: OMP_NUM_THREADS or all cores)\n"
           "  -endTime T         stop at T seconds instead of the case's endTime\n"
           "  -quiet             no progress lines\n"
           "  -parallel          run the DEM spread over the processes of an MPI launcher, e.g.\n"
           "                     mpirun -np 4 demRun -case DIR -parallel (each rank steps the particles of\n"
           "                     its slab; one thread per rank unless -threads; docs/parallel.md)\n"
           "  -help              this text\n\n"
           "Writes into the case: log.demRun (a run with -restart adds to it), <output>/particles.xdmf\n"
           "(+ particles_*.h5; open the .xdmf in ParaView), <output>/summary.csv, <output>/restart/restart_*.h5.\n"
           "The input format is described in docs/case-reference.md.  Exit status: 0 on success, 1 on bad\n"
           "input, 2 on a runtime or filesystem failure or a case in use by another run (the case folder is\n"
           "locked for the length of a run: <case>/.diefill.lock), 128 + the signal when stopped by SIGINT or SIGTERM (the restart\n"
           "file of that step is written first; a second signal ends it at once).\n";
}

}  // namespace

int main(int argc, char** argv) {
    std::string caseDir = ".";
    dem::RunOptions options;
    double endTime = -1.0;
    int threads = 0;
    bool parallel = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](const char* what) -> std::string {
            if (i + 1 >= argc) {
                std::cerr << "demRun: option " << a << " expects " << what << "\n";
                std::exit(1);
            }
            return argv[++i];
        };
        if (a == "-help" || a == "--help" || a == "-h") {
            usage(std::cout);
            return 0;
        } else if (a == "-case") {
            caseDir = value("a directory");
        } else if (a == "-restart") {
            options.restartFrom = value("a restart file or 'latest'");
        } else if (a == "-threads") {
            const std::string text = value("a number of threads");
            double n = 0.0;
            if (!dem::parseNumber(text, n) || n < 1.0 || n != std::floor(n) || n > 4096.0) {
                std::cerr << "demRun: -threads expects a positive integer, got '" << text << "'\n";
                return 1;
            }
            threads = static_cast<int>(n);
        } else if (a == "-endTime") {
            const std::string text = value("a time in seconds");
            if (!dem::parseNumber(text, endTime) || !(endTime > 0.0)) {
                std::cerr << "demRun: -endTime expects a positive time in seconds, got '" << text << "'\n";
                return 1;
            }
        } else if (a == "-quiet") {
            options.progressInterval = 0.0;
        } else if (a == "-parallel") {
            parallel = true;
        } else {
            std::cerr << "demRun: unknown option '" << a << "'\n";
            usage(std::cerr);
            return 1;
        }
    }
    // -parallel: MPI starts here (demLib never starts it) and every rank runs
    // the case; rank 0 writes the log and the outputs.
    int rank = 0;
    if (parallel) {
#if DEMLIB_HAS_MPI
        int provided = 0;
        MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
        options.communicator = dem::communicatorFromMpi(MPI_COMM_WORLD);
        rank = options.communicator.rank();
        if (options.communicator.size() < 2) {
            std::cerr << "demRun: -parallel runs under an MPI launcher with 2 or more processes, e.g. "
                         "mpirun -np 4 demRun -case " << caseDir << " -parallel; without it run demRun alone\n";
            MPI_Finalize();
            return 1;
        }
        if (threads == 0) threads = 1;  // ranks share the cores: one thread each unless told
#else
        std::cerr << "demRun: -parallel needs demLib built with MPI (this build has none: DEMLIB_MPI off or "
                     "MPI not found when it was configured)\n";
        return 1;
#endif
    }
    const bool writer = rank == 0;
    // Ends an MPI run: at once (MPI_Abort) when a rank failed, since the others
    // may wait for it in a collective.
    auto leave = [&](int status) {
#if DEMLIB_HAS_MPI
        if (parallel) {
            if (status == 0 || status >= 128) MPI_Finalize();
            else MPI_Abort(MPI_COMM_WORLD, status);
        }
#endif
        return status;
    };
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#endif
    // A continued run adds to the log of the run it continues (whose earlier part the
    // restart file's results belong to); a new run starts a new log, as its results do.
    // The log is opened once the run has started: until then its lines are held here,
    // so that a run refused for its input leaves the log of the earlier run as it was.
    std::ofstream logFile;
    bool outputsChanged = false;
    const bool continuing = !options.restartFrom.empty();
    std::stringbuf beforeStart;
    std::stringbuf discarded;  // the other ranks' log: rank 0 writes the run's
    TeeBuffer tee(writer ? std::cout.rdbuf() : &discarded, writer ? &beforeStart : nullptr);
    std::ostream log(&tee);
    const auto openLog = [&] {
        if (!writer || !std::filesystem::is_directory(caseDir)) return;
        logFile.open(std::filesystem::path(caseDir) / "log.demRun", continuing ? std::ios::app : std::ios::trunc);
        if (!logFile.is_open()) return;
        if (continuing)
            logFile << "\n==== demRun -restart " << options.restartFrom << ": continued at " << utcNow() << "\n";
        logFile << beforeStart.str() << std::flush;
        tee.setSecond(logFile.rdbuf());
    };
    try {
        log << "demRun (demLib " << dem::versionString << "), case " << std::filesystem::absolute(caseDir).string()
#ifdef _OPENMP
            << ", " << omp_get_max_threads() << " thread(s)"
#endif
            << (parallel ? " per rank, " + std::to_string(options.communicator.size()) + " MPI ranks" : std::string())
            << std::endl;
        dem::CaseSetup setup = dem::readCaseSetup(caseDir);
        if (endTime > 0.0) setup.endTime = endTime;
        // One run at a time in a case: a second one would cut the first one's results.
        std::optional<dem::CaseLock> lock;
        if (writer) {
            lock.emplace(caseDir, "demRun");
            dem::requireWritableFile(std::filesystem::path(caseDir) / "log.demRun", "the run's log");
        }
        options.outputsChanged = &outputsChanged;
        dem::CaseRunner runner(std::move(setup), options, log);
        log.flush();
        openLog();
        // Ctrl-C or SIGTERM: the run stops at the end of the current slice of steps and
        // writes its restart file, so that no more than a slice is lost.
        dem::catchStopSignals();
        const dem::Simulation& simulation = runner.simulation();
        const double end = runner.setup().endTime, dt = simulation.timeStep();
        // With ranks the stop is taken together (the launcher signals each rank).
        const dem::Communicator& comm = options.communicator;
        auto stopping = [&] {
            const bool mine = dem::stopSignalReceived() != 0;
            return comm.isSerial() ? mine : comm.anyTrue(mine);
        };
        // -parallel: the communication of the run from here on (the
        // communicator's counters; docs/performance.md, part (f)).
        comm.resetCounters();
        const auto runStart = std::chrono::steady_clock::now();
        const long firstStep = simulation.stepCount();
        double particleSteps = 0.0;
        while (simulation.time() < end - 0.5 * dt && !stopping()) {
            const long stepBefore = simulation.stepCount();
            runner.advanceTo(simulation.time() + 200.0 * dt);  // slices: same results as one call
            if (parallel)
                particleSteps += static_cast<double>(comm.sum(static_cast<std::int64_t>(simulation.ownedCount()))) *
                                 static_cast<double>(simulation.stepCount() - stepBefore);
        }
        runner.finish();
        if (parallel) {
            const dem::CommunicationCounters c = comm.counters();
            const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count();
            const double bytes = static_cast<double>(comm.sum(c.bytesSent()));
            const double slowest = comm.max(c.seconds);
            const long steps = std::max(1L, simulation.stepCount() - firstStep);
            log << "Communication over " << comm.size() << " ranks: " << std::setprecision(4)
                << (particleSteps > 0.0 ? bytes / particleSteps : 0.0) << " bytes per particle-step, "
                << c.seconds << " s in collectives on rank 0 (" << 100.0 * c.seconds / std::max(wall, 1e-9)
                << " % of " << wall << " s), at most " << slowest << " s on a rank, "
                << static_cast<double>(c.calls()) / static_cast<double>(steps) << " collectives per step"
                << std::setprecision(6) << std::endl;
        }
        int signal = dem::stopSignalReceived();
        if (!comm.isSerial()) signal = static_cast<int>(comm.max(static_cast<double>(signal)));
        if (signal != 0) {
            log << "\ndemRun: stopped by " << dem::stopSignalName(signal) << " at t = "
                << simulation.time() << " s (step " << simulation.stepCount()
                << "), its restart file written; continue with: demRun -case " << caseDir << " -restart latest"
                << std::endl;
            return leave(128 + signal);
        }
        log << "End. Results in " << runner.outputDirectory() << " (open particles.xdmf in ParaView)" << std::endl;
        return leave(0);
    } catch (const std::exception& e) {
        const bool inputError = dynamic_cast<const dem::InputError*>(&e) != nullptr;
        if (!writer) {
            // Input errors are found alike on every rank (rank 0 says it); anything
            // else may be this rank's alone.
            if (!inputError) std::cerr << "demRun (rank " << rank << "): error: " << e.what() << std::endl;
            return leave(inputError ? 1 : 2);
        }
        log << "\ndemRun: " << (inputError ? "input error: " : "error: ") << e.what() << std::endl;
        if (!outputsChanged)
            log << "demRun: the run did not start; log.demRun and the case's results are as they were" << std::endl;
        else if (!logFile.is_open())
            log << "demRun: the run stopped while it opened its output; the results in the case's output folder "
                   "may be incomplete" << std::endl;
        return leave(inputError ? 1 : 2);
    }
}
