#include "demLib/exchange_trace.hpp"

#include <cstdio>
#include <fstream>

#include "demLib/error.hpp"

namespace dem {

ExchangeTrace& ExchangeTrace::process() {
    static ExchangeTrace trace;
    return trace;
}

ExchangeTrace::~ExchangeTrace() {
    if (rank_ < 0 || rows_.empty()) return;
    try {
        write();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "demLib: %s\n", e.what());  // at exit: nobody left to catch it
    }
}

void ExchangeTrace::record(double startSeconds, double endSeconds, double bytesSent) {
    rows_.insert(rows_.end(), {startSeconds, endSeconds, bytesSent});
}

std::string ExchangeTrace::fileName(int rank) { return "exchangeTrace.rank" + std::to_string(rank) + ".bin"; }

void ExchangeTrace::write(const std::string& directory) const {
    const std::string path = directory + "/" + fileName(rank_ < 0 ? 0 : rank_);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(rows_.data()), static_cast<std::streamsize>(rows_.size() * sizeof(double)));
    if (!out) throw RuntimeError("exchange trace: cannot write " + path);
}

}  // namespace dem
