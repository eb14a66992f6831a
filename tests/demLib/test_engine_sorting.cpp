// Spatial sorting of the particles (Simulation::updatePairList): it must change
// nothing but the storage order -- every particle keeps its identity, its wall
// contact history and its pair history, and restarts stay bitwise identical.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "demLib/simulation.hpp"

namespace {

using dem::Vec3;

dem::Simulation makeCase(std::size_t sortFrom, bool interacting) {
    const std::vector<dem::Material> mats{{"glass", 5e6, 0.3, 2500.0}, {"steel", 2e7, 0.3, 7800.0}};
    dem::InteractionTable table(2);
    dem::PairCoefficients c;
    c.restitution = 0.5;
    c.friction = 0.5;
    c.rollingFriction = 0.1;
    table.set(mats, 0, 0, c);
    table.set(mats, 0, 1, c);
    table.set(mats, 1, 1, c);
    dem::SimulationSettings s;
    s.timeStep = 1e-5;
    s.forces.rolling = dem::RollingModel::EPSD2;
    s.spatialSortMinParticles = sortFrom;
    dem::WallMotion sliding;
    sliding.addTranslation(0.0, 1.0, Vec3(0.02, 0.0, 0.0));
    std::vector<dem::Wall> walls{{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), sliding, 1}};
    dem::Simulation sim(s, mats, table, walls);
    // A 20 x 20 lattice in random order: interacting spheres touch their
    // neighbours, the others are 3 diameters apart and meet only the floor.
    const double d = 1e-3, spacing = interacting ? 0.98 * d : 3.0 * d;
    std::vector<dem::InsertedParticle> q;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
            q.push_back({Vec3(i * spacing, j * spacing, 0.5 * d + 1e-4 * ((i * 7 + j * 3) % 5)), 0.5 * d});
    std::shuffle(q.begin(), q.end(), std::mt19937(4));
    sim.insert(q, 0, Vec3(0.0, 0.0, -0.05), "sorting test");
    return sim;
}

std::map<std::int64_t, std::pair<Vec3, Vec3>> byId(const dem::Simulation& sim) {
    std::map<std::int64_t, std::pair<Vec3, Vec3>> m;
    const dem::ParticleStore& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i) m[p.id[i]] = {p.position[i], p.velocity[i]};
    return m;
}

}  // namespace

TEST(EngineSorting, ChangesOnlyTheStorageOrder) {
    // Particles that meet only the (sliding) floor: each one's forces are summed in
    // the same order whatever the storage order, so sorted and unsorted runs must
    // agree exactly, particle by particle.
    dem::Simulation sorted = makeCase(0, false);
    dem::Simulation unsorted = makeCase(1u << 30, false);
    sorted.step(3000);
    unsorted.step(3000);
    ASSERT_GT(sorted.pairList().buildCount(), 0);
    bool reordered = false;
    for (std::size_t i = 0; i < sorted.particles().size(); ++i)
        reordered |= sorted.particles().id[i] != unsorted.particles().id[i];
    EXPECT_TRUE(reordered) << "the sort should have changed the storage order";
    const auto a = byId(sorted), b = byId(unsorted);
    ASSERT_EQ(a.size(), 400u);
    for (const auto& [id, state] : a) {
        EXPECT_EQ(state.first, b.at(id).first) << "particle " << id;
        EXPECT_EQ(state.second, b.at(id).second) << "particle " << id;
    }
    // The floor's contact history (dragged along at 0.02 m/s) came along.
    EXPECT_GT(sorted.wallContacts().records().size(), 390u);
}

TEST(EngineSorting, SortedRunRestartsBitwiseIdentically) {
    dem::Simulation first = makeCase(0, true);
    first.step(2000);
    const std::string path = ::testing::TempDir() + "sorting_restart.h5";
    first.writeRestart(path);
    first.step(1500);
    dem::Simulation second = makeCase(0, true);
    second.readRestart(path);
    second.step(1500);
    ASSERT_EQ(first.particles().size(), second.particles().size());
    for (std::size_t i = 0; i < first.particles().size(); ++i) {
        ASSERT_EQ(first.particles().id[i], second.particles().id[i]);
        ASSERT_EQ(first.particles().position[i], second.particles().position[i]);
        ASSERT_EQ(first.particles().velocity[i], second.particles().velocity[i]);
        ASSERT_EQ(first.particles().omega[i], second.particles().omega[i]);
    }
    EXPECT_GT(first.lastStep().contacts.touchingPairs, 300u);
}
