#pragma once
// The group of processes a demLib run is spread over.  demLib never starts or
// stops MPI: OpenFOAM's argList (or any other caller) calls MPI_Init and hands
// demLib a communicator (communicatorFromMpi in communicator_mpi.hpp, only in an
// MPI build).  Communicator::serial() is the one-process group; it has the same
// API and is what an MPI-free build or a serial run uses.  runThreadGroup gives
// ranks that are threads of this process (thread_group.hpp), in any build.
//
// This header does not include mpi.h: the MPI handle stays behind an opaque
// pointer, so MPI-free users of demLib need no MPI headers.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "demLib/config.hpp"

namespace dem {

class ThreadGroup;
enum class ReduceOp;

class Communicator {
public:
    // The single-process group (rank 0 of 1).
    static Communicator serial() { return Communicator(); }

    // Runs body(communicator of rank r) on `ranks` threads of this process,
    // r = 0 .. ranks-1 (rank 0 on a new thread too), and returns when all have
    // finished.  Each thread is one rank: it owns its data (e.g. its own
    // decomposed Simulation) and meets the others only in the collectives.
    // Each thread starts with one OpenMP thread.  If a body throws, ranks
    // waiting in a collective are released with an error and the first
    // exception thrown is rethrown here after all threads have ended.
    static void runThreadGroup(int ranks, const std::function<void(const Communicator&)>& body);

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool isSerial() const { return size_ == 1; }
    // True when built over an MPI communicator (even one of size 1).
    bool usesMpi() const { return static_cast<bool>(mpi_); }
    // True for the ranks of runThreadGroup.
    bool usesThreads() const { return static_cast<bool>(threads_); }

    // Reductions over all ranks; every rank gets the result.  Collective: all
    // ranks of the group must call them in the same order.
    double sum(double value) const;
    std::int64_t sum(std::int64_t value) const;
    double min(double value) const;
    double max(double value) const;
    bool anyTrue(bool value) const;

    // Sparse personalised exchange of byte buffers: sendTo[r] goes to rank r
    // (sendTo.size() == size(); empty buffers are allowed and are the common
    // case), the result's element r is what rank r sent here.  Collective.
    std::vector<std::vector<char>> exchange(const std::vector<std::vector<char>>& sendTo) const;

    // Opaque MPI state, defined in communicator_mpi.hpp (MPI builds only).
    struct MpiHandle;
    explicit Communicator(std::shared_ptr<const MpiHandle> mpi, int rank, int size);
    const MpiHandle* mpiHandle() const { return mpi_.get(); }

private:
    Communicator() = default;
    Communicator(std::shared_ptr<ThreadGroup> threads, int rank);
    template <class T>
    T reduce(T value, ReduceOp op) const;
    std::shared_ptr<const MpiHandle> mpi_;
    std::shared_ptr<ThreadGroup> threads_;
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace dem
