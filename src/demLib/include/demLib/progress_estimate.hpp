#pragma once
// The time left of a long run, from its recent pace.
//
// A run's pace changes: a die fill's dry filling, its wet bed and the opening
// cost different wall time per simulated second, and a run paused (fullRun
// pause) or sharing its cores stalls for a while.  The mean pace since the
// start carries every stall to the end of the run: the full die-filling run,
// paused for 25 minutes right after a continue, printed an ETA of 175 h where
// its pace gave 27 h.  The estimate here uses the pace over the samples of the
// last `window` seconds of wall time (all samples since the start until the
// window is full).
#include <cstddef>
#include <deque>

namespace dem {

class ProgressEstimate {
public:
    // simulatedStart: the simulated time the run starts (or continues) from;
    // end: the simulated time it runs to; window: wall seconds of the pace.
    // sampleInterval (0: off): the wall seconds between samples of a running
    // process.  A gap of more than three of them is a stop (the process was
    // paused and printed nothing); all of it but one interval is left out of
    // the pace, so a paused run's ETA is right at once instead of only after
    // the pause has left the window.
    ProgressEstimate(double simulatedStart, double end, double window = 600.0, double sampleInterval = 0.0);

    // A sample: wall seconds since the run started, simulated time reached.
    void add(double wall, double simulated);

    // Wall seconds left at the recent pace; negative when there is no pace
    // yet (fewer than two samples, or no simulated time gained in the window).
    double secondsLeft() const;
    // Simulated seconds per wall second over the window (0 without a pace).
    double pace() const;
    // Share of the whole run done, 0..1 (the simulated time over the end time,
    // not over what is left since a continue).
    double fractionDone() const;

private:
    struct Sample {
        double wall, simulated;
    };
    double end_, window_, sampleInterval_;
    double lastWall_ = 0.0;  // wall time of the newest sample as given
    double stalled_ = 0.0;   // wall seconds left out (stops)
    std::deque<Sample> samples_;
};

}  // namespace dem
