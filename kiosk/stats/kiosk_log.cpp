// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_log.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>

namespace mogao {
namespace {

// "<N>": the syslog priority of the message's level (sd-daemon.h SD_ERR ... SD_DEBUG).
class SyslogPriorityFlag final : public spdlog::custom_flag_formatter {
public:
    void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
        const char* prefix = "<6>";
        switch (msg.level) {
            case spdlog::level::trace:
            case spdlog::level::debug:
                prefix = "<7>";
                break;
            case spdlog::level::info:
                prefix = "<6>";
                break;
            case spdlog::level::warn:
                prefix = "<4>";
                break;
            case spdlog::level::err:
                prefix = "<3>";
                break;
            case spdlog::level::critical:
                prefix = "<2>";
                break;
            default:
                break;
        }
        dest.append(prefix, prefix + 3);
    }
    [[nodiscard]] std::unique_ptr<custom_flag_formatter> clone() const override {
        return spdlog::details::make_unique<SyslogPriorityFlag>();
    }
};

}  // namespace

bool stderr_is_journal() {
    const char* stream = std::getenv("JOURNAL_STREAM");
    if (stream == nullptr) return false;
    struct stat st {};
    if (::fstat(STDERR_FILENO, &st) != 0) return false;
    return std::string(stream) == fmt::format("{}:{}", st.st_dev, st.st_ino);
}

void setup_kiosk_logging() {
    auto formatter = std::make_unique<spdlog::pattern_formatter>();
    formatter->add_flag<SyslogPriorityFlag>('*').set_pattern(stderr_is_journal() ? "%*%n %l: %v" : "%n %l: %v");
    spdlog::set_formatter(std::move(formatter));
    if (!spdlog::get("mogao-link")) spdlog::stderr_color_mt("mogao-link");
    auto kiosk = spdlog::get("mogao-kiosk");
    if (!kiosk) kiosk = spdlog::stderr_color_mt("mogao-kiosk");
    spdlog::set_default_logger(kiosk);
}

}  // namespace mogao
