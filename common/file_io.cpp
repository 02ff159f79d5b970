// SPDX-License-Identifier: Apache-2.0
#include "common/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace mogao {
namespace {

[[noreturn]] void throw_errno(int err, const std::string& what) {
    throw std::system_error(err, std::generic_category(), what);
}

// Closes the descriptor on every path out of a function.
class Fd {
public:
    explicit Fd(int fd) : fd_(fd) {}
    ~Fd() {
        if (fd_ >= 0) ::close(fd_);
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    [[nodiscard]] int get() const { return fd_; }
    // Returns close(2)'s errno (0 on success): on NFS a write error may surface only at close.
    int close_checked() {
        const int rc = ::close(std::exchange(fd_, -1));
        return rc == 0 ? 0 : errno;
    }

private:
    int fd_;
};

std::filesystem::path temp_path_for(const std::filesystem::path& path) {
    // Hidden, in the same directory (rename must not cross file systems), unique per process and call
    // so two writers of the same frame cannot interleave into one temporary.
    static std::atomic<unsigned> counter{0};
    std::filesystem::path tmp = path;
    tmp.replace_filename("." + path.filename().string() + ".tmp." + std::to_string(::getpid()) + "." +
                         std::to_string(counter.fetch_add(1)));
    return tmp;
}

// Cleans up the temporary and reports which step failed for which destination.
[[noreturn]] void fail_write(Fd& fd, const std::filesystem::path& tmp, int err, const std::string& what) {
    fd.close_checked();
    ::unlink(tmp.c_str());
    throw_errno(err, what);
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes,
                           unsigned exact_mode) {
    if (path.filename().empty()) {
        throw std::invalid_argument("write_file_atomically: '" + path.string() + "' has no file name");
    }
    const std::filesystem::path tmp = temp_path_for(path);
    const std::string where = "'" + path.string() + "'";
    Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644));
    // errno is copied first everywhere: building the message may allocate, which may touch errno.
    if (const int err = errno; fd.get() < 0) throw_errno(err, "cannot create temporary file for " + where);

    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd.get(), bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            const int err = errno;
            if (err == EINTR) continue;
            fail_write(fd, tmp, err, "cannot write " + where);
        }
        done += static_cast<std::size_t>(n);
    }
    if (exact_mode != 0 && ::fchmod(fd.get(), static_cast<mode_t>(exact_mode)) != 0) {
        const int err = errno;
        fail_write(fd, tmp, err, "cannot set the mode of " + where);
    }
    if (::fsync(fd.get()) != 0) {
        const int err = errno;
        fail_write(fd, tmp, err, "cannot fsync " + where);
    }
    if (const int err = fd.close_checked(); err != 0) {
        ::unlink(tmp.c_str());
        throw_errno(err, "cannot close " + where);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw_errno(err, "cannot rename temporary file onto " + where);
    }
}

std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path, std::uint64_t max_bytes) {
    const std::string where = "'" + path.string() + "'";
    Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
    if (const int err = errno; fd.get() < 0) throw_errno(err, "cannot open " + where);
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) {
        const int err = errno;
        throw_errno(err, "cannot stat " + where);
    }
    if (!S_ISREG(st.st_mode)) throw std::runtime_error(where + " is not a regular file");
    if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
        throw std::runtime_error(where + " is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                                 std::to_string(max_bytes));
    }
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            const int err = errno;
            if (err == EINTR) continue;
            throw_errno(err, "cannot read " + where);
        }
        if (n == 0) break;  // file shrank while we read it; return what is there
        done += static_cast<std::size_t>(n);
    }
    bytes.resize(done);
    return bytes;
}

}  // namespace mogao
