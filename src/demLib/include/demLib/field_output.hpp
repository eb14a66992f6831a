#pragma once
// Particle field output: one HDF5 file per output time (id, position, velocity,
// angular velocity, radius, force, material, ...) and an XDMF index beside
// them, so that ParaView opens the whole time series from one file.
#include <string>
#include <vector>

#include "demLib/simulation.hpp"

namespace dem {

class FieldOutput {
public:
    // Writes into `directory` (created if missing) as <baseName>_<step>.h5,
    // listed in <baseName>.series (every output) and <baseName>.xdmf (the
    // outputs that hold particles: ParaView's index).  An existing index is
    // continued: entries later than `continueFromTime` are dropped from it (a
    // restarted run rewrites them), earlier ones are kept.
    FieldOutput(std::string directory, std::string baseName = "particles",
                double continueFromTime = -1.0);

    // Writes the current state; returns the HDF5 file's path.
    std::string write(const Simulation& simulation);
    // The same for particles gathered elsewhere (e.g. from MPI ranks).
    std::string write(const ParticleStore& particles, double time, long step);

    const std::string& indexPath() const { return indexPath_; }

    struct Entry {
        double time;
        long step;
        std::size_t count;
        std::string file;  // relative to the directory
    };
    const std::vector<Entry>& entries() const { return entries_; }

private:
    void writeIndex() const;
    std::string directory_;
    std::string baseName_;
    std::string indexPath_;
    std::string seriesPath_;
    std::vector<Entry> entries_;
};

}  // namespace dem
