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

// What one rank's communicator has done since it was made or last reset
// (Communicator::counters).  Only traffic between ranks counts: a group of one
// rank counts nothing.
struct CommunicationCounters {
    std::int64_t exchangeCalls = 0;   // exchange() calls
    std::int64_t reductionCalls = 0;  // sum, min, max, anyTrue calls
    // Payload bytes this rank sent to other ranks: the exchange buffers
    // addressed to other ranks, and one value (8 bytes) per other rank for each
    // reduction.  The transport's own overhead (headers, the sizes an MPI
    // exchange announces first, a reduction tree's relaying) is not counted.
    std::int64_t exchangeBytes = 0;
    std::int64_t reductionBytes = 0;
    // Wall time spent inside the collectives (steady_clock around each call),
    // waiting for the other ranks included: a rank that arrives first at a
    // collective counts the time until the slowest arrives.
    double seconds = 0.0;

    std::int64_t calls() const { return exchangeCalls + reductionCalls; }
    std::int64_t bytesSent() const { return exchangeBytes + reductionBytes; }
};

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

    // The two things a decomposed step needs from the other ranks, in one
    // round: the exchange of sendTo as exchange() does it, where each rank
    // already knows how many bytes it gets from each other rank
    // (receiveSizes[r]; 0: nothing from r, and r sends nothing), and
    // anyTrue(flag).  With MPI the reduction and the messages travel together
    // (the point-to-point messages posted, the flag reduced, one wait), instead
    // of the three waits of anyTrue and exchange (sizes first, then data).
    // A message of another size than announced is an error.  Collective.
    struct ExchangeAndFlag {
        std::vector<std::vector<char>> received;
        bool anyTrue = false;
    };
    ExchangeAndFlag exchangeKnownSizesAndAnyTrue(const std::vector<std::vector<char>>& sendTo,
                                                 const std::vector<std::size_t>& receiveSizes, bool flag) const;

    // This rank's traffic and time in the collectives above.  A communicator
    // and its copies share one set of counters (e.g. the copy a GhostExchange
    // holds and the caller's); each rank of a group counts its own, and each
    // communicatorFromMpi / serial() / runThreadGroup rank starts a new set at
    // zero.  Counting costs two clock reads per collective and changes no
    // result.  resetCounters() zeroes the shared set (local, not collective).
    CommunicationCounters counters() const { return *counters_; }
    void resetCounters() const { *counters_ = CommunicationCounters{}; }

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
    std::shared_ptr<CommunicationCounters> counters_ = std::make_shared<CommunicationCounters>();
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace dem
