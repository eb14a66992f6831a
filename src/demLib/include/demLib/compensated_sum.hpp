#pragma once
// Neumaier's compensated sum: a budget (the liquid of all bridges) closes to
// ~1e-16 of its total, not to N·1e-16, however many terms there are.  The
// running sum and its compensation are readable apart, so that partial sums
// can travel between ranks and be added there (liquid_bridges_over_ranks).
#include <cmath>

namespace dem {

class CompensatedSum {
public:
    void add(double value) {
        const double total = sum_ + value;
        if (std::abs(sum_) >= std::abs(value))
            compensation_ += (sum_ - total) + value;
        else
            compensation_ += (value - total) + sum_;
        sum_ = total;
    }
    double value() const { return sum_ + compensation_; }
    double sum() const { return sum_; }
    double compensation() const { return compensation_; }

private:
    double sum_ = 0.0;
    double compensation_ = 0.0;
};

}  // namespace dem
