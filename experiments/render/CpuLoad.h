// CpuLoad: whether the timed frames of a render had the CPU they asked for. A render's times are
// wall-clock times; on a loaded machine (other processes competing for the cores) its threads
// wait for a core and every time is inflated. The process's CPU time over the same interval says
// so: with T worker threads on a machine with at least T cores, an unloaded run keeps close to T
// threads busy (the G-buffer pass scales 1.95x on 2 threads), so CPU seconds per wall second well
// below T mean the threads were waiting. A stage that runs mostly on one thread lowers the ratio
// too, which the warning says.
//
// Measured by RenderJob over the timed repetitions (G-buffer pass and stage, after the warm-up
// runs; without warm-up the first repetition's stage only, its G-buffer pass running among the
// scene's serial preparation) with CLOCK_PROCESS_CPUTIME_ID (every thread of the process) and the
// steady clock, summed over the repetitions; judged
// by judgeCpuLoad, a pure function of the figures so that tests can force either verdict. Written
// to stats.json (`cpu_load`) and, when loaded, as a warning on stderr by `testbed render`.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace experiments {

// Warn when the threads were busy less than this fraction of the time they could have been: 0.5
// flags the loads that at least double the times (the 2-core development machine under a load of
// 16 measured about 0.15) and leaves room for stages that scale imperfectly.
inline constexpr double kLoadedMachineFraction = 0.5;

struct CpuLoad {
    double cpuSeconds = 0.0;   // process CPU time over the timed repetitions, every thread
    double wallSeconds = 0.0;  // wall time over the same interval
    int threads = 0;           // the render's worker threads
    int usableThreads = 0;     // min(threads, hardware threads): the most CPU seconds per second
    double cpuWallRatio = 0.0; // cpuSeconds / wallSeconds: threads busy on average
    double fraction = kLoadedMachineFraction; // the threshold judged against
    bool loaded = false;                      // cpuWallRatio < fraction * usableThreads
    std::string warning; // what to tell the user when loaded, with the figures; else ""

    nlohmann::json toJson() const; // cpu_seconds, wall_seconds, ..., loaded_machine_warning
};

// The verdict on measured figures (no clock is read): loaded when the threads were busy less than
// `fraction` of the time (usable threads x wall time). Nothing is judged (loaded false) when the
// wall time is not positive.
CpuLoad judgeCpuLoad(double cpuSeconds, double wallSeconds, int threads, int hardwareThreads,
                     double fraction = kLoadedMachineFraction);

// CPU time of the whole process so far, in seconds (CLOCK_PROCESS_CPUTIME_ID).
double processCpuSeconds();

} // namespace experiments
