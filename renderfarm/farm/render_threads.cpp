// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/render_threads.h"

#include <sched.h>

#include <algorithm>
#include <climits>

namespace mogao {

int threads_per_render_rank(int host_cpus, int render_ranks_on_host) {
    return std::max(1, std::max(1, host_cpus) / std::max(1, render_ranks_on_host));
}

int usable_cpus() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) != 0) return 1;
    return std::max(1, CPU_COUNT(&set));
}

int agree_render_threads(const MpiSession& mpi, int requested, bool renders) {
    if (requested > 0) return requested;  // the same flag on every rank: none of them calls a collective
    MPI_Comm host = MPI_COMM_NULL;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, mpi.rank(), MPI_INFO_NULL, &host);
    int mine = renders ? 1 : 0, on_host = 0;
    MPI_Allreduce(&mine, &on_host, 1, MPI_INT, MPI_SUM, host);
    MPI_Comm_free(&host);
    int own = renders ? threads_per_render_rank(usable_cpus(), on_host) : INT_MAX;
    int least = INT_MAX;
    MPI_Allreduce(&own, &least, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return least == INT_MAX ? 1 : least;
}

}  // namespace mogao
