// SPDX-License-Identifier: Apache-2.0
// ChildProcess: a program started with posix_spawn for one test (the real mogao-kiosk, say), sent
// SIGTERM and reaped when the object goes out of scope, so a failed assertion never leaves it running.
// stop() returns its exit status as a shell reports it (128 + signal when a signal ended it).
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

extern char** environ;

namespace mogao::testing {

class ChildProcess {
public:
    // args[0] is the program's path; a failed spawn leaves running() false.
    explicit ChildProcess(const std::vector<std::string>& args) {
        std::vector<char*> argv;
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        if (::posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) pid_ = -1;
    }
    ~ChildProcess() { (void)stop(); }
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    // Started and not yet reaped (by exited() or stop()).
    [[nodiscard]] bool running() const { return pid_ > 0; }

    // True once it has ended (reaped here, its status kept for stop()); never blocks.
    [[nodiscard]] bool exited() {
        if (pid_ <= 0) return true;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) != pid_) return false;
        status_ = status;
        pid_ = -1;
        return true;
    }

    // SIGTERM if still running, then its exit status.
    int stop() {
        if (pid_ > 0) {
            ::kill(pid_, SIGTERM);
            int status = 0;
            ::waitpid(pid_, &status, 0);
            status_ = status;
            pid_ = -1;
        }
        return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
    }

private:
    pid_t pid_ = -1;
    int status_ = 0;
};

}  // namespace mogao::testing
