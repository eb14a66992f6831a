#include "demLib/communicator.hpp"

#include <chrono>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "demLib/error.hpp"
#include "demLib/thread_group.hpp"

#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

namespace dem {

namespace {
// The known-size exchange's error for a message of another size than announced.
RuntimeError wrongSize(int from, std::size_t got, std::size_t expected) {
    return RuntimeError("demLib communicator: rank " + std::to_string(from) + " sent " + std::to_string(got) +
                        " bytes in the known-size exchange; expected " + std::to_string(expected));
}
}  // namespace


Communicator::Communicator(std::shared_ptr<const MpiHandle> mpi, int rank, int size)
    : mpi_(std::move(mpi)), rank_(rank), size_(size) {}

Communicator::Communicator(std::shared_ptr<ThreadGroup> threads, int rank)
    : threads_(std::move(threads)), rank_(rank), size_(threads_->size()) {}

void Communicator::runThreadGroup(int ranks, const std::function<void(const Communicator&)>& body) {
    auto group = std::make_shared<ThreadGroup>(ranks);
    std::mutex errorMutex;
    std::exception_ptr firstError;
    auto run = [&](int rank) {
        try {
#ifdef _OPENMP
            omp_set_num_threads(1);  // a new thread starts from OMP_NUM_THREADS
#endif
            body(Communicator(group, rank));
        } catch (...) {
            {
                std::lock_guard<std::mutex> lock(errorMutex);
                if (!firstError) firstError = std::current_exception();
            }
            group->abandon();
        }
    };
    std::vector<std::thread> threads;
    threads.reserve(static_cast<std::size_t>(ranks));
    try {
        for (int r = 0; r < ranks; ++r) threads.emplace_back(run, r);
    } catch (...) {
        // A thread could not be started: the started ranks would wait for it
        // in their first collective forever.
        group->abandon();
        for (auto& t : threads) t.join();
        throw;
    }
    for (auto& t : threads) t.join();
    if (firstError) std::rethrow_exception(firstError);
}

#if DEMLIB_HAS_MPI

namespace {

void check(int code, const char* what) {
    if (code != MPI_SUCCESS) throw RuntimeError(std::string("demLib communicator: ") + what + " failed");
}

// demLib's point-to-point messages use these tags on the caller's communicator.
constexpr int exchangeTag = 7331;
constexpr int knownSizeTag = 7332;

}  // namespace

Communicator communicatorFromMpi(MPI_Comm comm) {
    int initialised = 0, finalised = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    if (!initialised || finalised)
        throw RuntimeError(std::string("demLib communicator: MPI is ") + (finalised ? "already finalised" : "not initialised") +
                           "; the caller must call MPI_Init (OpenFOAM's argList does) before handing demLib a "
                           "communicator, and MPI_Finalize after demLib is done; demLib never does");
    if (comm == MPI_COMM_NULL) throw RuntimeError("demLib communicator: MPI_COMM_NULL given; expected a valid communicator");
    int rank = 0, size = 1;
    check(MPI_Comm_rank(comm, &rank), "MPI_Comm_rank");
    check(MPI_Comm_size(comm, &size), "MPI_Comm_size");
    return Communicator(std::make_shared<const Communicator::MpiHandle>(Communicator::MpiHandle{comm}), rank, size);
}

MPI_Comm mpiCommOf(const Communicator& c) { return c.mpiHandle() ? c.mpiHandle()->comm : MPI_COMM_SELF; }

namespace {

MPI_Datatype mpiType(double) { return MPI_DOUBLE; }
MPI_Datatype mpiType(std::int64_t) { return MPI_INT64_T; }

MPI_Op mpiOp(ReduceOp op) {
    switch (op) {
        case ReduceOp::sum: return MPI_SUM;
        case ReduceOp::min: return MPI_MIN;
        case ReduceOp::max: return MPI_MAX;
        case ReduceOp::logicalOr: return MPI_LOR;
    }
    return MPI_SUM;
}

// The reduction over the ranks of an MPI or serial communicator.
template <class T>
T processReduce(const Communicator& c, T value, ReduceOp op) {
    if (!c.usesMpi() || c.size() == 1) return value;
    T result{};
    check(MPI_Allreduce(&value, &result, 1, mpiType(value), mpiOp(op), c.mpiHandle()->comm), "MPI_Allreduce");
    return result;
}

// The exchange between the ranks of an MPI or serial communicator (sizes checked).
std::vector<std::vector<char>> processExchange(const Communicator& c, const std::vector<std::vector<char>>& sendTo) {
    if (!c.usesMpi() || c.size() == 1) return sendTo;
    const int size = c.size();
    const int rank = c.rank();
    const MPI_Comm comm = c.mpiHandle()->comm;
    // Sizes first (one integer to every rank), then only the non-empty buffers
    // travel, point to point: the data volume is that of the neighbours.
    std::vector<long long> sendSize(size), recvSize(size);
    for (int r = 0; r < size; ++r) sendSize[r] = static_cast<long long>(sendTo[r].size());
    check(MPI_Alltoall(sendSize.data(), 1, MPI_LONG_LONG, recvSize.data(), 1, MPI_LONG_LONG, comm), "MPI_Alltoall");
    std::vector<std::vector<char>> received(size);
    std::vector<MPI_Request> requests;
    requests.reserve(2 * size);
    for (int r = 0; r < size; ++r) {
        if (recvSize[r] > std::numeric_limits<int>::max() || sendSize[r] > std::numeric_limits<int>::max())
            throw RuntimeError("demLib communicator: a message of more than 2 GiB; expected smaller subdomains");
        if (r == rank) {
            received[r] = sendTo[r];
            continue;
        }
        if (recvSize[r] > 0) {
            received[r].resize(static_cast<std::size_t>(recvSize[r]));
            requests.emplace_back();
            check(MPI_Irecv(received[r].data(), static_cast<int>(recvSize[r]), MPI_BYTE, r, exchangeTag, comm,
                            &requests.back()),
                  "MPI_Irecv");
        }
    }
    for (int r = 0; r < size; ++r) {
        if (r == rank || sendSize[r] == 0) continue;
        requests.emplace_back();
        check(MPI_Isend(sendTo[r].data(), static_cast<int>(sendSize[r]), MPI_BYTE, r, exchangeTag, comm,
                        &requests.back()),
              "MPI_Isend");
    }
    check(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    return received;
}

// exchangeKnownSizesAndAnyTrue between the ranks of an MPI communicator of
// more than one rank: the messages posted, the flag reduced, then one wait.
Communicator::ExchangeAndFlag processExchangeKnownSizes(const Communicator& c,
                                                        const std::vector<std::vector<char>>& sendTo,
                                                        const std::vector<std::size_t>& receiveSizes, bool flag) {
    const int size = c.size();
    const int rank = c.rank();
    const MPI_Comm comm = c.mpiHandle()->comm;
    Communicator::ExchangeAndFlag out;
    out.received.resize(size);
    std::vector<MPI_Request> requests;
    requests.reserve(2 * size);
    const std::int64_t mine = flag ? 1 : 0;
    std::int64_t any = 0;
    std::vector<int> from;
    for (int r = 0; r < size; ++r) {
        if (r == rank) {
            out.received[r] = sendTo[r];
            continue;
        }
        if (receiveSizes[r] > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
            sendTo[r].size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
            throw RuntimeError("demLib communicator: a message of more than 2 GiB; expected smaller subdomains");
        if (receiveSizes[r] == 0) continue;
        out.received[r].resize(receiveSizes[r]);
        requests.emplace_back();
        from.push_back(r);
        check(MPI_Irecv(out.received[r].data(), static_cast<int>(receiveSizes[r]), MPI_BYTE, r, knownSizeTag, comm,
                        &requests.back()),
              "MPI_Irecv");
    }
    for (int r = 0; r < size; ++r) {
        if (r == rank || sendTo[r].empty()) continue;
        requests.emplace_back();
        check(MPI_Isend(sendTo[r].data(), static_cast<int>(sendTo[r].size()), MPI_BYTE, r, knownSizeTag, comm,
                        &requests.back()),
              "MPI_Isend");
    }
    // The flag after the messages are posted, as a blocking reduction (the
    // posted messages move meanwhile) rather than Open MPI's MPI_Iallreduce
    // (libnbc, advanced only inside the wait): the round after both ranks had
    // arrived, quick die filling on 2 ranks, 12.8 -> 9.8 us median over two
    // alternating pairs (docs/performance.md (f)).
    check(MPI_Allreduce(&mine, &any, 1, MPI_INT64_T, MPI_LOR, comm), "MPI_Allreduce");
    std::vector<MPI_Status> statuses(requests.size());
    // A message longer than announced fails here (MPI_ERR_TRUNCATE) ...
    if (MPI_Waitall(static_cast<int>(requests.size()), requests.data(), statuses.data()) != MPI_SUCCESS)
        throw RuntimeError("demLib communicator: a message of the known-size exchange did not arrive as announced "
                           "(longer than expected?)");
    // ... a shorter one here.
    for (std::size_t k = 0; k < from.size(); ++k) {
        int count = 0;
        MPI_Get_count(&statuses[k], MPI_BYTE, &count);
        if (static_cast<std::size_t>(count) != receiveSizes[from[k]])
            throw wrongSize(from[k], static_cast<std::size_t>(count), receiveSizes[from[k]]);
    }
    out.anyTrue = any != 0;
    return out;
}

}  // namespace

#else  // serial build: the only process-level communicator is the one-process group

namespace {
template <class T>
T processReduce(const Communicator&, T value, ReduceOp) {
    return value;
}
std::vector<std::vector<char>> processExchange(const Communicator&, const std::vector<std::vector<char>>& sendTo) {
    return sendTo;
}
}  // namespace

#endif

template <class T>
T Communicator::reduce(T value, ReduceOp op) const {
    if (size_ == 1) return threads_ ? threads_->reduce(rank_, value, op) : processReduce(*this, value, op);
    const auto start = std::chrono::steady_clock::now();
    const T result = threads_ ? threads_->reduce(rank_, value, op) : processReduce(*this, value, op);
    CommunicationCounters& c = *counters_;
    c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++c.reductionCalls;
    c.reductionBytes += static_cast<std::int64_t>(sizeof(T)) * (size_ - 1);
    return result;
}

double Communicator::sum(double v) const { return reduce(v, ReduceOp::sum); }
std::int64_t Communicator::sum(std::int64_t v) const { return reduce(v, ReduceOp::sum); }
double Communicator::min(double v) const { return reduce(v, ReduceOp::min); }
double Communicator::max(double v) const { return reduce(v, ReduceOp::max); }
bool Communicator::anyTrue(bool v) const { return reduce(std::int64_t{v ? 1 : 0}, ReduceOp::logicalOr) != 0; }

std::vector<std::vector<char>> Communicator::exchange(const std::vector<std::vector<char>>& sendTo) const {
    if (static_cast<int>(sendTo.size()) != size_)
        throw RuntimeError("demLib communicator: exchange given " + std::to_string(sendTo.size()) +
                           " buffers; expected one per rank (" + std::to_string(size_) + ")");
    if (size_ == 1) return threads_ ? threads_->exchange(rank_, sendTo) : processExchange(*this, sendTo);
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::vector<char>> received =
        threads_ ? threads_->exchange(rank_, sendTo) : processExchange(*this, sendTo);
    CommunicationCounters& c = *counters_;
    c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++c.exchangeCalls;
    for (int r = 0; r < size_; ++r)
        if (r != rank_) c.exchangeBytes += static_cast<std::int64_t>(sendTo[static_cast<std::size_t>(r)].size());
    return received;
}

Communicator::ExchangeAndFlag Communicator::exchangeKnownSizesAndAnyTrue(const std::vector<std::vector<char>>& sendTo,
                                                                       const std::vector<std::size_t>& receiveSizes,
                                                                       bool flag) const {
    if (static_cast<int>(sendTo.size()) != size_ || static_cast<int>(receiveSizes.size()) != size_)
        throw RuntimeError("demLib communicator: known-size exchange given " + std::to_string(sendTo.size()) +
                           " buffers and " + std::to_string(receiveSizes.size()) + " sizes; expected one per rank (" +
                           std::to_string(size_) + ")");
    ExchangeAndFlag out;
#if DEMLIB_HAS_MPI
    if (!threads_ && usesMpi() && size_ > 1) {
        const auto start = std::chrono::steady_clock::now();
        out = processExchangeKnownSizes(*this, sendTo, receiveSizes, flag);
        CommunicationCounters& c = *counters_;
        c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++c.exchangeCalls;
        ++c.reductionCalls;
        c.reductionBytes += static_cast<std::int64_t>(sizeof(std::int64_t)) * (size_ - 1);
        for (int r = 0; r < size_; ++r)
            if (r != rank_) c.exchangeBytes += static_cast<std::int64_t>(sendTo[static_cast<std::size_t>(r)].size());
        return out;
    }
#endif
    // Thread ranks and the one-process group: the two collectives one after the other.
    out.anyTrue = anyTrue(flag);
    out.received = exchange(sendTo);
    for (int r = 0; r < size_; ++r) {
        const std::size_t got = out.received[static_cast<std::size_t>(r)].size();
        if (r != rank_ && got != receiveSizes[static_cast<std::size_t>(r)])
            throw wrongSize(r, got, receiveSizes[static_cast<std::size_t>(r)]);
    }
    return out;
}

}  // namespace dem
