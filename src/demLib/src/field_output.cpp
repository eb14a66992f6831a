#include "demLib/field_output.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "demLib/error.hpp"
#include "demLib/hdf5_file.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

// Writes through a temporary file and a rename: a crash mid-write leaves the
// previous version intact.
void writeAtomically(const std::string& path, const std::string& text) {
    const std::string tmp = path + ".writing";
    {
        std::ofstream out(tmp);
        out << text;
        if (!out) throw RuntimeError("cannot write '" + tmp + "'");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) throw RuntimeError("cannot rename '" + tmp + "'");
}

}  // namespace

FieldOutput::FieldOutput(std::string directory, std::string baseName, double continueFromTime)
    : directory_(std::move(directory)), baseName_(std::move(baseName)) {
    std::error_code ec;
    fs::create_directories(directory_, ec);
    if (ec) throw RuntimeError("cannot create output directory '" + directory_ + "': " + ec.message());
    indexPath_ = (fs::path(directory_) / (baseName_ + ".xdmf")).string();
    seriesPath_ = (fs::path(directory_) / (baseName_ + ".series")).string();
    std::ifstream in(seriesPath_);
    Entry e;
    while (in >> e.time >> e.step >> e.count >> e.file)
        if (continueFromTime >= 0.0 && e.time <= continueFromTime) entries_.push_back(e);
}

std::string FieldOutput::write(const Simulation& sim) { return write(sim.particles(), sim.time(), sim.stepCount()); }

std::string FieldOutput::write(const ParticleStore& p, double time, long step) {
    std::ostringstream name;
    name << baseName_ << "_" << std::setw(9) << std::setfill('0') << step << ".h5";
    const std::string file = name.str();
    const std::string path = (fs::path(directory_) / file).string();
    {
        Hdf5File f(path + ".writing", Hdf5File::Mode::Create);
        f.setAttribute("time", time);
        f.setAttribute("step", static_cast<std::int64_t>(step));
        f.sealAttributes();
        f.write("id", p.id);
        f.write("position", p.position);
        f.write("velocity", p.velocity);
        f.write("omega", p.omega);
        f.write("force", p.force);
        f.write("radius", p.radius);
        f.write("mass", p.mass);
        f.write("material", p.material);
    }
    if (std::rename((path + ".writing").c_str(), path.c_str()) != 0)
        throw RuntimeError("cannot rename '" + path + ".writing'");
    while (!entries_.empty() && entries_.back().time >= time) entries_.pop_back();
    entries_.push_back({time, step, p.size(), file});
    writeIndex();
    return path;
}

void FieldOutput::writeIndex() const {
    std::ostringstream series;
    series << std::setprecision(17);
    for (const Entry& e : entries_) series << e.time << " " << e.step << " " << e.count << " " << e.file << "\n";
    writeAtomically(seriesPath_, series.str());

    std::ostringstream x;
    x << std::setprecision(12);
    x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      << "<Xdmf Version=\"2.0\">\n <Domain>\n"
      << "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    auto vectorAttr = [&](const std::string& n, const Entry& e) {
        x << "    <Attribute Name=\"" << n << "\" AttributeType=\"Vector\" Center=\"Node\">\n"
          << "     <DataItem Dimensions=\"" << e.count << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
          << e.file << ":/" << n << "</DataItem>\n    </Attribute>\n";
    };
    auto scalarAttr = [&](const std::string& n, const Entry& e, const char* type, int precision) {
        x << "    <Attribute Name=\"" << n << "\" AttributeType=\"Scalar\" Center=\"Node\">\n"
          << "     <DataItem Dimensions=\"" << e.count << "\" NumberType=\"" << type << "\" Precision=\""
          << precision << "\" Format=\"HDF\">" << e.file << ":/" << n << "</DataItem>\n    </Attribute>\n";
    };
    for (const Entry& e : entries_) {
        // An output without particles stays in the series file but not in the
        // index: ParaView 5.11's Xdmf Reader fails on an empty grid ("Failed to
        // read data"), and one with no geometry crashes it (tests/paraview).
        if (e.count == 0) continue;
        x << "   <Grid Name=\"step" << e.step << "\" GridType=\"Uniform\">\n"
          << "    <Time Value=\"" << e.time << "\"/>\n"
          << "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << e.count << "\"/>\n"
          << "    <Geometry GeometryType=\"XYZ\">\n"
          << "     <DataItem Dimensions=\"" << e.count << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
          << e.file << ":/position</DataItem>\n    </Geometry>\n";
        vectorAttr("velocity", e);
        vectorAttr("omega", e);
        vectorAttr("force", e);
        scalarAttr("radius", e, "Float", 8);
        scalarAttr("mass", e, "Float", 8);
        scalarAttr("id", e, "Int", 8);
        scalarAttr("material", e, "Int", 4);
        x << "   </Grid>\n";
    }
    x << "  </Grid>\n </Domain>\n</Xdmf>\n";
    writeAtomically(indexPath_, x.str());
}

}  // namespace dem
