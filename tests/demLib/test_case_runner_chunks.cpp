// CaseRunner::advanceTo hands the engine the steps up to the runner's next
// event (an insertion wave, field or summary output, the target time) in one
// call, which fuses each step's closing half kick with the next step's drift.
// A run advanced one step per call must give the same bits: particle states,
// summary lines and field files.  Both runs use 1 and 2 threads.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "demLib/case_runner.hpp"
#include "demLib/case_setup.hpp"
#include "demLib/simulation.hpp"
#include "thread_count.hpp"

namespace {

namespace fs = std::filesystem;

// A box filled in waves (the region holds only part of the particles at a
// time; they leave it at 1.5 m/s), with a side wall that moves in during the
// run, field output every 0.0105 s and a summary line every 0.007 s: events
// that fall inside the chunks.
constexpr const char* demProperties = R"(FoamFile { version 2.0; format ascii; class dictionary; object demProperties; }
simulation
{
    timeStep    1e-5;
    endTime     0.03;
    gravity     (0 0 -9.81);
    domain      { min (-0.02 -0.02 -0.01); max (0.02 0.02 0.05); }
}
contactModel { normal hertz; tangential history; rolling epsd2; }
materials
{
    sand  { youngsModulus 5e6; poissonRatio 0.3; density 2650; }
    steel { youngsModulus 7e10; poissonRatio 0.3; density 7800; }
}
interactions
{
    sand-sand   { restitution 0.1; friction 0.7; rollingFriction 0.5; }
    sand-steel  { restitution 0.15; friction 0.61; rollingFriction 0.5; }
    steel-steel { restitution 0.5; friction 0.5; rollingFriction 0.0; }
}
walls
{
    floor { type plane; material steel; point (0 0 0); normal (0 0 1); }
    xLow  { type plane; material steel; point (-0.006 0 0); normal (1 0 0); }
    xHigh { type plane; material steel; point (0.006 0 0); normal (-1 0 0); }
    yLow  { type plane; material steel; point (0 -0.006 0); normal (0 1 0); }
    yHigh { type plane; material steel; point (0 0.006 0); normal (0 -1 0); }
    pusher
    {
        type plane; material steel; point (0.0065 0 0); normal (-1 0 0);
        motion { in { type translate; start 0.01; end 0.03; velocity (-0.1 0 0); } }
    }
}
insertion
{
    sand
    {
        material     sand;
        count        300;
        diameter     1.5e-3;
        region       { type box; min (-0.005 -0.005 0.02); max (0.005 0.005 0.023); }
        velocity     (0 0 -1.5);
        packing      random;
        seed         3;
        waveInterval 0.004;
    }
}
output
{
    fieldInterval   0.0105;
    logInterval     0.007;
}
)";

std::string fileText(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

struct Finished {
    std::unique_ptr<dem::CaseRunner> runner;
    std::size_t particlesAfterFirstStep = 0;
};

Finished run(const fs::path& dir, bool oneStepPerCall) {
    fs::remove_all(dir);
    fs::create_directories(dir / "constant");
    std::ofstream(dir / "constant" / "demProperties") << demProperties;
    dem::RunOptions options;
    options.progressInterval = 0.0;
    static std::ostringstream quiet;
    Finished f;
    f.runner = std::make_unique<dem::CaseRunner>(dem::readCaseSetup(dir.string()), options, quiet);
    dem::CaseRunner& r = *f.runner;
    const double dt = r.simulation().timeStep();
    if (oneStepPerCall) {
        for (long k = 1; r.simulation().time() < r.setup().endTime - 0.5 * dt; ++k) {
            r.advanceTo(static_cast<double>(k) * dt);
            EXPECT_EQ(r.simulation().stepCount(), k) << "one step per advanceTo call";
            if (k == 1) f.particlesAfterFirstStep = r.simulation().particles().size();
        }
    } else {
        r.runToEnd();
    }
    r.finish();
    return f;
}

void expectSameRuns(int threads) {
    ThreadCount scope(threads);
    // Per process and thread count: two test runs on one machine must not share it.
    const fs::path base = fs::temp_directory_path() /
                          ("demlib_chunks_" + std::to_string(::getpid()) + "_" + std::to_string(threads));
    const Finished chunked = run(base / "chunked", false);
    const Finished single = run(base / "single", true);
    const dem::ParticleStore& a = chunked.runner->simulation().particles();
    const dem::ParticleStore& b = single.runner->simulation().particles();
    // The case exercises waves: not all particles fit at the first insertion.
    EXPECT_LT(single.particlesAfterFirstStep, 300u);
    ASSERT_EQ(a.size(), 300u) << "all waves inserted";
    ASSERT_EQ(b.size(), a.size());
    EXPECT_EQ(chunked.runner->simulation().stepCount(), single.runner->simulation().stepCount());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a.id[i] != b.id[i] || a.position[i] != b.position[i] || a.velocity[i] != b.velocity[i] ||
            a.omega[i] != b.omega[i])
            ++differ;
    EXPECT_EQ(differ, 0u) << "particles whose state differs between chunked and single steps";
    // The moving wall pushed into the bed (contacts with it), so its motion is covered.
    std::size_t onPusher = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        onPusher += a.position[i].x() + a.radius[i] > 0.0065 - 0.1 * (0.03 - 0.01);
    EXPECT_GT(onPusher, 5u) << "particles touching the moving wall at the end";
    const std::string summaryA = fileText(base / "chunked" / "dem" / "summary.csv");
    EXPECT_GT(std::count(summaryA.begin(), summaryA.end(), '\n'), 4);
    EXPECT_EQ(summaryA, fileText(base / "single" / "dem" / "summary.csv"));
    EXPECT_EQ(fileText(base / "chunked" / "dem" / "particles.xdmf"), fileText(base / "single" / "dem" / "particles.xdmf"));
    fs::remove_all(base);
}

TEST(CaseRunner, ChunkedStepsGiveTheSingleStepRunBitwiseOneThread) { expectSameRuns(1); }
TEST(CaseRunner, ChunkedStepsGiveTheSingleStepRunBitwiseTwoThreads) { expectSameRuns(2); }

}  // namespace
