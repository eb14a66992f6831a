#pragma once
// A record of the decomposed step's exchange rounds (GhostExchange::
// updateGhostsUnlessRebuild, one per step) on this process: when each began
// and ended and how many bytes it sent.  Written at exit as
// exchangeTrace.rank<N>.bin in the working directory, three doubles a round
// (start and end in seconds of std::chrono::steady_clock, bytes sent), when
// demLib is built with -DDEMLIB_EXCHANGE_TRACE=ON (off by default: a
// diagnostic, not a feature).  With the ranks on one machine their clocks are
// one clock, so bench/exchangeTrace splits each rank's wait into the time
// until the last rank arrived (imbalance, jitter) and the time after (the
// transfer).  docs/performance.md (f) shows what it found.
#include <cstddef>
#include <string>
#include <vector>

namespace dem {

class ExchangeTrace {
public:
    ExchangeTrace() = default;
    ExchangeTrace(const ExchangeTrace&) = delete;
    ExchangeTrace& operator=(const ExchangeTrace&) = delete;
    ~ExchangeTrace();  // writes the file (once rank() was set)

    // The process's one trace (written when the process ends).
    static ExchangeTrace& process();

    void setRank(int rank) { rank_ = rank; }
    void record(double startSeconds, double endSeconds, double bytesSent);
    const std::vector<double>& rows() const { return rows_; }
    // exchangeTrace.rank<N>.bin in `directory`; throws RuntimeError if it cannot be written.
    void write(const std::string& directory = ".") const;
    static std::string fileName(int rank);

private:
    int rank_ = -1;
    std::vector<double> rows_;
};

}  // namespace dem
