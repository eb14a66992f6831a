// The spinning barrier behind the force kernel's and the integrator's OpenMP
// regions and the thread ranks (SpinBarrier): nobody passes before everybody
// has arrived, round after round, also with more threads than cores (the
// yielding path); an abandoned wait ends; one party never waits.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "demLib/spin_barrier.hpp"

namespace {

// Each round every thread writes the round into its own slot, meets the
// others, and reads all slots: a barrier that let a thread through early
// shows it the previous round's value.  A second meeting keeps the next
// round's writes after everybody's reads.
int roundsSeenOutOfStep(int threads, int rounds, long spinsBeforeYield) {
    dem::SpinBarrier barrier(spinsBeforeYield);
    std::vector<int> slot(static_cast<std::size_t>(threads) * 16, -1);  // a cache line apart
    std::atomic<int> wrong{0};
    std::vector<std::thread> team;
    for (int t = 0; t < threads; ++t)
        team.emplace_back([&, t] {
            for (int r = 0; r < rounds; ++r) {
                slot[static_cast<std::size_t>(t) * 16] = r;
                barrier.arriveAndWait(threads);
                for (int u = 0; u < threads; ++u)
                    if (slot[static_cast<std::size_t>(u) * 16] != r) wrong.fetch_add(1);
                barrier.arriveAndWait(threads);
            }
        });
    for (auto& thread : team) thread.join();
    return wrong.load();
}

TEST(SpinBarrier, NobodyPassesBeforeAllHaveArrived) {
    EXPECT_EQ(roundsSeenOutOfStep(2, 5000, dem::SpinBarrier::defaultSpinsBeforeYield), 0);
    EXPECT_EQ(roundsSeenOutOfStep(3, 2000, dem::SpinBarrier::defaultSpinsBeforeYield), 0);
}

TEST(SpinBarrier, MoreThreadsThanCoresGetThroughByYielding) {
    // No spinning at all: every wait is the yield loop, 8 threads on the
    // machine's (here 2) cores.
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(roundsSeenOutOfStep(8, 500, 0), 0);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60.0);
}

TEST(SpinBarrier, AnAbandonedWaitEnds) {
    dem::SpinBarrier barrier;
    std::atomic<bool> abandoned{false};
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        abandoned.store(true);
    });
    // Two parties, one arrives: only the flag ends the wait.
    EXPECT_FALSE(barrier.arriveAndWait(2, &abandoned));
    stopper.join();
}

TEST(SpinBarrier, OnePartyNeverWaits) {
    dem::SpinBarrier barrier;
    for (int r = 0; r < 3; ++r) EXPECT_TRUE(barrier.arriveAndWait(1));
}

}  // namespace
