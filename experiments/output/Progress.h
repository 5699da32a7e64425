// Progress: the progress lines of the commands that can run for long, on stderr: a sweep's jobs
// (SweepRunner.h: one line per job with elapsed and estimated remaining time) and a long render's
// steps (DelayedProgress, used by `testbed render`). Both write whole lines, never carriage
// returns, whether or not stderr is a terminal, so that a batch job's log keeps them; both give
// durations as formatDuration writes them.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <string>
#include <thread>

namespace experiments {

// "4.2s", "3m07s", "1h02m03s".
std::string formatDuration(double seconds);

// "elapsed E, remaining ~R": R extrapolates the mean of the `done` items' `doneSeconds` to the
// `left` ones ("?" before any is done).
std::string elapsedAndRemaining(double elapsedSeconds, double doneSeconds, size_t done,
                                size_t left);

// A render's steps as progress lines, but only for a render that runs longer than `delaySeconds`
// (kLongRenderSeconds for `testbed render`): nothing is printed before then; when the delay
// passes, the step under way is printed (by a timer thread, so a single long step shows too),
// then every later step as it starts, and finish() prints the total. A short render prints
// nothing. Lines: "testbed: [elapsed 2.0s] STEP".
//
// Thread safety: step(), poll() and finish() may be called from any thread (one mutex).
class DelayedProgress {
public:
    // `elapsedSeconds` (tests inject a clock) defaults to the steady clock since construction;
    // `timer` starts the thread that calls poll() when the delay passes.
    DelayedProgress(std::ostream& out, double delaySeconds,
                    std::function<double()> elapsedSeconds = {}, bool timer = true);
    ~DelayedProgress(); // stops and joins the timer
    DelayedProgress(const DelayedProgress&) = delete;
    DelayedProgress& operator=(const DelayedProgress&) = delete;

    void step(const std::string& what); // a step starts
    void poll();                        // once the delay has passed: print the step under way
    void finish();                      // "done in E" when anything was printed

private:
    void printLocked(const std::string& what);

    std::ostream& mOut;
    double mDelaySeconds;
    std::function<double()> mElapsedSeconds;
    std::mutex mMutex;
    std::condition_variable mStop;
    bool mStopping = false;
    bool mLive = false; // the delay has passed: steps are printed
    std::string mCurrent;
    std::thread mTimer;
};

// Renders shorter than this print no progress (issue 16: like sweeps, but not for short renders).
inline constexpr double kLongRenderSeconds = 2.0;

} // namespace experiments
