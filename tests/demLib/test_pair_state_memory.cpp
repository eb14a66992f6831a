// Memory layout of the pair state and the particle store (issue 7): contact
// history only for pairs in contact (ContactHistoryPool), the rolling spring
// only for the EPSD models, bridge volumes only with cohesion, and the external
// force allocated on first write.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "demLib/contact_history_pool.hpp"
#include "demLib/error.hpp"
#include "demLib/hdf5_file.hpp"
#include "demLib/simulation.hpp"
#include "contact_history_testing.hpp"
#include "thread_count.hpp"

namespace {

using dem::Vec3;

using dem_testing::expectHistory;
using dem_testing::history;

TEST(ContactHistoryPool, SlotsOnlyForPairsWithHistory) {
    dem::ContactHistoryPool pool;
    pool.reset(4);
    EXPECT_EQ(pool.records(), 0u);
    pool.set(1, history(1.0, 10.0));
    pool.set(3, history(3.0, 30.0));
    EXPECT_EQ(pool.records(), 2u);
    expectHistory(pool.get(0), history(0.0, 0.0));
    expectHistory(pool.get(1), history(1.0, 10.0));
    expectHistory(pool.get(3), history(3.0, 30.0));

    // A force loop: pair 1 opened (its record rests), pair 2 closed (new history).
    const int rested = pool.slots()[1];
    pool.open(1);
    EXPECT_TRUE(dem::ContactHistoryPool::isResting(pool.slots()[1]));
    std::vector<dem::ContactHistoryPool::Changes> changes(2);
    changes[1].opened.push_back({2, history(2.0, 20.0)});
    pool.commit(changes);
    EXPECT_EQ(pool.contactsWithHistory(), 2u);
    EXPECT_EQ(pool.records(), 3u);  // the resting record is kept until the next build
    expectHistory(pool.get(1), history(0.0, 0.0));
    expectHistory(pool.get(2), history(2.0, 20.0));
    // Pair 1 touches again: it takes its own record back, the pool does not grow.
    pool.set(1, history(4.0, 40.0));
    EXPECT_EQ(pool.slots()[1], rested);
    EXPECT_EQ(pool.records(), 3u);
    expectHistory(pool.get(1), history(4.0, 40.0));
    pool.open(1);

    // A list rebuild: new entry 0 is old pair 3 seen from its other particle,
    // entry 1 continues old pair 1 (resting: no history), entry 2 is new but
    // already touching, entry 3 is old pair 2.
    pool.rebuild({3, 1, -1, 2}, {1, 0, 0, 0}, {0, 0, 1, 0});
    EXPECT_EQ(pool.entries(), 4u);
    EXPECT_EQ(pool.records(), 3u);  // the resting record is dropped
    EXPECT_EQ(pool.contactsWithHistory(), 3u);
    expectHistory(pool.get(0), history(-3.0, -30.0));
    EXPECT_EQ(pool.slots()[1], -1);
    EXPECT_GE(pool.slots()[2], 0);
    expectHistory(pool.get(2), history(0.0, 0.0));
    expectHistory(pool.get(3), history(2.0, 20.0));
    // Slots are handed out in list order at a rebuild.
    EXPECT_LT(pool.slots()[0], pool.slots()[2]);
    EXPECT_LT(pool.slots()[2], pool.slots()[3]);

    // Without the rolling spring the records shrink; the shear stays.
    const std::size_t withRolling = pool.bytes();
    pool.setRolling(false);
    EXPECT_EQ(pool.stride(), 3u);
    EXPECT_LT(pool.bytes(), withRolling);
    expectHistory(pool.get(3), dem::ContactHistory{history(2.0, 0.0).shear, Vec3::Zero()});
}

dem::Simulation twoTouchingAndOneNear(dem::RollingModel rolling, dem::CohesionModel cohesion,
                                      bool vectorizedPairLaw = true) {
    dem::SimulationSettings s;
    s.forces.vectorizedPairLaw = vectorizedPairLaw;
    s.timeStep = 1e-6;
    s.gravity = Vec3::Zero();
    s.forces.rolling = rolling;
    s.forces.cohesion = cohesion;
    s.source = "test_pair_state_memory";
    const std::vector<dem::Material> mats{{"glass", 5e6, 0.3, 2500.0}};
    dem::PairCoefficients c;
    c.restitution = 0.5;
    c.friction = 0.5;
    c.rollingFriction = 0.1;
    dem::InteractionTable table(1);
    table.set(mats, 0, 0, c);
    dem::Simulation sim(s, mats, table, {});
    const double r = 1e-3;
    // 0 and 1 overlap by 1 um and slide past each other; 2 is 0.1 mm away from 1
    // (inside the skin of 0.4 mm): listed, not touching.
    sim.insert({{Vec3(0, 0, 0), r}}, 0, Vec3(0, 0.01, 0));
    sim.insert({{Vec3(2 * r - 1e-6, 0, 0), r}}, 0, Vec3(0, -0.01, 0));
    sim.insert({{Vec3(4 * r - 1e-6 + 1e-4, 0, 0), r}}, 0, Vec3::Zero());
    return sim;
}

TEST(PairStateMemory, HistoryOnlyForTouchingPairsAndOnlyTheModelsParts) {
    ThreadCount threads(1);
    dem::Simulation sim = twoTouchingAndOneNear(dem::RollingModel::EPSD2, dem::CohesionModel::None);
    sim.particles().omega[0] = Vec3(0, 0, 50.0);  // rolls on 1: the rolling spring winds up
    sim.step(20);
    const auto& list = sim.pairList();
    EXPECT_TRUE(list.stateFields().rollingSpring);
    EXPECT_FALSE(list.stateFields().bridgeVolume);
    EXPECT_TRUE(list.bridgeVolume().empty());
    ASSERT_EQ(list.pairCount(), 2u);  // (0,1) touching and (1,2) within the skin
    EXPECT_EQ(sim.lastStep().contacts.touchingPairs, 1u);
    EXPECT_EQ(list.history().contactsWithHistory(), 1u);
    const dem::PairState touching = list.state()[0];  // pair (0, 1)
    const dem::PairState near = list.state()[1];      // pair (1, 2)
    // Particle 0 moves +y relative to 1: the tangential spring stretches along +y.
    EXPECT_GT(touching.contact.shear.y(), 0.0);
    EXPECT_GT(touching.contact.rollingAngle.norm(), 0.0);
    EXPECT_EQ(near.contact.shear, Vec3::Zero());
    EXPECT_EQ(near.contact.rollingAngle, Vec3::Zero());

    // CDT keeps no rolling spring, and dry runs no bridge volumes.
    dem::Simulation cdt = twoTouchingAndOneNear(dem::RollingModel::CDT, dem::CohesionModel::None);
    cdt.step(20);
    dem::Simulation epsd2 = twoTouchingAndOneNear(dem::RollingModel::EPSD2, dem::CohesionModel::None);
    epsd2.step(20);
    EXPECT_FALSE(cdt.pairList().stateFields().rollingSpring);
    EXPECT_EQ(cdt.pairList().history().stride(), 3u);
    EXPECT_EQ(cdt.pairList().state()[0].contact.rollingAngle, Vec3::Zero());
    EXPECT_GT(cdt.pairList().state()[0].contact.shear.y(), 0.0);
    // Without spin the tangential spring does not depend on the rolling model.
    EXPECT_EQ(cdt.pairList().state()[0].contact.shear, epsd2.pairList().state()[0].contact.shear);

    // The capillary model keeps a bridge volume per listed pair.
    dem::Simulation wet = twoTouchingAndOneNear(dem::RollingModel::None, dem::CohesionModel::Capillary);
    EXPECT_TRUE(wet.pairList().stateFields().bridgeVolume);
    wet.step(1);
    EXPECT_EQ(wet.pairList().bridgeVolume().size(), wet.pairList().pairCount());
}

TEST(PairStateMemory, ContactThatOpensForgetsItsHistoryAndTakesItsRecordBackWhenItCloses) {
    for (const bool batched : {true, false}) {
        SCOPED_TRACE(batched ? "law in vector lanes" : "law per pair");
        ThreadCount threads(1);
        dem::Simulation sim = twoTouchingAndOneNear(dem::RollingModel::EPSD2, dem::CohesionModel::None, batched);
        sim.step(5);
        const dem::ContactHistoryPool& pool = sim.pairList().history();
        ASSERT_EQ(pool.contactsWithHistory(), 1u);
        const int record = pool.slot(0);
        ASSERT_GE(record, 0);
        const double shearBefore = sim.pairList().state()[0].contact.shear.norm();  // 5 steps' worth
        ASSERT_GT(shearBefore, 0.0);
        sim.particles().velocity[0] = Vec3(-0.05, 0, 0);  // 0 leaves 1: 1 um in 20 us
        sim.step(100);
        EXPECT_EQ(sim.lastStep().contacts.touchingPairs, 0u);
        EXPECT_EQ(pool.contactsWithHistory(), 0u);
        for (const dem::PairState& s : sim.pairList().state()) EXPECT_EQ(s.contact.shear, Vec3::Zero());
        EXPECT_EQ(sim.pairList().buildCount(), 1);  // still the first list: the record rests
        EXPECT_EQ(pool.slot(0), dem::ContactHistoryPool::resting(record));

        // Back into contact before the next build: the pair's springs start from
        // zero again, in its own record (the pool does not grow).
        sim.particles().velocity[0] = Vec3(0.05, 0.01, 0);
        for (int n = 0; n < 300 && sim.lastStep().contacts.touchingPairs == 0; ++n) sim.step(1);
        ASSERT_EQ(sim.lastStep().contacts.touchingPairs, 1u);
        // One step's worth of spring, not the resting record's old value.
        EXPECT_LT(sim.pairList().state()[0].contact.shear.norm(), 0.5 * shearBefore);
        sim.step(5);
        EXPECT_EQ(sim.pairList().buildCount(), 1);
        EXPECT_EQ(pool.slot(0), record);
        EXPECT_EQ(pool.records(), 1u);
        EXPECT_GT(sim.pairList().state()[0].contact.shear.norm(), 0.0);
    }
}

// Restart files keep the rolling springs as angles ("rollingAngle").  Files
// of the builds that kept them as torques hold "rollingTorque": continued when
// it is all zero (runs without EPSD/EPSD2), refused otherwise.  Such a file is
// made here by renaming the datasets of a new one.
void renameRollingDatasetsToTheTorqueForm(const std::string& path) {
    dem::Hdf5File f(path, dem::Hdf5File::Mode::Update);
    for (const std::string group : {"pairs", "wallContacts"}) {
        ASSERT_TRUE(f.exists(group + "/rollingAngle"));
        ASSERT_FALSE(f.exists(group + "/rollingTorque"));
        f.rename(group + "/rollingAngle", group + "/rollingTorque");
    }
}

TEST(PairStateRestart, OldFileWithRollingSpringTorquesIsRefusedNamingTheFile) {
    ThreadCount threads(1);
    dem::Simulation sim = twoTouchingAndOneNear(dem::RollingModel::EPSD2, dem::CohesionModel::None);
    sim.particles().omega[0] = Vec3(0, 0, 50.0);  // the rolling spring winds up
    sim.step(20);
    ASSERT_GT(sim.pairList().state()[0].contact.rollingAngle.norm(), 0.0);
    const std::string path = ::testing::TempDir() + "pair_state_old_rolling_torque.h5";
    sim.writeRestart(path);
    renameRollingDatasetsToTheTorqueForm(path);

    dem::Simulation continued = twoTouchingAndOneNear(dem::RollingModel::EPSD2, dem::CohesionModel::None);
    try {
        continued.readRestart(path);
        ADD_FAILURE() << "a restart file with non-zero rolling spring torques was read";
    } catch (const dem::InputError& e) {
        const std::string what = e.what();
        std::printf("refused: %s\n", what.c_str());
        EXPECT_NE(what.find(path), std::string::npos) << what;
        EXPECT_NE(what.find("pairs/rollingTorque"), std::string::npos) << what;
        EXPECT_NE(what.find("rolling springs as torques"), std::string::npos) << what;
        EXPECT_NE(what.find("continue the run with the build that wrote"), std::string::npos) << what;
    }
    std::remove(path.c_str());
}

TEST(PairStateRestart, OldFileWithZeroRollingTorquesContinuesBitwise) {
    ThreadCount threads(1);
    // CDT keeps no rolling spring: its files hold zeros in the rolling datasets.
    dem::Simulation first = twoTouchingAndOneNear(dem::RollingModel::CDT, dem::CohesionModel::None);
    first.particles().omega[0] = Vec3(0, 0, 50.0);
    first.step(20);
    ASSERT_GT(first.pairList().state()[0].contact.shear.norm(), 0.0);
    const std::string path = ::testing::TempDir() + "pair_state_old_zero_torque.h5";
    first.writeRestart(path);
    renameRollingDatasetsToTheTorqueForm(path);
    first.step(30);

    dem::Simulation continued = twoTouchingAndOneNear(dem::RollingModel::CDT, dem::CohesionModel::None);
    continued.readRestart(path);
    EXPECT_EQ(continued.stepCount(), 20);
    EXPECT_EQ(continued.pairList().history().contactsWithHistory(), 1u);
    continued.step(30);
    for (std::size_t i = 0; i < first.particles().size(); ++i) {
        EXPECT_EQ(continued.particles().position[i], first.particles().position[i]) << "particle " << i;
        EXPECT_EQ(continued.particles().velocity[i], first.particles().velocity[i]) << "particle " << i;
        EXPECT_EQ(continued.particles().omega[i], first.particles().omega[i]) << "particle " << i;
    }
    std::remove(path.c_str());
}

TEST(ExternalForceField, AllocatedOnFirstWriteAndFollowsTheParticles) {
    dem::ParticleStore p;
    for (int i = 0; i < 3; ++i) p.add(i, Vec3(i, 0, 0), Vec3::Zero(), 1e-3, 2500.0, 0);
    const std::size_t dryBytes = p.bytesPerParticle();
    EXPECT_FALSE(p.externalForce.allocated());
    EXPECT_EQ(p.externalForce.size(), 3u);
    const dem::ParticleStore& view = p;
    EXPECT_EQ(view.externalForce[1], Vec3::Zero());
    EXPECT_FALSE(p.externalForce.allocated());  // reading does not allocate

    p.externalForce[2] = Vec3(1, 2, 3);
    EXPECT_TRUE(p.externalForce.allocated());
    EXPECT_EQ(p.bytesPerParticle(), dryBytes + sizeof(Vec3));
    EXPECT_EQ(view.externalForce[0], Vec3::Zero());
    p.permute({2, 0, 1});
    EXPECT_EQ(view.externalForce[0], Vec3(1, 2, 3));
    EXPECT_EQ(p.id[0], 2);
    p.compact({0, 1, 1});
    EXPECT_EQ(p.externalForce.size(), 2u);
    EXPECT_EQ(view.externalForce[0], Vec3::Zero());
    p.add(7, Vec3::Zero(), Vec3::Zero(), 1e-3, 2500.0, 0);
    EXPECT_EQ(p.externalForce.size(), 3u);
    EXPECT_EQ(view.externalForce[2], Vec3::Zero());
}

TEST(ExternalForceField, AcceleratesTheParticleInASimulation) {
    ThreadCount threads(1);
    dem::Simulation sim = twoTouchingAndOneNear(dem::RollingModel::None, dem::CohesionModel::None);
    const double m = sim.particles().mass[2];
    const double a = 3.0;  // m/s^2 along z on the free particle 2
    sim.particles().externalForce[2] = Vec3(0, 0, m * a);
    sim.step(10);
    EXPECT_NEAR(sim.particles().velocity[2].z(), a * 10 * sim.timeStep(), 1e-12);
    EXPECT_EQ(sim.particles().velocity[0].z(), 0.0);
}

}  // namespace
