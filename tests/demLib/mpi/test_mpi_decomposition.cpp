// demLib's MPI domain decomposition against the serial engine, run under
// mpirun (any rank count >= 1; ctest uses 2).  This program, as OpenFOAM's
// argList would, initialises MPI itself and hands demLib MPI_COMM_WORLD.
// The checks are in ../decomposition_checks.hpp (shared with the thread ranks).
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "../decomposition_checks.hpp"
#include "../thread_count.hpp"
#include "demLib/communicator_mpi.hpp"
#include "demLib/ghost_exchange.hpp"
#include "demLib/simulation.hpp"

namespace {

using dem::Vec3;
using namespace decomposition_checks;

dem::Communicator world() { return dem::communicatorFromMpi(MPI_COMM_WORLD); }

TEST(MpiCommunicator, WrapsTheCallersCommunicator) {
    int rank = -1, size = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    const dem::Communicator c = world();
    EXPECT_TRUE(c.usesMpi());
    EXPECT_EQ(c.rank(), rank);
    EXPECT_EQ(c.size(), size);
    collectivesAgree(c);
    knownSizeExchangeAgrees(c);
}

TEST(MpiDecomposition, GhostsGiveTheSerialContactForces) {
    OneThread one;
    ghostsGiveTheSerialContactForces(world());
}

TEST(MpiDecomposition, MultiStepRunFollowsTheSerialRun) {
    OneThread one;
    multiStepRunFollowsTheSerialRun(world());
}

TEST(MpiDecomposition, WetRunSharesTheSerialLiquid) {
    OneThread one;
    wetRunSharesTheSerialLiquid(world());
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);  // the caller's job, never demLib's
    ::testing::InitGoogleTest(&argc, argv);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank != 0) {
        // One report, from rank 0; failures on any rank still fail the run.
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    int failed = RUN_ALL_TESTS() != 0 ? 1 : 0;
    int anyFailed = 0;
    MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return anyFailed;
}
