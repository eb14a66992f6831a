#pragma once
// A barrier for the threads of one parallel region (an OpenMP team, the ranks
// of a ThreadGroup) that spins, then yields, and never sleeps.
//
// Why not OpenMP's own barrier: GOMP waits GOMP_SPINCOUNT spins, then sleeps
// in the kernel.  etc/bashrc keeps that spin short (1000) because GOMP's long
// default stole the core another process needed on a shared machine; but then
// a thread that arrives a little early (a few per cent of a step) sleeps, and
// waking it costs tens of microseconds on a virtual machine, at every barrier.
// Yielding instead of sleeping costs nothing while the cores are free and
// hands the core over while another process wants it (docs/performance.md,
// round 19: 2 OpenMP threads 1.6x -> 1.85x one thread on an idle 2-core VM,
// unchanged beside a busy process).
#include <atomic>
#include <cstdint>

namespace dem {

class SpinBarrier {
public:
    // Spins (a pause each, ~0.1-1 ms in all) before a waiting thread starts
    // yielding its core: the threads of a balanced step arrive within
    // microseconds of each other.
    static constexpr long defaultSpinsBeforeYield = 20000;

    explicit SpinBarrier(long spinsBeforeYield = defaultSpinsBeforeYield) : spinsBeforeYield_(spinsBeforeYield) {}
    SpinBarrier(const SpinBarrier&) = delete;
    SpinBarrier& operator=(const SpinBarrier&) = delete;

    // Returns when all `parties` threads have called it (every caller passes
    // the same count).  `abandoned`, if given, is polled while waiting: when it
    // turns true the wait ends and this returns false (the caller's partners
    // will never come).
    bool arriveAndWait(int parties, const std::atomic<bool>* abandoned = nullptr);

private:
    long spinsBeforeYield_;
    alignas(64) std::atomic<int> arrived_{0};
    alignas(64) std::atomic<std::uint64_t> generation_{0};
};

}  // namespace dem
