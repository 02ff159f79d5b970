// SPDX-License-Identifier: Apache-2.0
// How many render threads each render rank runs (`mogao-farm --threads`, 0 = automatic).
//
// Automatic: the CPUs this process may run on (its affinity mask, so a taskset or a cgroup's
// cpuset counts), shared equally among the render ranks on the same host (MPI shared-memory
// domain), at least one; then the least of that over all render ranks, so that every rank runs as
// many threads as the others: the PBT splits a frame by predicted cost and takes the render ranks as
// equally fast (rank_speed.h corrects only for a rank's share of its cores). The admin does not
// count: while the ranks render it waits, and it filters and encodes only while they wait.
// Why threads and not more ranks on one host: a frame ends with its slowest rank, and a rank whose
// core is taken a while (the kiosk on a shared machine, the admin's encode) holds the frame up;
// threads of one rank share its tiles dynamically (tile_pass.h) and absorb that.
//
// Errors: none beyond MPI's (its error handler aborts the job).
#pragma once

#include "renderfarm/farm/mpi_session.h"

namespace mogao {

// Threads for one render rank: host_cpus / render_ranks_on_host, at least 1 (inputs below 1 count as 1).
[[nodiscard]] int threads_per_render_rank(int host_cpus, int render_ranks_on_host);

// The CPUs this process may run on (sched_getaffinity), at least 1.
[[nodiscard]] int usable_cpus();

// Every rank's render thread count: `requested` when > 0 (it must be the same on every rank),
// else the automatic count above, a collective that every rank calls (`renders`: this rank traces
// frames). Returns the same value on every rank.
[[nodiscard]] int agree_render_threads(const MpiSession& mpi, int requested, bool renders);

}  // namespace mogao
