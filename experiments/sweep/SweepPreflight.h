// SweepPreflight: every job of a sweep's shard planned before the first one runs (issue 32,
// class 4: an invalid value must not be found after jobs have run). expandSweep already checks
// each job's options (cheap, no scene); this goes on to what needs the scene: the scene file loads
// (and its parse fits in memory), the view exists, the G-buffer layout the job asks for holds what
// its stage reads, and the job's peak memory estimate (MemoryEstimate.h) is within its limit
// (max-memory, default a fraction of the machine's memory). Each job is planned with
// planRenderWithScene, exactly as it will be run.
//
// Cost: one pass over the shard's jobs (as expandSweep's validation); jobs that differ only in
// their seed share one plan (the seed moves generated lights, never their count or kind), and each
// distinct scene (scene, scene options, lights, light density, brdf, view) is loaded once, in run
// order (jobs sharing a reference are adjacent), one kept at a time; each distinct plan copies
// it. Nothing is rendered and nothing is written.
//
// Errors: SweepError (exit code 2) listing the first kMaxListedInvalidJobs invalid jobs (id,
// settings, reason) and how many there are.
#pragma once

#include <cstddef>
#include <string>

#include "experiments/sweep/SweepFile.h"

namespace experiments {

void preflightSweepJobs(const SweepExpansion& expansion, size_t first, size_t last,
                        const std::string& origin);

} // namespace experiments
