#pragma once
// Ranks as threads of one process: the shared state behind a thread-group
// dem::Communicator (Communicator::runThreadGroup).  Each rank runs its own
// Simulation on its own arrays, exactly as an MPI rank does; the collectives
// meet here instead of in MPI.  Why: with OpenMP threads on one Simulation the
// two cores of the benchmark machine share every particle array and give
// 1.7x; two ranks of the domain decomposition give 1.9x (docs/performance.md,
// round 8).
//
// Every collective is one barrier over slots of the phase it belongs to; the
// slots alternate between two phases, so a rank that runs ahead into the next
// collective cannot overwrite what a slower rank still reads from this one
// (to reach the collective after that it must pass a barrier the slower rank
// only enters after reading).
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "demLib/spin_barrier.hpp"

namespace dem {

enum class ReduceOp { sum, min, max, logicalOr };

class ThreadGroup {
public:
    explicit ThreadGroup(int ranks);

    int size() const { return size_; }

    // Collectives (all ranks call them in the same order).  Reductions combine
    // the ranks' values in rank order, so every rank gets the same bits
    // (logicalOr: of integers, non-zero is true).
    double reduce(int rank, double value, ReduceOp op);
    std::int64_t reduce(int rank, std::int64_t value, ReduceOp op);
    std::vector<std::vector<char>> exchange(int rank, const std::vector<std::vector<char>>& sendTo);

    // A rank stopped with an error: ranks waiting in a collective, now or
    // later, throw RuntimeError instead of waiting for it forever.
    void abandon() { abandoned_.store(true, std::memory_order_release); }

private:
    // Cache-line sized so that ranks writing their own slot do not share a line.
    struct alignas(64) Slot {
        double real = 0.0;
        std::int64_t integer = 0;
    };
    template <class T>
    T reduceIn(int rank, T value, T Slot::*field, ReduceOp op);
    // Enters the barrier of the next collective; returns its phase (0 or 1).
    int arriveAndWait(int rank);

    int size_;
    SpinBarrier barrier_;
    std::atomic<bool> abandoned_{false};
    struct alignas(64) Calls {
        std::uint64_t entered = 0;  // collectives this rank entered (their parity is the phase)
    };
    std::vector<Calls> calls_;  // per rank
    std::vector<Slot> slots_[2];        // per phase, per rank
    // mail_[phase][to * size + from]: what `from` sent to `to`.
    std::vector<std::vector<char>> mail_[2];
};

}  // namespace dem
