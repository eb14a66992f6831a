#include "demLib/communicator.hpp"

#include <limits>
#include <string>

#include "demLib/error.hpp"

#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

namespace dem {

Communicator::Communicator(std::shared_ptr<const MpiHandle> mpi, int rank, int size)
    : mpi_(std::move(mpi)), rank_(rank), size_(size) {}

#if DEMLIB_HAS_MPI

namespace {

void check(int code, const char* what) {
    if (code != MPI_SUCCESS) throw RuntimeError(std::string("demLib communicator: ") + what + " failed");
}

// demLib's point-to-point messages use this tag on the caller's communicator.
constexpr int exchangeTag = 7331;

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
template <class T>
T allReduce(const Communicator& c, T value, MPI_Datatype type, MPI_Op op) {
    if (!c.usesMpi() || c.size() == 1) return value;
    T result{};
    check(MPI_Allreduce(&value, &result, 1, type, op, c.mpiHandle()->comm), "MPI_Allreduce");
    return result;
}
}  // namespace

double Communicator::sum(double v) const { return allReduce(*this, v, MPI_DOUBLE, MPI_SUM); }
std::int64_t Communicator::sum(std::int64_t v) const { return allReduce(*this, v, MPI_INT64_T, MPI_SUM); }
double Communicator::min(double v) const { return allReduce(*this, v, MPI_DOUBLE, MPI_MIN); }
double Communicator::max(double v) const { return allReduce(*this, v, MPI_DOUBLE, MPI_MAX); }
bool Communicator::anyTrue(bool v) const { return allReduce(*this, v ? 1 : 0, MPI_INT, MPI_LOR) != 0; }

std::vector<std::vector<char>> Communicator::exchange(const std::vector<std::vector<char>>& sendTo) const {
    if (static_cast<int>(sendTo.size()) != size_)
        throw RuntimeError("demLib communicator: exchange given " + std::to_string(sendTo.size()) +
                           " buffers; expected one per rank (" + std::to_string(size_) + ")");
    if (!usesMpi() || size_ == 1) return sendTo;
    const MPI_Comm comm = mpi_->comm;
    // Sizes first (one integer to every rank), then only the non-empty buffers
    // travel, point to point: the data volume is that of the neighbours.
    std::vector<long long> sendSize(size_), recvSize(size_);
    for (int r = 0; r < size_; ++r) sendSize[r] = static_cast<long long>(sendTo[r].size());
    check(MPI_Alltoall(sendSize.data(), 1, MPI_LONG_LONG, recvSize.data(), 1, MPI_LONG_LONG, comm), "MPI_Alltoall");
    std::vector<std::vector<char>> received(size_);
    std::vector<MPI_Request> requests;
    requests.reserve(2 * size_);
    for (int r = 0; r < size_; ++r) {
        if (recvSize[r] > std::numeric_limits<int>::max() || sendSize[r] > std::numeric_limits<int>::max())
            throw RuntimeError("demLib communicator: a message of more than 2 GiB; expected smaller subdomains");
        if (r == rank_) {
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
    for (int r = 0; r < size_; ++r) {
        if (r == rank_ || sendSize[r] == 0) continue;
        requests.emplace_back();
        check(MPI_Isend(sendTo[r].data(), static_cast<int>(sendSize[r]), MPI_BYTE, r, exchangeTag, comm,
                        &requests.back()),
              "MPI_Isend");
    }
    check(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    return received;
}

#else  // serial build: the only communicator is the one-process group

double Communicator::sum(double v) const { return v; }
std::int64_t Communicator::sum(std::int64_t v) const { return v; }
double Communicator::min(double v) const { return v; }
double Communicator::max(double v) const { return v; }
bool Communicator::anyTrue(bool v) const { return v; }

std::vector<std::vector<char>> Communicator::exchange(const std::vector<std::vector<char>>& sendTo) const {
    if (sendTo.size() != 1)
        throw RuntimeError("demLib communicator: exchange given " + std::to_string(sendTo.size()) +
                           " buffers; expected one per rank (1)");
    return sendTo;
}

#endif

}  // namespace dem
