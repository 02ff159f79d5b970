// SPDX-License-Identifier: Apache-2.0
// One RAII template for every kernel, GPU and library object the project owns (after libcamera's
// UniqueFD, generalised): a move-only sole owner of one handle value that it releases exactly once.
//
//   UniqueHandle<Traits>  owns a value of Traits::Value (an int fd, a GL name, an opaque pointer);
//                         Traits supplies null() (the "owns nothing" value) and close(v), called
//                         once for every non-null value it owns, never for null.
//   FreeWith<&fn>         a unique_ptr deleter that calls a C library's free function, so
//   UniquePtr<T, &fn>     std::unique_ptr<T, FreeWith<&fn>> owns a library object (OpenSSL, libdrm).
//
// Classes that own one handle hold a UniqueHandle member and default their moves instead of
// writing them by hand. Errors: none; close() must not throw (its failure is not actionable in a
// destructor, and the handle is gone either way).
#pragma once

#include <memory>
#include <utility>

namespace mogao {

template <typename Traits>
class UniqueHandle {
public:
    using Value = typename Traits::Value;

    UniqueHandle() = default;
    explicit UniqueHandle(Value value) noexcept : value_(value) {}
    UniqueHandle(UniqueHandle&& other) noexcept : value_(other.release()) {}
    // Releases what this owns, then takes the other's value: two owners of a reference-counted
    // handle that share one value (Mesa returns the same EGLDisplay for every open) each release.
    UniqueHandle& operator=(UniqueHandle&& other) noexcept {
        if (this != &other) {
            reset();
            value_ = other.release();
        }
        return *this;
    }
    UniqueHandle(const UniqueHandle&) = delete;
    UniqueHandle& operator=(const UniqueHandle&) = delete;
    ~UniqueHandle() { reset(); }

    [[nodiscard]] Value get() const noexcept { return value_; }
    [[nodiscard]] bool valid() const noexcept { return value_ != Traits::null(); }
    explicit operator bool() const noexcept { return valid(); }
    // Gives up ownership without closing; returns the value (or null).
    [[nodiscard]] Value release() noexcept { return std::exchange(value_, Traits::null()); }
    // Closes the owned value (if any) and takes `value`. Resetting to the value already owned keeps it.
    void reset(Value value = Traits::null()) noexcept {
        const Value old = std::exchange(value_, value);
        if (old != Traits::null() && old != value) Traits::close(old);
    }

private:
    Value value_ = Traits::null();
};

template <auto Free>
struct FreeWith {
    template <typename T>
    void operator()(T* p) const noexcept {
        if (p != nullptr) Free(p);
    }
};

template <typename T, auto Free>
using UniquePtr = std::unique_ptr<T, FreeWith<Free>>;

}  // namespace mogao
