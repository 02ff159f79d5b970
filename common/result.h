// SPDX-License-Identifier: Apache-2.0
// Error convention of drivers/ (kernel-, EGL- and GL-facing code): functions return Status or
// Result<T> instead of throwing, so that a missing device, a refused modeset or a lost GPU is an
// ordinary value the kiosk can log and act on (fall back to headless, retry, exit with a code).
//
//   Error    { code, message }: code is a positive errno value (ENOENT, ENODEV, EINVAL, EBUSY,
//            EACCES, EIO, ...) so callers can branch on it; message names the call or object that
//            failed and the reason (strerror, the EGL/GL error name, the limit that was exceeded).
//   Status   success, or one Error.
//   Result<T> a T, or one Error (a tiny std::expected, which C++20 lacks). T may be move-only.
//
// Reading value() of a failed Result or error() of a successful one is a programming error: it
// prints the message and aborts (there is no exception to catch in drivers/).
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

namespace mogao {

struct Error {
    int code = EIO;       // positive errno value
    std::string message;  // what failed and why
};

// An Error with `code` and `message`.
[[nodiscard]] inline Error make_error(int code, std::string message) { return Error{code, std::move(message)}; }

// An Error from the current errno: "<what>: <strerror(errno)>". Read errno before any other call.
[[nodiscard]] inline Error errno_error(std::string_view what) {
    const int code = errno != 0 ? errno : EIO;
    return Error{code, std::string(what) + ": " + std::strerror(code)};
}

// Prefixes the message with `context` ("<context>: <message>"), keeping the code.
[[nodiscard]] inline Error with_context(Error error, std::string_view context) {
    error.message = std::string(context) + ": " + error.message;
    return error;
}

namespace result_detail {
[[noreturn]] inline void misuse(const char* what, const std::string& message) {
    std::fprintf(stderr, "mogao: %s (%s)\n", what, message.c_str());
    std::abort();
}
}  // namespace result_detail

class [[nodiscard]] Status {
public:
    Status() = default;                                               // success
    Status(Error error) : error_(std::move(error)), failed_(true) {}  // NOLINT: implicit on purpose

    [[nodiscard]] bool ok() const { return !failed_; }
    explicit operator bool() const { return ok(); }
    [[nodiscard]] int code() const { return failed_ ? error_.code : 0; }
    [[nodiscard]] const Error& error() const {
        if (!failed_) result_detail::misuse("Status::error() on success", "");
        return error_;
    }

private:
    Error error_;
    bool failed_ = false;
};

template <typename T>
class [[nodiscard]] Result {
    static_assert(!std::is_same_v<std::remove_cvref_t<T>, Error>, "Result<Error> is ambiguous");
    static_assert(!std::is_reference_v<T>, "Result<T&> is not supported");

public:
    Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}      // NOLINT: implicit on purpose
    Result(Error error) : v_(std::in_place_index<1>, std::move(error)) {}  // NOLINT: implicit on purpose

    [[nodiscard]] bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }
    [[nodiscard]] int code() const { return ok() ? 0 : std::get<1>(v_).code; }

    [[nodiscard]] T& value() & {
        check();
        return std::get<0>(v_);
    }
    [[nodiscard]] const T& value() const& {
        check();
        return std::get<0>(v_);
    }
    [[nodiscard]] T&& value() && {
        check();
        return std::get<0>(std::move(v_));
    }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T&& operator*() && { return std::move(*this).value(); }

    [[nodiscard]] const Error& error() const {
        if (ok()) result_detail::misuse("Result::error() on a value", "");
        return std::get<1>(v_);
    }
    // The Status of this result (success or a copy of the error), for propagation.
    [[nodiscard]] Status status() const { return ok() ? Status{} : Status{std::get<1>(v_)}; }

private:
    void check() const {
        if (!ok()) result_detail::misuse("Result::value() on an error", std::get<1>(v_).message);
    }
    std::variant<T, Error> v_;
};

}  // namespace mogao
