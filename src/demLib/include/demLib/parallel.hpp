#pragma once
// How many OpenMP threads a loop over n particles uses.  Forking threads costs
// microseconds (much more on a loaded machine), so small loops stay serial.
// The count depends only on n and the thread setting, so results stay
// deterministic for a given thread count.
#include <algorithm>
#include <cstddef>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dem {

// Per-particle work of a few flops (integration, resets, displacement checks).
inline constexpr std::size_t lightLoopParticlesPerThread = 4096;
// Per-particle work over all its contacts (forces, neighbour search).
inline constexpr std::size_t heavyLoopParticlesPerThread = 64;

inline int threadsFor(std::size_t n, std::size_t particlesPerThread) {
#ifdef _OPENMP
    const std::size_t wanted = std::max<std::size_t>(1, n / particlesPerThread);
    return static_cast<int>(std::min<std::size_t>(wanted, static_cast<std::size_t>(omp_get_max_threads())));
#else
    (void)n;
    (void)particlesPerThread;
    return 1;
#endif
}

// This thread's index in its OpenMP team, and the team's size (0 and 1 outside
// a parallel region or without OpenMP).
inline int threadIndex() {
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

inline int teamSize() {
#ifdef _OPENMP
    return omp_get_num_threads();
#else
    return 1;
#endif
}

}  // namespace dem
