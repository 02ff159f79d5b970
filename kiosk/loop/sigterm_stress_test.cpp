// SPDX-License-Identifier: Apache-2.0
// SIGTERM (systemd's stop) at random moments of the real `mogao-kiosk` binary's life must always
// end it through its signalfd with exit code 0, never by the signal's default action (143). Four
// phases, each with its own random moments:
//   start-up     from the moment the kiosk has blocked the stop signals (its signalfd is open:
//                /proc/PID/fd) to well into its set-up (configuration, EGL, outputs, link, threads);
//   running      frames flowing from the farm (a TEST DOUBLE: the real link server over [::1] with
//                mutual TLS, answering every request with one frame) and shown on headless outputs;
//   swap         the watched MPCDI file just replaced by another calibration (loaded and swapped in
//                by the watcher thread while the signal arrives);
//   shutdown     the kiosk stopping on its own (--duration-s) as the signal arrives.
// Before its main() blocks the signals (the dynamic loader and library constructors) a process
// cannot handle SIGTERM at all; that moment is left out here (systemd counts a death by SIGTERM as a
// clean stop). MOGAO_SIGTERM_STRESS_RUNS (default 200) sets the number of runs over the phases.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/ideal_calibration.h"
#include "common/jpeg_codec.h"
#include "kiosk/config/config_overrides.h"
#include "renderfarm/link/link_test_support.h"

extern char** environ;

namespace mogao {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr ImageSize kContent{160, 90};
constexpr ImageSize kOutput{96, 72};

enum class Phase { start_up, running, swap, shutdown };

const char* name_of(Phase p) {
    switch (p) {
        case Phase::start_up:
            return "start-up";
        case Phase::running:
            return "running";
        case Phase::swap:
            return "swap";
        case Phase::shutdown:
            return "shutdown";
    }
    return "?";
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void write_ideal(const fs::path& file, double overlap, double gamma) {
    IdealCalibrationParams params;
    params.projectors = 3;
    params.overlap = overlap;
    params.output = kOutput;
    params.content = kContent;
    params.gamma = gamma;
    const fs::path tmp = file.string() + ".tmp";
    write_mpcdi(tmp, to_mpcdi(make_ideal_calibration(params)));
    fs::rename(tmp, file);  // the watcher sees one complete file, as an installer leaves it
}

// Whether the process has its signalfd open (an fd linking to "anon_inode:[signalfd]"): the kiosk
// creates it right after blocking the stop signals, first thing in main(). The blocked mask itself
// (/proc/PID/status, SigBlk) is no such mark: library constructors that start threads before main()
// (LTTng-UST's, through libcamera) block every signal for a moment and then unblock them again.
bool has_signalfd(pid_t pid) {
    std::error_code ec;
    for (const auto& fd : fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
        std::error_code link_ec;
        if (fs::read_symlink(fd.path(), link_ec).string() == "anon_inode:[signalfd]") return true;
    }
    return false;
}

struct Exit {
    bool exited = false;  // by itself (WIFEXITED), else by a signal
    int code = 0;         // exit code, or the signal number
};

// The kiosk as a child process, its stderr read line by line (with arrival times) on a thread.
class KioskProcess {
public:
    explicit KioskProcess(const std::vector<std::string>& args) {
        std::vector<char*> argv;
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        int fds[2];
        if (::pipe2(fds, O_CLOEXEC) != 0) return;
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
        if (::posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
        posix_spawn_file_actions_destroy(&actions);
        ::close(fds[1]);
        reader_ = std::thread([this, fd = fds[0]] { read_lines(fd); });
    }
    ~KioskProcess() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        if (reader_.joinable()) reader_.join();  // EOF once the kiosk is gone
    }
    KioskProcess(const KioskProcess&) = delete;
    KioskProcess& operator=(const KioskProcess&) = delete;

    [[nodiscard]] pid_t pid() const { return pid_; }
    [[nodiscard]] bool alive() {
        if (pid_ <= 0) return false;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) != pid_) return true;
        reap(status);
        return false;
    }
    Exit wait_exit() {
        if (pid_ > 0) {
            int status = 0;
            ::waitpid(pid_, &status, 0);
            reap(status);
        }
        return exit_;
    }
    // When the first stderr line containing `text` arrived (nullopt: none within `timeout`).
    std::optional<Clock::time_point> wait_line(const std::string& text, std::chrono::seconds timeout) {
        std::unique_lock lock(mutex_);
        std::optional<Clock::time_point> at;
        changed_.wait_for(lock, timeout, [&] {
            for (const auto& [t, line] : lines_) {
                if (line.find(text) != std::string::npos) at = t;
                if (at) return true;
            }
            return eof_;
        });
        return at;
    }
    std::string log() {
        std::lock_guard lock(mutex_);
        std::string all;
        for (const auto& l : lines_) all += l.second + "\n";
        return all;
    }

private:
    void read_lines(int fd) {
        std::string pending;
        char buf[4096];
        for (;;) {
            const ssize_t n = ::read(fd, buf, sizeof buf);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            pending.append(buf, static_cast<std::size_t>(n));
            for (std::size_t eol; (eol = pending.find('\n')) != std::string::npos; pending.erase(0, eol + 1)) {
                std::lock_guard lock(mutex_);
                lines_.emplace_back(Clock::now(), pending.substr(0, eol));
                changed_.notify_all();
            }
        }
        ::close(fd);
        std::lock_guard lock(mutex_);
        eof_ = true;
        changed_.notify_all();
    }
    void reap(int status) {
        exit_.exited = WIFEXITED(status);
        exit_.code = exit_.exited ? WEXITSTATUS(status) : WTERMSIG(status);
        pid_ = -1;
    }
    pid_t pid_ = -1;
    Exit exit_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<std::pair<Clock::time_point, std::string>> lines_;
    bool eof_ = false;
    std::thread reader_;  // last: started once the members above exist
};

// One kiosk at a time per worker, in its own folder (configuration, status file, watched MPCDI).
struct Worker {
    fs::path dir;
    std::mt19937 rng;
};

class SigtermStress : public ::testing::Test {
protected:
    void SetUp() override {
        if (!testing::ipv6_loopback_available()) GTEST_SKIP() << "no IPv6 loopback ([::1]) for the link";
        Rgb8Image image(kContent);
        for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<std::uint8_t>(i * 7);
        frame_.size = kContent;
        frame_.jpeg = JpegEncoder().encode(image, 90);
        farm_.emplace(testing::test_server_options(), [this](const ViewRequest&) { return frame_; });
    }

    Worker make_worker(int index) {
        Worker w{tmp_.path() / ("kiosk-" + std::to_string(index)), std::mt19937(20261125u + index)};
        fs::create_directories(w.dir);
        const auto& pki = testing::TestPki::get();
        std::ofstream(w.dir / "ca.pem") << pki.ca.cert_pem;
        std::ofstream(w.dir / "a.pem") << pki.museum1.cert_pem;
        std::ofstream(w.dir / "a.key") << pki.museum1.key_pem;
        write_ideal(w.dir / "screen.mpcdi", 0.15, 2.2);
        const std::string toml = apply_config_overrides(
            kiosk_example_toml(),
            {"farm.endpoint=\"" + farm_->endpoint().to_string() + "\"", R"(farm.ca="ca.pem")", R"(farm.cert="a.pem")",
             R"(farm.key="a.key")", "display.rate_hz=60", R"(outputs.backend="headless")", "outputs.composite=false",
             R"(calibration.source="screen.mpcdi")", "calibration.watch=true", R"(quality.content="160x90")",
             "navigation.path_frames=10", "stats.file=", R"(stats.status_file="status.json")",
             "stats.status_period_s=0.1"});
        std::ofstream(w.dir / "kiosk.toml") << toml;
        return w;
    }

    // Starts a kiosk and waits until it has blocked the stop signals (its signalfd exists).
    static std::unique_ptr<KioskProcess> start(const Worker& w, double duration_s) {
        fs::remove(w.dir / "status.json");
        // MOGAO_KIOSK_UNDER_TEST: another build of the kiosk (e.g. an older one, to see the test fail).
        const char* binary = std::getenv("MOGAO_KIOSK_UNDER_TEST");
        auto kiosk = std::make_unique<KioskProcess>(
            std::vector<std::string>{binary != nullptr ? binary : MOGAO_KIOSK_BINARY, "--config",
                                     (w.dir / "kiosk.toml").string(), "--duration-s", std::to_string(duration_s)});
        const auto guard = Clock::now() + std::chrono::seconds(20);
        while (kiosk->alive() && !has_signalfd(kiosk->pid()) && Clock::now() < guard) {
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        return kiosk;
    }

    // Waits until the status file reports frames on the wall (false: the kiosk ended or 30 s passed).
    static bool wait_frames_shown(const Worker& w, KioskProcess& kiosk) {
        const auto guard = Clock::now() + std::chrono::seconds(30);
        while (kiosk.alive() && Clock::now() < guard) {
            const auto status = nlohmann::json::parse(slurp(w.dir / "status.json"), nullptr, false);
            if (!status.is_discarded() && status.value("frames_shown", 0) > 0) return true;
            std::this_thread::sleep_for(milliseconds(5));
        }
        return false;
    }

    // One run of a phase; returns how it ended ("" with exit code 0). `shutdown_ms`: the mean time
    // from the kiosk's "stopping" line to its exit seen so far, where the shutdown phase aims.
    std::string run_once(Worker& w, Phase phase, int run, double& shutdown_ms) {
        const auto uniform_ms = [&w](int lo, int hi) {
            return milliseconds(std::uniform_int_distribution(lo, hi)(w.rng));
        };
        const auto kiosk = start(w, phase == Phase::shutdown ? 0.5 : 60.0);
        if (!kiosk->alive()) return "ended before its stop signals were blocked:\n" + kiosk->log();
        Clock::time_point at = Clock::now();
        switch (phase) {
            case Phase::start_up:  // configuration, EGL and outputs, link, threads: about 0.3-1 s
                at += uniform_ms(0, 800);
                break;
            case Phase::running:
                if (!wait_frames_shown(w, *kiosk)) return "showed no frame:\n" + kiosk->log();
                at = Clock::now() + uniform_ms(0, 200);
                break;
            case Phase::swap:
                if (!wait_frames_shown(w, *kiosk)) return "showed no frame:\n" + kiosk->log();
                write_ideal(w.dir / "screen.mpcdi", run % 2 == 0 ? 0.3 : 0.15, run % 2 == 0 ? 1.8 : 2.2);
                at = Clock::now() + uniform_ms(0, 150);
                break;
            case Phase::shutdown: {  // the kiosk stopping on its own (--duration-s): from its log line to its exit
                const auto stopping = kiosk->wait_line("stopping:", std::chrono::seconds(30));
                if (!stopping) return "never logged its stop:\n" + kiosk->log();
                at = *stopping + uniform_ms(0, static_cast<int>(1.1 * shutdown_ms) + 1);
                break;
            }
        }
        std::this_thread::sleep_until(at);
        ::kill(kiosk->pid(), SIGTERM);
        const Exit exit = kiosk->wait_exit();
        if (phase == Phase::shutdown) {
            const auto stopping = kiosk->wait_line("stopping:", std::chrono::seconds(0));
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - *stopping).count();
            shutdown_ms = 0.8 * shutdown_ms + 0.2 * ms;
        }
        if (exit.exited && exit.code == 0) return "";
        return (exit.exited ? "exit code " + std::to_string(exit.code)
                            : "killed by signal " + std::to_string(exit.code) + " (exit status " +
                                  std::to_string(128 + exit.code) + ")") +
               ":\n" + kiosk->log();
    }

    testing::TempDir tmp_;
    RenderedFrame frame_;
    std::optional<LinkServer> farm_;
};

TEST_F(SigtermStress, EverySigtermEndsTheKioskWithExitCodeZero) {
    int runs = 200;
    if (const char* env = std::getenv("MOGAO_SIGTERM_STRESS_RUNS")) runs = std::max(4, std::atoi(env));
    constexpr int kWorkers = 3;  // kiosks at a time: most of a run is waiting
    const Phase phases[] = {Phase::start_up, Phase::running, Phase::swap, Phase::shutdown};
    std::mutex mutex;
    std::map<Phase, int> done;
    std::map<Phase, int> failed;
    std::atomic<int> next{0};
    const auto start_time = Clock::now();
    std::vector<std::thread> threads;
    for (int k = 0; k < kWorkers; ++k) {
        threads.emplace_back([&, worker = make_worker(k)]() mutable {
            double shutdown_ms = 100.0;
            for (int run; (run = next++) < runs;) {
                const Phase phase = phases[run % 4];
                const std::string why = run_once(worker, phase, run, shutdown_ms);
                std::lock_guard lock(mutex);
                ++done[phase];
                if (!why.empty()) {
                    ++failed[phase];
                    ADD_FAILURE() << "run " << run << " (" << name_of(phase) << "): " << why;
                }
            }
        });
    }
    for (auto& t : threads) t.join();
    const double seconds = std::chrono::duration<double>(Clock::now() - start_time).count();
    for (const Phase p : phases) {
        std::cout << name_of(p) << ": " << done[p] - failed[p] << " of " << done[p] << " ended with exit code 0\n";
    }
    std::cout << runs << " runs (" << kWorkers << " kiosks at a time) in " << seconds << " s\n";
}

}  // namespace
}  // namespace mogao
