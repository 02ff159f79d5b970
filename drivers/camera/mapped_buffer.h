// MappedBuffer: sole owner of one read-only shared mapping of a device buffer (a V4L2 capture
// buffer mapped with mmap at the offset VIDIOC_QUERYBUF returned). Unmaps on destruction;
// move-only. The fd it was mapped from may be closed afterwards (the mapping keeps the buffer
// alive), but V4l2Capture unmaps before closing anyway.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <span>

#include "common/result.h"

namespace mogao {

class MappedBuffer {
public:
    // mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, offset). PROT_READ is enough for a capture
    // queue (videobuf2 only demands VM_READ there). Errors: EINVAL for length 0, else mmap's errno.
    [[nodiscard]] static Result<MappedBuffer> map(int fd, std::size_t length, off_t offset);

    MappedBuffer() = default;
    MappedBuffer(MappedBuffer&& other) noexcept;
    MappedBuffer& operator=(MappedBuffer&& other) noexcept;
    MappedBuffer(const MappedBuffer&) = delete;
    MappedBuffer& operator=(const MappedBuffer&) = delete;
    ~MappedBuffer();

    [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept {
        return {static_cast<const std::uint8_t*>(address_), length_};
    }
    [[nodiscard]] bool valid() const noexcept { return address_ != nullptr; }

private:
    MappedBuffer(void* address, std::size_t length) noexcept : address_(address), length_(length) {}
    void reset() noexcept;

    void* address_ = nullptr;
    std::size_t length_ = 0;
};

}  // namespace mogao
