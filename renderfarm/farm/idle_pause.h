// SPDX-License-Identifier: Apache-2.0
// How long a farm rank sleeps between two polls of MPI while it waits for a message, by how long it
// has waited so far.
//
// Why: Open MPI busy-polls inside its blocking calls, so the ranks wait by polling (MPI_Iprobe,
// MPI_Test) and sleeping between polls. A render rank waits between frames while the admin
// composes, denoises and encodes, and for hours while no gallery is served. Polling every 100 µs
// throughout cost an idle render rank about 5.5 % of a core (ten thousand wakeups a second, each a
// timer, two context switches and the probe's own sched_yield), taken from the render threads and
// the kiosk that share the machine. A message that follows another closely (the tiles after the
// view) is still caught within 100 µs; after a longer wait a pause of 1 ms, and 5 ms past a second,
// adds at most that to the first message of the next frame.
//
//   idle_pause(waited) = 100 µs   for waited <  5 ms
//                        1 ms     for waited <  1 s
//                        5 ms     otherwise
// Units: microseconds of steady-clock time; a negative `waited` counts as 0.
#pragma once

#include <chrono>

namespace mogao {

[[nodiscard]] constexpr std::chrono::microseconds idle_pause(std::chrono::microseconds waited) {
    using std::chrono::microseconds;
    if (waited < std::chrono::milliseconds(5)) return microseconds(100);
    if (waited < std::chrono::seconds(1)) return std::chrono::milliseconds(1);
    return std::chrono::milliseconds(5);
}

}  // namespace mogao
