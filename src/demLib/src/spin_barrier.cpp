#include "demLib/spin_barrier.hpp"

#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace dem {

namespace {
void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#endif
}
}  // namespace

bool SpinBarrier::arriveAndWait(int parties, const std::atomic<bool>* abandoned) {
    if (parties <= 1) return true;
    const std::uint64_t generation = generation_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == parties) {
        arrived_.store(0, std::memory_order_relaxed);
        generation_.store(generation + 1, std::memory_order_release);
        return true;
    }
    for (long spins = 0; generation_.load(std::memory_order_acquire) == generation; ++spins) {
        if (abandoned && abandoned->load(std::memory_order_acquire)) return false;
        if (spins < spinsBeforeYield_)
            cpuRelax();
        else
            std::this_thread::yield();
    }
    return true;
}

}  // namespace dem
