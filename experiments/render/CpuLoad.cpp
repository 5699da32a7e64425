#include "experiments/render/CpuLoad.h"

#include <algorithm>
#include <cstdio>
#include <ctime>

namespace experiments {

CpuLoad judgeCpuLoad(double cpuSeconds, double wallSeconds, int threads, int hardwareThreads,
                     double fraction) {
    CpuLoad load;
    load.cpuSeconds = cpuSeconds;
    load.wallSeconds = wallSeconds;
    load.threads = threads;
    load.fraction = fraction;
    load.usableThreads =
        std::max(1, hardwareThreads > 0 ? std::min(threads, hardwareThreads) : threads);
    if (!(wallSeconds > 0.0))
        return load;
    load.cpuWallRatio = cpuSeconds / wallSeconds;
    load.loaded = load.cpuWallRatio < fraction * double(load.usableThreads);
    if (load.loaded) {
        char text[400];
        std::snprintf(text, sizeof text,
                      "the timed frames got %.2f s of CPU time in %.2f s of wall time, %.2f CPU "
                      "seconds per second with %d worker thread%s (%.0f%% of %d usable): the "
                      "machine is probably loaded and the times inflated (or the stage runs "
                      "mostly on one thread); rerun on a quiet machine before comparing them",
                      cpuSeconds, wallSeconds, load.cpuWallRatio, threads, threads == 1 ? "" : "s",
                      100.0 * load.cpuWallRatio / double(load.usableThreads), load.usableThreads);
        load.warning = text;
    }
    return load;
}

nlohmann::json CpuLoad::toJson() const {
    return {{"cpu_seconds", cpuSeconds},
            {"wall_seconds", wallSeconds},
            {"threads", threads},
            {"usable_threads", usableThreads},
            {"cpu_wall_ratio", cpuWallRatio},
            {"threshold_fraction", fraction},
            {"loaded_machine_warning", loaded},
            {"warning", warning}};
}

double processCpuSeconds() {
    timespec now{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

} // namespace experiments
