// Particle field output (demLib/field_output.hpp): every output in the series
// file, only those holding particles in the XDMF index that ParaView opens
// (its Xdmf Reader fails on an empty grid; tests/paraview opens the index).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "demLib/field_output.hpp"
#include "demLib/particle_store.hpp"

namespace {

namespace fs = std::filesystem;

std::string fileText(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

}  // namespace

TEST(FieldOutput, AnOutputWithoutParticlesIsInTheSeriesButNotInTheParaViewIndex) {
    const fs::path dir = fs::temp_directory_path() / ("demLib-fieldOutput-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    dem::ParticleStore p;
    {
        dem::FieldOutput out(dir.string());
        out.write(p, 0.0, 0);                                     // before the insertion
        p.add(7, {0.0, 0.0, 0.01}, {0.0, 0.0, -1.0}, 1e-3, 2650.0, 0);
        p.add(9, {0.0, 0.005, 0.01}, {0.0, 0.0, 0.0}, 2e-3, 2650.0, 0);
        out.write(p, 0.01, 100);
        p = dem::ParticleStore{};
        out.write(p, 0.02, 200);                                  // all gone
    }
    const std::string series = fileText(dir / "particles.series");
    EXPECT_EQ(series, "0 0 0 particles_000000000.h5\n0.01 100 2 particles_000000100.h5\n"
                      "0.02 200 0 particles_000000200.h5\n");
    for (const char* file : {"particles_000000000.h5", "particles_000000100.h5", "particles_000000200.h5"})
        EXPECT_TRUE(fs::exists(dir / file)) << file;
    const std::string index = fileText(dir / "particles.xdmf");
    EXPECT_EQ(occurrences(index, "GridType=\"Uniform\""), 1u) << index;
    EXPECT_NE(index.find("<Time Value=\"0.01\"/>"), std::string::npos) << index;
    EXPECT_NE(index.find("particles_000000100.h5:/position"), std::string::npos) << index;
    EXPECT_EQ(index.find("particles_000000000.h5"), std::string::npos) << index;
    EXPECT_EQ(index.find("particles_000000200.h5"), std::string::npos) << index;
    EXPECT_EQ(index.find("NumberOfElements=\"0\""), std::string::npos) << index;

    // A continued run keeps the index's earlier entries and adds its own
    {
        dem::FieldOutput out(dir.string(), "particles", 0.015);
        p.add(11, {0.0, 0.0, 0.02}, {0.0, 0.0, 0.0}, 1e-3, 2650.0, 0);
        out.write(p, 0.03, 300);
    }
    const std::string continued = fileText(dir / "particles.xdmf");
    EXPECT_EQ(occurrences(continued, "GridType=\"Uniform\""), 2u) << continued;
    EXPECT_EQ(occurrences(fileText(dir / "particles.series"), "\n"), 3u);
    fs::remove_all(dir);
}
