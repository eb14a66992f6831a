// Spatial ordering of particles and the particle-wall candidate list.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>

#include "demLib/particle_reordering.hpp"
#include "demLib/particle_wall_broad_search.hpp"
#include "demLib/simulation.hpp"
#include "sand_without_gravity.hpp"

using dem::Vec3;

namespace {

// Checks that order is a permutation that visits the cells in the key order
// given (cell coordinates counted from the particles' lower corner, as the
// grid does), each cell as one run, old indices ascending inside a cell.
template <class CellKey>
void expectCellOrder(const std::vector<Vec3>& x, const std::vector<int>& order, double cell, CellKey cellKey) {
    ASSERT_EQ(order.size(), x.size());
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (int k = 0; k < static_cast<int>(sorted.size()); ++k) ASSERT_EQ(sorted[k], k);
    Vec3 lo = x[0];
    for (const Vec3& p : x) lo = lo.cwiseMin(p);
    auto key = [&](int i) {
        const Vec3 r = (x[i] - lo) / cell;
        return cellKey(static_cast<long>(r.x()), static_cast<long>(r.y()), static_cast<long>(r.z()));
    };
    std::set<long> finished;
    for (std::size_t k = 1; k < order.size(); ++k) {
        ASSERT_LE(key(order[k - 1]), key(order[k]));
        if (key(order[k - 1]) != key(order[k])) {
            ASSERT_TRUE(finished.insert(key(order[k - 1])).second);
        }
    }
    for (std::size_t k = 1; k < order.size(); ++k)
        if (key(order[k - 1]) == key(order[k])) {
            EXPECT_LT(order[k - 1], order[k]);
        }
    const std::vector<int> inverse = dem::inversePermutation(order);
    for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(inverse[order[k]], static_cast<int>(k));
}

std::vector<Vec3> randomBox(const Vec3& extent, int count) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3> x(count);
    for (Vec3& p : x) p = Vec3(extent.x() * u(rng), extent.y() * u(rng), extent.z() * u(rng));
    return x;
}

}  // namespace

TEST(SpatialOrder, TallBoxKeepsZYXOrder) {
    const std::vector<Vec3> x = randomBox(Vec3(0.3, 0.5, 1.0), 5000);
    const std::vector<int> order = dem::spatialOrder(x, 0.1);
    expectCellOrder(x, order, 0.1, [](long cx, long cy, long cz) { return (cz * 100 + cy) * 100 + cx; });
}

TEST(SpatialOrder, LongestAxisIsSlowestShortestFastest) {
    // A bed wider than deep: x longest, then z, then y.  (With z slowest the
    // first assertion of expectCellOrder fails.)
    const std::vector<Vec3> x = randomBox(Vec3(1.0, 0.3, 0.6), 5000);
    const std::vector<int> order = dem::spatialOrder(x, 0.1);
    expectCellOrder(x, order, 0.1, [](long cx, long cy, long cz) { return (cx * 100 + cz) * 100 + cy; });
}

TEST(SpatialOrder, ScatteredParticlesDoNotBlowUpTheGrid) {
    std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(1e3, 1e3, 1e3), Vec3(1e-3, 0, 0)};
    const std::vector<int> order = dem::spatialOrder(x, 1e-3);  // 1e18 cells without the cap
    ASSERT_EQ(order.size(), 3u);
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<int>{0, 1, 2}));  // a permutation
    // The two particles 1 mm apart are neighbours in the order, the far one at an end.
    const auto far = std::find(order.begin(), order.end(), 1) - order.begin();
    EXPECT_TRUE(far == 0 || far == 2) << far;
}

TEST(ParticleWallCandidates, ListsStaticWallsWithinReachAndAllMovingWalls) {
    dem::ParticleStore p;
    p.add(0, Vec3(0, 0, 0.0012), Vec3::Zero(), 0.001, 2500, 0);  // 0.2 mm above the floor
    p.add(1, Vec3(0, 0, 0.0050), Vec3::Zero(), 0.001, 2500, 0);  // 4 mm above
    p.add(2, Vec3(0.0095, 0, 0.0011), Vec3::Zero(), 0.001, 2500, 0);  // near the floor and the side wall
    std::vector<dem::Wall> walls;
    walls.push_back({"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), dem::WallMotion(), 0});
    walls.push_back({"side", dem::PlaneWall(Vec3(0.01, 0, 0), -Vec3::UnitX()), dem::WallMotion(), 0});
    dem::WallMotion lift;
    lift.addTranslation(0.0, 1.0, Vec3(0, 0, 0.01));
    walls.push_back({"lid", dem::PlaneWall(Vec3(0, 0, 0.02), -Vec3::UnitZ()), lift, 0});
    dem::ParticleWallCandidates c;
    c.build(p, walls, 0.0, 0.0005);
    ASSERT_EQ(c.offsets().size(), 4u);
    auto listed = [&](int i) {
        return std::vector<int>(c.walls().begin() + c.offsets()[i], c.walls().begin() + c.offsets()[i + 1]);
    };
    EXPECT_EQ(listed(0), std::vector<int>({0}));      // floor within 1 mm + 0.5 mm
    EXPECT_TRUE(listed(1).empty());                   // 4 mm from the floor, 10 mm from the side
    EXPECT_EQ(listed(2), std::vector<int>({0, 1}));   // floor and side wall
    EXPECT_EQ(c.movingWalls(), std::vector<int>({2}));  // the lid moves: checked every step
}

TEST(WallMotion, TellsWhenItMovesAndWhenThatChanges) {
    dem::WallMotion m;
    m.addTranslation(1.0, 2.0, Vec3(0, 0, -0.01));
    m.addRotation(2.0, 3.0, Vec3::Zero(), Vec3::UnitZ(), 0.5);  // adjacent: moves through t = 2
    m.addTranslation(4.0, 5.0, Vec3(0.01, 0, 0));
    EXPECT_FALSE(m.isMovingAt(0.5));
    EXPECT_TRUE(m.isMovingAt(1.0));
    EXPECT_TRUE(m.isMovingAt(2.0));
    EXPECT_FALSE(m.isMovingAt(3.0));
    EXPECT_FALSE(m.isMovingAt(5.0));
    EXPECT_EQ(m.nextChangeAfter(0.5), 1.0);
    EXPECT_EQ(m.nextChangeAfter(1.0), 2.0);
    EXPECT_EQ(m.nextChangeAfter(2.5), 3.0);
    EXPECT_EQ(m.nextChangeAfter(3.0), 4.0);
    EXPECT_EQ(m.nextChangeAfter(4.5), 5.0);
    EXPECT_EQ(m.nextChangeAfter(5.0), std::numeric_limits<double>::infinity());
    EXPECT_EQ(dem::WallMotion().nextChangeAfter(0.0), std::numeric_limits<double>::infinity());
}

TEST(ParticleWallCandidates, WallAtRestBetweenSegmentsIsListedUntilItMoves) {
    // A die wall that rests, is lowered on [1, 2) s, and rests again: at rest it
    // is searched near the particles only; under way, for every particle.
    dem::ParticleStore p;
    p.add(0, Vec3(0, 0, 0.0012), Vec3::Zero(), 0.001, 2500, 0);  // 0.2 mm from the wall
    p.add(1, Vec3(0, 0, 0.0050), Vec3::Zero(), 0.001, 2500, 0);  // 4 mm from it
    dem::WallMotion lowered;
    lowered.addTranslation(1.0, 2.0, Vec3(0, 0, -0.01));
    std::vector<dem::Wall> walls{{"die", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), lowered, 0}};
    dem::ParticleWallCandidates c;
    auto listed = [&](int i) {
        return std::vector<int>(c.walls().begin() + c.offsets()[i], c.walls().begin() + c.offsets()[i + 1]);
    };
    c.build(p, walls, 0.5, 0.0005);
    EXPECT_EQ(listed(0), std::vector<int>({0}));
    EXPECT_TRUE(listed(1).empty());
    EXPECT_TRUE(c.movingWalls().empty());
    EXPECT_EQ(c.validUntil(), 1.0);
    c.build(p, walls, 1.5, 0.0005);
    EXPECT_TRUE(listed(0).empty());
    EXPECT_EQ(c.movingWalls(), std::vector<int>({0}));
    EXPECT_EQ(c.validUntil(), 2.0);
    c.build(p, walls, 2.5, 0.0005);  // 10 mm lower now: near neither particle
    EXPECT_TRUE(listed(0).empty());
    EXPECT_TRUE(c.movingWalls().empty());
    EXPECT_EQ(c.validUntil(), std::numeric_limits<double>::infinity());
}

TEST(ParticleWallCandidates, SimulationSearchesAWallFromTheStepItStartsMoving) {
    // One sphere at rest without gravity never moves far enough to rebuild its
    // lists; a wall 4 mm away rests until 1 ms and then runs into it at 2 m/s
    // (contact from 3 ms).  Listed as at rest at the start, the wall is found
    // only because the lists are built again when it starts moving.
    dem::WallMotion approach;
    approach.addTranslation(1e-3, 1.0, Vec3(-2.0, 0, 0));
    dem::Simulation sim = sandWithoutGravity({{"pusher", dem::PlaneWall(Vec3(0.005, 0, 0), -Vec3::UnitX()), approach, 0}});
    sim.insert({{Vec3::Zero(), 0.001}}, 0, Vec3::Zero());
    sim.step(2900);  // to 2.9 ms
    EXPECT_EQ(sim.pairList().buildCount(), 1);
    EXPECT_EQ(sim.particles().velocity[0].x(), 0.0);
    sim.step(2100);  // to 5 ms
    // Pushed ahead of the wall: at least the wall's speed (about 1.5x it for e = 0.5).
    EXPECT_LT(sim.particles().velocity[0].x(), -2.0);
}
