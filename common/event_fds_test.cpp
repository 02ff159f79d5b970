// SPDX-License-Identifier: Apache-2.0
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pthread.h>

#include <csignal>
#include <thread>

#include "common/event_fd.h"
#include "common/event_loop.h"
#include "common/signal_fd.h"
#include "common/timer_fd.h"

namespace mogao {
namespace {

// Readable within a generous bound (a missed wake-up fails; no timing is measured).
bool readable(int fd) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, 10'000) == 1 && (p.revents & POLLIN) != 0;
}

bool readable_now(int fd) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, 0) == 1;
}

TEST(EventFd, CountsSignalsUntilDrained) {
    auto wake = EventFd::create();
    ASSERT_TRUE(wake) << wake.error().message;
    EXPECT_FALSE(readable_now(wake->fd()));
    ASSERT_TRUE(wake->signal());
    ASSERT_TRUE(wake->signal());
    EXPECT_TRUE(readable_now(wake->fd()));
    auto n = wake->drain();
    ASSERT_TRUE(n);
    EXPECT_EQ(*n, 2u);
    EXPECT_FALSE(readable_now(wake->fd()));
    auto none = wake->drain();
    ASSERT_TRUE(none);
    EXPECT_EQ(*none, 0u);
}

TEST(EventFd, WakesAPollFromAnotherThread) {
    auto wake = EventFd::create();
    ASSERT_TRUE(wake);
    std::thread other([&] { ASSERT_TRUE(wake->signal()); });
    EXPECT_TRUE(readable(wake->fd()));
    other.join();
    EXPECT_EQ(*wake->drain(), 1u);
}

TEST(EventFd, IsCloseOnExec) {
    auto wake = EventFd::create();
    ASSERT_TRUE(wake);
    EXPECT_NE(::fcntl(wake->fd(), F_GETFD) & FD_CLOEXEC, 0);
}

TEST(TimerFd, FiresPeriodicallyAfterArm) {
    auto timer = TimerFd::create();
    ASSERT_TRUE(timer) << timer.error().message;
    EXPECT_NE(::fcntl(timer->fd(), F_GETFD) & FD_CLOEXEC, 0);
    EXPECT_FALSE(readable_now(timer->fd()));  // not armed
    ASSERT_TRUE(timer->arm(std::chrono::milliseconds(1)));
    for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(readable(timer->fd()));
        auto n = timer->drain();
        ASSERT_TRUE(n);
        EXPECT_GE(*n, 1u);
    }
    ASSERT_TRUE(timer->disarm());
    (void)timer->drain();
    EXPECT_FALSE(readable_now(timer->fd()));
}

TEST(TimerFd, RefusesPeriodsOutsideTheLimits) {
    auto timer = TimerFd::create();
    ASSERT_TRUE(timer);
    EXPECT_EQ(timer->arm(std::chrono::microseconds(10)).code(), EINVAL);
    EXPECT_EQ(timer->arm(std::chrono::hours(2)).code(), EINVAL);
}

TEST(SignalFd, DeliversABlockedSignalAsData) {
    sigset_t before;
    ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, nullptr, &before), 0);
    {
        auto signals = SignalFd::create({SIGUSR1});
        ASSERT_TRUE(signals) << signals.error().message;
        sigset_t now;
        ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, nullptr, &now), 0);
        EXPECT_EQ(sigismember(&now, SIGUSR1), 1);  // blocked while the SignalFd lives
        auto none = signals->read();
        ASSERT_TRUE(none);
        EXPECT_FALSE(none->has_value());
        ASSERT_EQ(::raise(SIGUSR1), 0);  // would kill the test without the SignalFd
        ASSERT_TRUE(readable(signals->fd()));
        auto got = signals->read();
        ASSERT_TRUE(got);
        ASSERT_TRUE(got->has_value());
        EXPECT_EQ(**got, SIGUSR1);
        ASSERT_EQ(::raise(SIGUSR1), 0);  // pending at destruction: consumed, not delivered
    }
    sigset_t after;
    ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, nullptr, &after), 0);
    EXPECT_EQ(sigismember(&after, SIGUSR1), sigismember(&before, SIGUSR1));  // mask restored
}

// A program's own SignalFd: a signal that arrives after it is gone (main returning, static
// destructors) must stay blocked and pending, never reach its default action.
TEST(SignalFd, KeepBlockedLeavesTheSetBlockedAfterDestruction) {
    sigset_t before;
    ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, nullptr, &before), 0);
    ASSERT_EQ(sigismember(&before, SIGUSR1), 0);
    {
        auto signals = SignalFd::create({SIGUSR1}, SignalFd::OnDestroy::keep_blocked);
        ASSERT_TRUE(signals) << signals.error().message;
    }
    sigset_t after;
    ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, nullptr, &after), 0);
    EXPECT_EQ(sigismember(&after, SIGUSR1), 1);
    ASSERT_EQ(::raise(SIGUSR1), 0);  // would kill the test if the mask had been restored
    const timespec zero{};
    sigset_t usr1;
    sigemptyset(&usr1);
    sigaddset(&usr1, SIGUSR1);
    EXPECT_EQ(::sigtimedwait(&usr1, nullptr, &zero), SIGUSR1);  // pending, not delivered
    ASSERT_EQ(::pthread_sigmask(SIG_SETMASK, &before, nullptr), 0);
}

TEST(SignalFd, RefusesAnEmptyOrInvalidSet) {
    EXPECT_EQ(SignalFd::create({}).code(), EINVAL);
    EXPECT_EQ(SignalFd::create({12345}).code(), EINVAL);
}

TEST(EventLoop, RunsHandlersOfReadableFdsUntilStopped) {
    auto a = EventFd::create();
    auto b = EventFd::create();
    ASSERT_TRUE(a && b);
    EventLoop loop;
    int a_runs = 0, b_runs = 0;
    loop.watch(-1, [] { FAIL() << "a negative fd is never polled"; });
    loop.watch(a->fd(), [&] {
        ++a_runs;
        (void)a->drain();
        ASSERT_TRUE(b->signal());
    });
    loop.watch(b->fd(), [&] {
        ++b_runs;
        (void)b->drain();
        loop.stop();
    });
    ASSERT_TRUE(a->signal());
    ASSERT_TRUE(loop.run());
    EXPECT_EQ(a_runs, 1);
    EXPECT_EQ(b_runs, 1);
    EXPECT_TRUE(loop.stopping());
    ASSERT_TRUE(loop.run());  // stopped: returns at once
}

TEST(EventLoop, RunOnceTimesOutWithoutRunningHandlers) {
    auto a = EventFd::create();
    ASSERT_TRUE(a);
    EventLoop loop;
    bool ran = false;
    loop.watch(a->fd(), [&] { ran = true; });
    ASSERT_TRUE(loop.run_once(0));
    EXPECT_FALSE(ran);
}

}  // namespace
}  // namespace mogao
