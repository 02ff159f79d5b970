// SPDX-License-Identifier: Apache-2.0
// RAII for the MPI runtime (Open MPI): one MpiSession per process, created first in main() and
// destroyed last. Rank 0 is the admin (scene description, view, PBT, compositing, encoding);
// ranks 1..N-1 render.
#pragma once

#include <mpi.h>

namespace mogao {

class MpiSession {
public:
    MpiSession(int* argc, char*** argv) {
        int provided = 0;
        // Only the main thread of each rank calls MPI; render threads never do.
        MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
    }
    ~MpiSession() { MPI_Finalize(); }
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;

    [[nodiscard]] int rank() const { return rank_; }
    [[nodiscard]] int size() const { return size_; }
    [[nodiscard]] bool is_admin() const { return rank_ == 0; }
    [[nodiscard]] int render_ranks() const { return size_ > 1 ? size_ - 1 : 0; }

    // True on every rank when `ok` is true on every rank. A collective: every rank must call it,
    // so a rank that is about to give up calls it too instead of returning alone (a rank that
    // returns early sits in MPI_Finalize while the others wait for it in their next collective).
    [[nodiscard]] bool all(bool ok) const {
        int mine = ok ? 1 : 0, every = 0;
        MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        return every == 1;
    }

private:
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace mogao
