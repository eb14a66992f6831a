#pragma once
// Sets the OpenMP thread count for one scope and restores it: the physics
// tests pin one thread (they run alike whatever OMP_NUM_THREADS says), the
// determinism tests choose their own.
#ifdef _OPENMP
#include <omp.h>
#endif

class ThreadCount {
public:
    explicit ThreadCount(int n) {
#ifdef _OPENMP
        saved_ = omp_get_max_threads();
        omp_set_num_threads(n);
#else
        (void)n;
#endif
    }
    ~ThreadCount() {
#ifdef _OPENMP
        omp_set_num_threads(saved_);
#endif
    }
    ThreadCount(const ThreadCount&) = delete;
    ThreadCount& operator=(const ThreadCount&) = delete;

private:
    int saved_ = 1;
};

class OneThread : public ThreadCount {
public:
    OneThread() : ThreadCount(1) {}
};
