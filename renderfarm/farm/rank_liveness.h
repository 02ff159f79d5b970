// SPDX-License-Identifier: Apache-2.0
// RankLiveness: when the admin takes a render rank for lost (dead host, stopped process, cut link)
// and ends the MPI job so that the farm restarts over the hosts that answer (docs/services.md,
// "Render-node failure").
//
// Liveness is a heartbeat, not a frame deadline: while a render rank works on a frame its main
// thread (the one that talks MPI, MPI_THREAD_FUNNELED) does not render; the pass's worker threads
// do (tile_pass.h, TilePassControl), and the main thread reports the pass's progress (tiles done of
// tiles assigned) to the admin every `beat_s`. A rank is lost when the admin has heard nothing
// from it (no progress report, no reply) for `silence_s` while it owes a reply:
//
//   lost(rank, now) = owes_reply(rank) and now - last_heard(rank) > silence_s + allowance(rank)
//
// One exception: when two or more ranks owe a reply and, as one of them passes the limit, every
// one of them has been silent for at least `kAllRanksSilentShare` of it, each is allowed
// `kAllRanksSilentFactor` times the limit (plus its allowance) instead, and all are named together.
// When the first of them is heard again the stall is over, and the others are judged from its end
// (their silence so far allowed, as for the admin's own stall, below): ranks resume one by one.
// A lost host silences its ranks while the others keep reporting every beat (0.1 s); all of them
// falling silent within a few beats of each other is what a stall of the machine they share looks
// like (page cache or I/O pressure, a descheduled cgroup), and the farm can serve nothing either
// way, so a restart gains nothing while the ranks may still answer. The cost: a farm whose render
// ranks all live on one host names that host's loss after the longer limit; and a rank that had
// replied to the frame before the stall owes nothing, so the others are judged by the ordinary
// limit (their silence cannot be told from a lost host's then).
//
// So how long a frame's work takes never enters the decision: a frame of any cost is answered by
// beats (a slow frame is never taken for a lost rank), and a lost rank is named `silence_s` after
// its last beat whatever the frame. A frame deadline from the frame's expected time cannot tell
// the two apart: it must cover the dearest admitted frame (seconds) to leave slow frames alone,
// and any estimate of the expected time misses some of the cost (AO and area-light samples, a
// dearer part of the scene, a loaded host), so a slow frame is taken for a lost host.
// `allowance` covers a reply's transfer, during which the rank sends nothing else (its pixels
// are on the way: the admin allows payload bytes at kSlowestLinkBytesPerSecond).
//
// Units: seconds on one monotonic clock (the caller's); ranks are MPI ranks 1..ranks.
// Errors: the constructor throws std::invalid_argument for ranks < 0 or a non-finite silence_s.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mogao {

// The slowest farm network the reply allowance assumes, bytes per second (100 Mbit/s Ethernet).
inline constexpr double kSlowestLinkBytesPerSecond = 12.5e6;
// A gap this long between two of the admin's own polls is the admin's stall (descheduled, a
// sanitizer, a long unpack), not the ranks' silence: it is allowed to every rank that owes a reply.
inline constexpr double kAdminStallS = 0.5;
// When every rank that owes a reply (two or more) is silent at once, the limit is this many times
// `silence_s` (above): a stall of a loaded two-core machine silenced two render ranks 3.9 s at once.
inline constexpr double kAllRanksSilentFactor = 4.0;
// ... when each of them has been silent for at least this share of `silence_s` as the first passes it
// (far above a beat, 0.1 s, the most by which ranks that stall together differ in their last report).
inline constexpr double kAllRanksSilentShare = 0.5;

class RankLiveness {
public:
    // A frame sent at `now` to render ranks 1..ranks, each owing a reply and counted heard at `now`;
    // silence_s <= 0: no rank is ever taken for lost.
    RankLiveness(int ranks, double silence_s, double now);

    void heard(int rank, double now);                         // a beat or a reply header from `rank`
    void allow(int rank, double extra_s);                     // `rank` may stay silent this much longer
    void replied(int rank);                                   // its reply is in: it owes nothing more
    [[nodiscard]] bool owes(int rank) const;                  // a reply is still owed by `rank`
    [[nodiscard]] std::vector<int> silent(double now) const;  // lost ranks at `now`, ascending
    // The limit the ranks `silent(now)` returned were judged by: silence_s, or kAllRanksSilentFactor
    // times it when they are every rank that owes a reply (two or more).
    [[nodiscard]] double limit_s(const std::vector<int>& silent) const;
    [[nodiscard]] double silent_for(int rank, double now) const;  // seconds since `rank` was heard
    [[nodiscard]] double silence_s() const { return silence_s_; }

private:
    struct Rank {
        double last_heard = 0.0;
        double allowance = 0.0;
        bool owes = true;
    };
    [[nodiscard]] std::size_t index(int rank) const;                        // throws for a rank outside 1..ranks
    [[nodiscard]] std::vector<int> past(double now, double limit_s) const;  // owing ranks past limit_s
    [[nodiscard]] int owing() const;
    [[nodiscard]] bool all_silent(double now) const;  // two or more owe, each kAllRanksSilentShare silent
    double silence_s_;
    std::vector<Rank> ranks_;
};

// Seconds a whole pass would have taken at full quality when it was cut `cut_at_s` seconds in
// with `done` of `total` tiles finished: cut_at_s * total / max(done, 1) (tiles of one pass cost
// alike on average; the PBT balances them). Not cut (done == total or total == 0): `seconds`.
[[nodiscard]] double full_pass_seconds(double seconds, double cut_at_s, std::uint64_t done, std::uint64_t total);

}  // namespace mogao
