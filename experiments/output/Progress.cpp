#include "experiments/output/Progress.h"

#include <cmath>
#include <cstdio>
#include <ostream>

namespace experiments {

std::string formatDuration(double seconds) {
    char text[32];
    if (seconds < 60.0) {
        std::snprintf(text, sizeof text, "%.1fs", seconds);
    } else {
        const long whole = std::lround(seconds);
        if (whole < 3600)
            std::snprintf(text, sizeof text, "%ldm%02lds", whole / 60, whole % 60);
        else
            std::snprintf(text, sizeof text, "%ldh%02ldm%02lds", whole / 3600, whole / 60 % 60,
                          whole % 60);
    }
    return text;
}

std::string elapsedAndRemaining(double elapsedSeconds, double doneSeconds, size_t done,
                                size_t left) {
    const std::string remaining =
        done == 0 ? "?" : formatDuration(doneSeconds / double(done) * double(left));
    return "elapsed " + formatDuration(elapsedSeconds) + ", remaining ~" + remaining;
}

DelayedProgress::DelayedProgress(std::ostream& out, double delaySeconds,
                                 std::function<double()> elapsedSeconds, bool timer)
    : mOut(out), mDelaySeconds(delaySeconds), mElapsedSeconds(std::move(elapsedSeconds)) {
    if (!mElapsedSeconds) {
        const auto start = std::chrono::steady_clock::now();
        mElapsedSeconds = [start] {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        };
    }
    if (timer)
        mTimer = std::thread([this] {
            std::unique_lock lock(mMutex);
            const auto delay = std::chrono::duration<double>(mDelaySeconds);
            if (mStop.wait_for(lock, delay, [this] { return mStopping; }))
                return;
            lock.unlock();
            poll();
        });
}

DelayedProgress::~DelayedProgress() {
    {
        std::lock_guard lock(mMutex);
        mStopping = true;
    }
    mStop.notify_all();
    if (mTimer.joinable())
        mTimer.join();
}

void DelayedProgress::printLocked(const std::string& what) {
    mOut << "testbed: [elapsed " << formatDuration(mElapsedSeconds()) << "] " << what << "\n";
    mOut.flush();
}

void DelayedProgress::step(const std::string& what) {
    std::lock_guard lock(mMutex);
    mCurrent = what;
    if (!mLive && mElapsedSeconds() >= mDelaySeconds)
        mLive = true;
    if (mLive)
        printLocked(what);
}

void DelayedProgress::poll() {
    std::lock_guard lock(mMutex);
    if (mLive || mElapsedSeconds() < mDelaySeconds)
        return;
    mLive = true;
    if (!mCurrent.empty())
        printLocked(mCurrent + " (under way)");
}

void DelayedProgress::finish() {
    std::lock_guard lock(mMutex);
    if (mLive)
        printLocked("done");
}

} // namespace experiments
