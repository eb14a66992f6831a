#pragma once
// Reads a case's constant/demProperties (OpenFOAM dictionary syntax, see
// docs/input-format.md and docs/case-reference.md) into the engine's
// configuration structs.  Every keyword is checked: a missing, misspelt or
// out-of-range one is an InputError naming the file, the line, the keyword and
// what was expected.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demLib/coarse_grain.hpp"
#include "demLib/dictionary.hpp"
#include "demLib/insertion.hpp"
#include "demLib/simulation.hpp"
#include "demLib/size_distribution.hpp"

namespace dem {

// One insertion block: a population drawn from a size distribution and placed
// in a region at a given time.
struct InsertionSpec {
    std::string name;
    int materialIndex = 0;
    double time = 0.0;
    std::shared_ptr<Region> region;
    std::shared_ptr<SizeDistribution> distribution;
    InsertionRequest request;
    // Particles listed explicitly ('positions' + 'diameter'), placed as given.
    std::vector<InsertedParticle> explicitParticles;
    // > 0: a population larger than the region holds at once is inserted in
    // waves this far apart in time (each wave fills the free lattice sites).
    double waveInterval = 0.0;
    std::string context;  // "file: insertion/<name>" for messages
};

// A named region whose particle mass is logged (e.g. the die).
struct MonitorRegion {
    std::string name;
    std::shared_ptr<Region> region;
};

struct OutputSpec {
    std::string directory = "dem";   // relative to the case
    double fieldInterval = 0.0;      // HDF5/XDMF particle fields (0: only at the end)
    double logInterval = 0.0;        // summary.csv line
    double restartInterval = 0.0;    // restart file (0: only at the end)
    std::vector<MonitorRegion> regions;
};

struct CaseSetup {
    std::string caseDir;
    std::string propertiesFile;
    SimulationSettings settings;
    std::vector<Material> materials;
    InteractionTable interactions;
    std::vector<Wall> walls;
    std::vector<InsertionSpec> insertions;
    OutputSpec output;
    double endTime = 0.0;
    double waterContent = 0.0;  // > 0 with the capillary model
    // The water is added at this time [s] (0: with the particles, each insertion
    // wetted as it comes): the paper fills its shoe dry and then conditions the
    // bed with humid air, so that bridges form in a poured frictional packing
    // (docs/capillary-model.md, liquid coordination).
    double wettingTime = 0.0;
    CoarseGrainSettings coarseGrain;

    int materialIndex(const std::string& name) const;  // -1 if unknown
};

// Reads <caseDir>/constant/demProperties.  Relative file names inside (STL
// walls) are relative to the case directory.
CaseSetup readCaseSetup(const std::string& caseDir);

// Reads from an already parsed dictionary (used by tests and by diefillFoam).
CaseSetup readCaseSetup(const Dictionary& dict, const std::string& caseDir);

// Builds the simulation of a case (no particles inserted yet).
std::unique_ptr<Simulation> makeSimulation(const CaseSetup& setup);

// The diameters of an insertion block's whole population (deterministic from its seed).
std::vector<double> drawPopulation(const InsertionSpec& spec);

// The number of particles an insertion will place, expected before it is drawn:
// the count, the listed particles, or the mass over the mean particle mass.
double expectedParticleCount(const InsertionSpec& spec);

// Places diameters[first...] in the block's region, avoiding the particles
// already in `simulation` and its walls, and inserts them.  Returns how many
// were placed: all of them, or (with a wave interval) those that fit now.
// existing: the particles the new ones must not overlap (default: those the
// simulation holds; with a domain decomposition the caller gathers them).
std::size_t performInsertion(Simulation& simulation, const InsertionSpec& spec,
                             const std::vector<double>& diameters, std::size_t first = 0,
                             const ExistingParticles* existing = nullptr);
// The whole population at once.
inline std::size_t performInsertion(Simulation& simulation, const InsertionSpec& spec) {
    return performInsertion(simulation, spec, drawPopulation(spec));
}

// Mass of the particles whose centre lies in `region`.
double massInRegion(const ParticleStore& particles, const Region& region);

}  // namespace dem
