#include "demLib/thread_group.hpp"

#include <algorithm>

#include "demLib/error.hpp"

namespace dem {

ThreadGroup::ThreadGroup(int ranks) : size_(ranks), calls_(static_cast<std::size_t>(std::max(ranks, 0))) {
    if (ranks < 1) throw InputError("demLib thread group: " + std::to_string(ranks) + " ranks; expected at least 1");
    for (int phase = 0; phase < 2; ++phase) {
        slots_[phase].resize(static_cast<std::size_t>(ranks));
        mail_[phase].resize(static_cast<std::size_t>(ranks) * static_cast<std::size_t>(ranks));
    }
}

int ThreadGroup::arriveAndWait(int rank) {
    const int phase = static_cast<int>(calls_[static_cast<std::size_t>(rank)].entered++ & 1U);
    if (!barrier_.arriveAndWait(size_, &abandoned_))
        throw RuntimeError("demLib thread group: rank " + std::to_string(rank) +
                           " stopped waiting: another rank of the group failed");
    return phase;
}

template <class T>
T ThreadGroup::reduceIn(int rank, T value, T Slot::*field, ReduceOp op) {
    if (size_ == 1) return value;
    // The slot to write is that of this rank's next phase, known before the barrier.
    const int phase = static_cast<int>(calls_[static_cast<std::size_t>(rank)].entered & 1U);
    slots_[phase][static_cast<std::size_t>(rank)].*field = value;
    arriveAndWait(rank);
    T result = slots_[phase][0].*field;
    for (int r = 1; r < size_; ++r) {
        const T v = slots_[phase][static_cast<std::size_t>(r)].*field;
        switch (op) {
            case ReduceOp::sum: result = result + v; break;
            case ReduceOp::min: result = std::min(result, v); break;
            case ReduceOp::max: result = std::max(result, v); break;
            case ReduceOp::logicalOr: result = (result != T{0} || v != T{0}) ? T{1} : T{0}; break;
        }
    }
    return result;
}

double ThreadGroup::reduce(int rank, double v, ReduceOp op) { return reduceIn(rank, v, &Slot::real, op); }
std::int64_t ThreadGroup::reduce(int rank, std::int64_t v, ReduceOp op) { return reduceIn(rank, v, &Slot::integer, op); }

std::vector<std::vector<char>> ThreadGroup::exchange(int rank, const std::vector<std::vector<char>>& sendTo) {
    if (static_cast<int>(sendTo.size()) != size_)
        throw RuntimeError("demLib communicator: exchange given " + std::to_string(sendTo.size()) +
                           " buffers; expected one per rank (" + std::to_string(size_) + ")");
    std::vector<std::vector<char>> received(static_cast<std::size_t>(size_));
    received[static_cast<std::size_t>(rank)] = sendTo[static_cast<std::size_t>(rank)];
    if (size_ == 1) return received;
    const int phase = static_cast<int>(calls_[static_cast<std::size_t>(rank)].entered & 1U);
    const std::size_t n = static_cast<std::size_t>(size_);
    for (std::size_t to = 0; to < n; ++to)
        if (static_cast<int>(to) != rank) mail_[phase][to * n + static_cast<std::size_t>(rank)] = sendTo[to];
    arriveAndWait(rank);
    for (std::size_t from = 0; from < n; ++from)
        if (static_cast<int>(from) != rank)
            received[from] = std::move(mail_[phase][static_cast<std::size_t>(rank) * n + from]);
    return received;
}

}  // namespace dem
