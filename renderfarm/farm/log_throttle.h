// SPDX-License-Identifier: Apache-2.0
// LogThrottle: at most one journal line per key (a session and a kind of event) per interval, so
// that an event that repeats with every request (a visitor pressing against the view policy's
// edge changes the eye, and so the line, 60 times a second) writes about one line a minute, not
// one per frame. A farm serves for years; its journal must not grow with its frames.
//
//   allow(key, now) = first event of `key`, or now - last_written(key) >= interval_s
//
// and a written line carries how many events of its key were held back since the previous one
// (the metrics count every event). Keys are forgotten beyond `max_keys` (sessions come and go):
// the next event of a forgotten key is written at once.
//
// Units: seconds on the caller's monotonic clock. Errors: the constructor throws
// std::invalid_argument for a non-finite or negative interval or max_keys == 0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace mogao {

class LogThrottle {
public:
    explicit LogThrottle(double interval_s = 60.0, std::size_t max_keys = 1024);

    struct Verdict {
        bool write = false;           // write this event's line
        std::uint64_t held_back = 0;  // events of this key not written since its last line
    };
    [[nodiscard]] Verdict allow(const std::string& key, double now_s);

private:
    struct Key {
        double written_s = 0.0;
        std::uint64_t held_back = 0;
    };
    double interval_s_;
    std::size_t max_keys_;
    std::map<std::string, Key> keys_;
};

// " (N more since the last line)" for held_back > 0, else "": the suffix of a throttled line.
[[nodiscard]] std::string held_back_note(std::uint64_t held_back);

// Seconds on the steady clock, for LogThrottle's callers.
[[nodiscard]] double log_clock_s();

}  // namespace mogao
