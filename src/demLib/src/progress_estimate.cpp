#include "demLib/progress_estimate.hpp"

#include <algorithm>

namespace dem {

ProgressEstimate::ProgressEstimate(double simulatedStart, double end, double window, double sampleInterval)
    : end_(end), window_(window), sampleInterval_(sampleInterval) {
    samples_.push_back({0.0, simulatedStart});
}

void ProgressEstimate::add(double wall, double simulated) {
    const double gap = wall - lastWall_;
    if (sampleInterval_ > 0.0 && gap > 3.0 * sampleInterval_) stalled_ += gap - sampleInterval_;
    lastWall_ = wall;
    samples_.push_back({wall - stalled_, simulated});
    // Keep the newest sample at least `window` old, so the pace always spans
    // the window once the run is that long.
    while (samples_.size() > 2 && samples_.back().wall - samples_[1].wall >= window_) samples_.pop_front();
}

double ProgressEstimate::pace() const {
    if (samples_.size() < 2) return 0.0;
    const Sample& first = samples_.front();
    const Sample& last = samples_.back();
    const double wall = last.wall - first.wall;
    const double gained = last.simulated - first.simulated;
    return wall > 0.0 && gained > 0.0 ? gained / wall : 0.0;
}

double ProgressEstimate::secondsLeft() const {
    const double p = pace();
    if (p <= 0.0) return -1.0;
    return std::max(0.0, end_ - samples_.back().simulated) / p;
}

double ProgressEstimate::fractionDone() const {
    if (end_ <= 0.0) return 1.0;
    return std::clamp(samples_.back().simulated / end_, 0.0, 1.0);
}

}  // namespace dem
