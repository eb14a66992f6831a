// demStability: the stable time step of a bed from its actual contacts
// (demLib/bed_stability.hpp): reads a case and one of its restart files (a
// settled bed), linearises every contact and reports the largest step at which
// no mode of the bed grows, against the case's step and the a-priori limits
// the engine checks at insertion.
//   demStability [-case DIR] [-restart FILE|latest] [-timeStep T] [-region X0 Y0 Z0 X1 Y1 Z1]
//                [-iterations N] [-tolerance F] [-help]
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <string>

#include "demLib/bed_stability.hpp"
#include "demLib/case_runner.hpp"
#include "demLib/case_setup.hpp"
#include "demLib/command_line.hpp"
#include "demLib/error.hpp"
#include "demLib/simulation.hpp"
#include "demLib/version.hpp"

namespace {

void usage(std::ostream& out) {
    out << "Usage: demStability [OPTIONS]\n"
           "The stable time step of a bed from its actual contacts (demLib " << dem::versionString << ").\n"
           "Every contact of the bed in the restart file is linearised (normal, tangential and rolling\n"
           "springs and dashpots at its own overlap), all particles move, and the growth of the velocity\n"
           "Verlet step is measured by iterating it; the step is bisected between stable and growing.\n"
           "Use it on a settled bed (e.g. a short run at a small step) of up to some thousand particles:\n"
           "it costs a few seconds per thousand particles and trial step.  docs/engine.md explains it.\n\n"
           "Options:\n"
           "  -case DIR          case directory (default: current directory); reads DIR/constant/demProperties\n"
           "  -restart FILE      restart file of the bed; 'latest' (default) takes the newest one of the case\n"
           "  -timeStep T        the step to judge (default: the case's timeStep, which the restart file holds)\n"
           "  -region X0 Y0 Z0 X1 Y1 Z1  only the particles with centres in this box [m] move; those outside\n"
           "                     that touch them are held fixed (for a part of a large bed; default: all)\n"
           "  -iterations N      steps of the linear map per trial step (default 10000, at least 1000)\n"
           "  -tolerance F       relative tolerance of the bisection (default 0.01, in [1e-6, 0.5))\n"
           "  -help              this text\n\n"
           "Exit status: 0 when the step is stable, 3 when a mode grows at it, 1 on bad input, 2 on a\n"
           "runtime failure.\n";
}

// A finite number, or an InputError naming the option and what it expects.
double number(const std::string& option, const std::string& text, const std::string& expected) {
    double v = 0.0;
    if (!dem::parseNumber(text, v))
        throw dem::InputError("demStability: " + option + " expects " + expected + ", got '" + text + "'");
    return v;
}

double positiveNumber(const std::string& option, const std::string& text) {
    const double v = number(option, text, "a positive number");
    if (!(v > 0.0)) throw dem::InputError("demStability: " + option + " expects a positive number, got '" + text + "'");
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        std::string caseDir = ".";
        std::string restart = "latest";
        dem::BedStabilityOptions options;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto value = [&](const char* what) -> std::string {
                if (i + 1 >= argc) throw dem::InputError("demStability: option " + a + " expects " + what);
                return argv[++i];
            };
            if (a == "-help" || a == "--help" || a == "-h") {
                usage(std::cout);
                return 0;
            } else if (a == "-case") {
                caseDir = value("a directory");
                if (caseDir.rfind('-', 0) == 0)
                    throw dem::InputError("demStability: -case expects a directory, got the option '" + caseDir + "'");
            } else if (a == "-restart") {
                restart = value("a restart file or 'latest'");
                if (restart.rfind('-', 0) == 0)
                    throw dem::InputError("demStability: -restart expects a restart file or 'latest', got the option '" +
                                          restart + "'");
            } else if (a == "-timeStep") {
                options.timeStep = positiveNumber(a, value("a time step in seconds"));
            } else if (a == "-iterations") {
                const double n = positiveNumber(a, value("a number of steps"));
                if (n < 1000 || n > 1e8 || n != std::floor(n))
                    throw dem::InputError("demStability: -iterations expects an integer in [1000, 1e8], got '" +
                                          std::string(argv[i]) + "'");
                options.iterations = static_cast<int>(n);
            } else if (a == "-region") {
                double v[6];
                for (double& x : v)
                    x = number(a, value("six numbers: xmin ymin zmin xmax ymax zmax"),
                               "six numbers (xmin ymin zmin xmax ymax zmax, m)");
                if (!(v[0] < v[3] && v[1] < v[4] && v[2] < v[5]))
                    throw dem::InputError("demStability: -region expects xmin < xmax, ymin < ymax, zmin < zmax");
                options.regionLower = dem::Vec3(v[0], v[1], v[2]);
                options.regionUpper = dem::Vec3(v[3], v[4], v[5]);
            } else if (a == "-tolerance") {
                options.relativeTolerance = positiveNumber(a, value("a relative tolerance"));
                if (options.relativeTolerance < 1e-6 || options.relativeTolerance >= 0.5)
                    throw dem::InputError("demStability: -tolerance expects a number in [1e-6, 0.5), got '" +
                                          std::string(argv[i]) + "'");
            } else {
                usage(std::cerr);
                throw dem::InputError("demStability: unknown option '" + a + "'");
            }
        }
        dem::CaseSetup setup = dem::readCaseSetup(caseDir);
        restart = dem::restartFileFor(setup, restart, "demStability");
        // The bed is analysed, not run: the a-priori checks are reported below, not enforced.
        setup.settings.allowLargeTimeStep = true;
        std::unique_ptr<dem::Simulation> sim = dem::makeSimulation(setup);
        sim->readRestart(restart);
        const dem::Simulation::TimeStepLimits limits = sim->timeStepLimits();

        std::cout << "demStability (demLib " << dem::versionString << "): " << restart << ", t = " << sim->time()
                  << " s" << std::endl;
        // A progress line per trial step, with the time left (a trial costs about 2 s per
        // thousand particles).
        const auto start = std::chrono::steady_clock::now();
        options.onTrial = [&](int trial, int expected, double dt, double growth, bool grows) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::cout << "  trial " << trial << " of about " << expected << ": dt " << std::setprecision(4) << dt
                      << " s " << (grows ? "grows" : "stable") << " (log growth per step " << growth
                      << "), elapsed " << std::lround(elapsed) << " s, about "
                      << std::lround(elapsed / trial * std::max(0, expected - trial)) << " s left" << std::endl;
        };
        if (sim->particles().empty())
            throw dem::InputError("demStability: the restart file '" + restart +
                                  "' holds no particle; expected a bed to analyse");
        const dem::BedStabilityReport r = dem::analyseBedStability(*sim, options);
        if (r.particles == 0)  // the bed has particles (checked above): none in -region
            throw dem::InputError("demStability: -region holds no particle centre of the bed (expected a box "
                                  "around some of its " + std::to_string(sim->particles().size()) + " particles)");
        std::cout << std::setprecision(4) << r.particles << " particles analysed (of " << sim->particles().size()
                  << "), " << r.particleContacts << " contacts between them, " << r.fixedParticleContacts
                  << " with particles held fixed outside the region, " << r.wallContacts
                  << " with walls; contacts per particle:";
        for (std::size_t k = 0; k < r.contactsPerParticle.size(); ++k)
            if (r.contactsPerParticle[k] > 0) std::cout << ' ' << k << ':' << r.contactsPerParticle[k];
        std::cout << "\nundamped limit 2/w_max: " << r.undampedLimit << " s\n"
                  << "stable time step of the bed: " << r.stableTimeStep << " s (relative tolerance "
                  << options.relativeTolerance << ")\n"
                  << "a-priori limits of the engine: Rayleigh " << limits.rayleigh << " s, Hertz " << limits.hertz
                  << " s";
        if (std::isfinite(limits.capillary))
            std::cout << ", wet-bed cluster " << limits.capillary << " s (" << sim->settings().maxCapillaryClusterFraction
                      << " x the cluster model's " << limits.capillary / sim->settings().maxCapillaryClusterFraction
                      << " s)";
        std::cout << "\ntime step " << r.runTimeStep << " s: "
                  << (r.stableAtRunStep ? "stable" : "a mode grows") << " (log growth per step "
                  << r.growthAtRunStep << "), " << r.runTimeStep / r.stableTimeStep << " of the bed's stable step"
                  << std::endl;
        return r.stableAtRunStep ? 0 : 3;
    } catch (const dem::InputError& e) {
        std::cerr << "Error: " << e.what() << std::endl;
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "Error: " << e.what() << std::endl;
        return 2;
    }
}
