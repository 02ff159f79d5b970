// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/rank_liveness.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {

RankLiveness::RankLiveness(int ranks, double silence_s, double now) : silence_s_(silence_s) {
    if (ranks < 0) throw std::invalid_argument("RankLiveness: ranks must be >= 0");
    if (!std::isfinite(silence_s)) throw std::invalid_argument("RankLiveness: silence_s must be finite");
    ranks_.assign(static_cast<std::size_t>(ranks), Rank{now, 0.0, true});
}

std::size_t RankLiveness::index(int rank) const {
    if (rank < 1 || rank > static_cast<int>(ranks_.size()))
        throw std::invalid_argument("RankLiveness: rank " + std::to_string(rank) + " is not in 1.." +
                                    std::to_string(ranks_.size()));
    return static_cast<std::size_t>(rank - 1);
}

void RankLiveness::heard(int rank, double now) {
    const std::size_t heard_index = index(rank);
    if (ranks_[heard_index].owes && all_silent(now)) {
        // A stall of the shared machine ends: the ranks resume one by one, so the ones still silent
        // are judged from its end, as for the admin's own stall (their silence so far is allowed).
        for (std::size_t i = 0; i < ranks_.size(); ++i) {
            Rank& other = ranks_[i];
            if (i != heard_index && other.owes) other.allowance = std::max(other.allowance, now - other.last_heard);
        }
    }
    Rank& r = ranks_[heard_index];
    r.last_heard = std::max(r.last_heard, now);
}

void RankLiveness::allow(int rank, double extra_s) {
    if (extra_s > 0) ranks_[index(rank)].allowance += extra_s;
}

void RankLiveness::replied(int rank) { ranks_[index(rank)].owes = false; }

bool RankLiveness::owes(int rank) const { return ranks_[index(rank)].owes; }

double RankLiveness::silent_for(int rank, double now) const { return now - ranks_[index(rank)].last_heard; }

std::vector<int> RankLiveness::past(double now, double limit_s) const {
    std::vector<int> ranks;
    for (std::size_t i = 0; i < ranks_.size(); ++i) {
        const Rank& r = ranks_[i];
        if (r.owes && now - r.last_heard > limit_s + r.allowance) ranks.push_back(static_cast<int>(i) + 1);
    }
    return ranks;
}

int RankLiveness::owing() const {
    return static_cast<int>(std::count_if(ranks_.begin(), ranks_.end(), [](const Rank& r) { return r.owes; }));
}

bool RankLiveness::all_silent(double now) const {
    const int owe = owing();
    return owe >= 2 && static_cast<int>(past(now, silence_s_ * kAllRanksSilentShare).size()) == owe;
}

std::vector<int> RankLiveness::silent(double now) const {
    if (silence_s_ <= 0) return {};
    std::vector<int> lost = past(now, silence_s_);
    if (lost.empty() || !all_silent(now)) return lost;
    // Every rank that owes fell silent together: the shared machine's stall until the longer limit,
    // then all of them are named.
    if (past(now, silence_s_ * kAllRanksSilentFactor).empty()) return {};
    return past(now, silence_s_ * kAllRanksSilentShare);
}

double RankLiveness::limit_s(const std::vector<int>& silent) const {
    const int owe = owing();
    return owe >= 2 && static_cast<int>(silent.size()) == owe ? silence_s_ * kAllRanksSilentFactor : silence_s_;
}

double full_pass_seconds(double seconds, double cut_at_s, std::uint64_t done, std::uint64_t total) {
    if (total == 0 || done >= total) return seconds;
    return cut_at_s * double(total) / double(std::max<std::uint64_t>(done, 1));
}

}  // namespace mogao
