// ProgressEstimate: the ETA of a long run from its pace over the last minutes.
#include <gtest/gtest.h>

#include "demLib/progress_estimate.hpp"

namespace {

TEST(ProgressEstimate, NoPaceBeforeTheFirstSampleOrWithoutProgress) {
    dem::ProgressEstimate e(0.9, 13.0);
    EXPECT_LT(e.secondsLeft(), 0.0);
    e.add(30.0, 0.9);  // stalled: no simulated time gained
    EXPECT_LT(e.secondsLeft(), 0.0);
    EXPECT_EQ(e.pace(), 0.0);
}

TEST(ProgressEstimate, SteadyPaceGivesTheExactTimeLeft) {
    // 0.01 simulated s per 30 wall s from t = 0.9 s to 13 s.
    dem::ProgressEstimate e(0.9, 13.0);
    double t = 0.9;
    for (int k = 1; k <= 100; ++k) {
        t += 0.01;
        e.add(30.0 * k, t);
    }
    EXPECT_NEAR(e.pace(), 0.01 / 30.0, 1e-15);
    EXPECT_NEAR(e.secondsLeft(), (13.0 - t) / (0.01 / 30.0), 1e-6);
}

TEST(ProgressEstimate, PercentCountsTheWholeRunFromZero) {
    // A run continued from 0.9 s that reached 0.936 s of 13 s is 7.2 % done
    // (not the 0.3 % of the stretch since the continue).
    dem::ProgressEstimate e(0.9, 13.0);
    e.add(60.0, 0.936);
    EXPECT_NEAR(e.fractionDone(), 0.936 / 13.0, 1e-15);
}

TEST(ProgressEstimate, APauseLeavesTheEstimateOnceItIsOutOfTheWindow) {
    // The full die-filling run: continued at 0.9 s, paused 25 min at once,
    // then 0.45 simulated s per hour.  The mean pace since the start said
    // 175 h after 31 min; the pace of the last 10 min says about 27 h.
    const double window = 600.0;
    dem::ProgressEstimate e(0.9, 13.0, window);
    const double pace = 0.45 / 3600.0;
    e.add(1500.0, 0.9);  // the pause
    double wall = 1500.0, t = 0.9;
    while (wall < 1500.0 + 30.0 * 30) {  // 15 min of running, a line every 30 s
        wall += 30.0;
        t += 30.0 * pace;
        e.add(wall, t);
    }
    const double expected = (13.0 - t) / pace;
    EXPECT_NEAR(e.secondsLeft(), expected, 1e-6 * expected);
    // The same samples through a window that holds the pause (the mean pace since
    // the start, the old estimate) say more than twice as long.
    dem::ProgressEstimate whole(0.9, 13.0, 1e9);
    whole.add(1500.0, 0.9);
    for (double w = 1530.0, tt = 0.9 + 30.0 * pace; w <= wall + 1e-9; w += 30.0, tt += 30.0 * pace) whole.add(w, tt);
    EXPECT_GT(whole.secondsLeft(), 2.0 * expected);
}

TEST(ProgressEstimate, AStopIsLeftOutOfThePaceAtOnce) {
    // Samples every 30 s at 0.45 simulated s per hour; the process is stopped
    // for 11 minutes (fullRun pause) between two samples.  With the sample
    // interval given, all of the gap but one interval is left out: the ETA
    // right after the stop is the running pace's.  Without it the stop is
    // inside the window and the ETA is several times too long.
    const double pace = 0.45 / 3600.0;
    dem::ProgressEstimate with(2.0, 13.0, 600.0, 30.0), without(2.0, 13.0, 600.0);
    double wall = 0.0, t = 2.0;
    for (int k = 0; k < 30; ++k) {
        wall += 30.0;
        t += 30.0 * pace;
        with.add(wall, t);
        without.add(wall, t);
    }
    wall += 660.0;  // stopped: no sample, no progress
    for (int k = 0; k < 4; ++k) {
        wall += 30.0;
        t += 30.0 * pace;
        with.add(wall, t);
        without.add(wall, t);
    }
    const double expected = (13.0 - t) / pace;
    EXPECT_NEAR(with.secondsLeft(), expected, 1e-6 * expected);
    EXPECT_GT(without.secondsLeft(), 2.0 * expected);
    // Gaps of up to three intervals (a slow stretch) are not stops: the
    // steady estimate is exact.
    dem::ProgressEstimate slow(2.0, 13.0, 600.0, 30.0);
    wall = 0.0;
    t = 2.0;
    for (int k = 0; k < 40; ++k) slow.add(wall += 85.0, t += 85.0 * pace);
    EXPECT_NEAR(slow.secondsLeft(), (13.0 - t) / pace, 1e-6 * (13.0 - t) / pace);
}

TEST(ProgressEstimate, ThePaceFollowsAChangeWithinTheWindow) {
    // A run that slows to half its pace (e.g. the wet bed): after one window
    // at the new pace the estimate is the new pace's.
    const double window = 600.0;
    dem::ProgressEstimate e(0.0, 10.0, window);
    double wall = 0.0, t = 0.0;
    for (int k = 0; k < 40; ++k) e.add(wall += 30.0, t += 0.02);
    for (int k = 0; k < 20; ++k) e.add(wall += 30.0, t += 0.01);
    EXPECT_NEAR(e.pace(), 0.01 / 30.0, 1e-12);
    EXPECT_NEAR(e.secondsLeft(), (10.0 - t) / (0.01 / 30.0), 1e-6);
}

}  // namespace
