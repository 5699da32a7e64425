// Tests for experiments/Progress: durations as sweeps print them, the remaining-time estimate,
// and DelayedProgress (a render's steps only once it has run for long), driven by an injected
// clock so that no test depends on timing.
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "experiments/output/Progress.h"

namespace experiments {
namespace {

TEST(Progress, DurationsAsSweepsPrintThem) {
    EXPECT_EQ(formatDuration(4.24), "4.2s");
    EXPECT_EQ(formatDuration(187.0), "3m07s");
    EXPECT_EQ(formatDuration(3723.0), "1h02m03s");
    EXPECT_EQ(elapsedAndRemaining(10.0, 0.0, 0, 5), "elapsed 10.0s, remaining ~?");
    EXPECT_EQ(elapsedAndRemaining(10.0, 6.0, 2, 4), "elapsed 10.0s, remaining ~12.0s");
}

TEST(DelayedProgress, AShortRenderPrintsNothing) {
    std::ostringstream out;
    double now = 0.0;
    {
        DelayedProgress progress(
            out, 2.0, [&] { return now; }, false);
        now = 0.1;
        progress.step("loading scene");
        now = 0.5;
        progress.step("G-buffer pass");
        now = 1.9;
        progress.poll();
        progress.step("writing outputs");
        progress.finish();
    }
    EXPECT_EQ(out.str(), "");
}

TEST(DelayedProgress, ALongRenderShowsTheStepUnderWayThenEveryStep) {
    std::ostringstream out;
    double now = 0.0;
    DelayedProgress progress(
        out, 2.0, [&] { return now; }, false);
    now = 0.3;
    progress.step("G-buffer pass");
    EXPECT_EQ(out.str(), "");
    now = 2.5; // the timer's poll: the long step is shown while it runs
    progress.poll();
    EXPECT_EQ(out.str(), "testbed: [elapsed 2.5s] G-buffer pass (under way)\n");
    progress.poll(); // once
    now = 3.0;
    progress.step("shading: brute");
    now = 4.0;
    progress.finish();
    EXPECT_EQ(out.str(), "testbed: [elapsed 2.5s] G-buffer pass (under way)\n"
                         "testbed: [elapsed 3.0s] shading: brute\n"
                         "testbed: [elapsed 4.0s] done\n");
}

TEST(DelayedProgress, AStepStartingAfterTheDelayIsPrintedAtOnce) {
    std::ostringstream out;
    double now = 2.0;
    DelayedProgress progress(
        out, 2.0, [&] { return now; }, false);
    progress.step("reference (double precision)");
    EXPECT_EQ(out.str(), "testbed: [elapsed 2.0s] reference (double precision)\n");
}

TEST(DelayedProgress, TheTimerThreadPrintsTheStepUnderWay) {
    // A zero delay: the timer fires at once; whichever of it and step() comes first, the step is
    // printed exactly once, and the destructor joins the timer.
    std::ostringstream out;
    {
        DelayedProgress progress(out, 0.0);
        progress.step("G-buffer pass");
    }
    const std::string text = out.str();
    EXPECT_NE(text.find("G-buffer pass"), std::string::npos) << text;
    EXPECT_EQ(text.find("G-buffer pass"), text.rfind("G-buffer pass")) << text;
    // A delay that never passes: nothing, and destruction does not wait for it.
    std::ostringstream quiet;
    {
        DelayedProgress progress(quiet, 3600.0);
        progress.step("G-buffer pass");
    }
    EXPECT_EQ(quiet.str(), "");
}

} // namespace
} // namespace experiments
