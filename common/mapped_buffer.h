// SPDX-License-Identifier: Apache-2.0
// MappedBuffer: sole owner of one read-only shared mapping of a device buffer (a V4L2 capture
// buffer mapped with mmap at the offset VIDIOC_QUERYBUF returned, a KMS scanout buffer at the
// offset DRM_IOCTL_MODE_MAP_DUMB returned). Unmaps on destruction;
// move-only (UniqueHandle, common/unique_handle.h): a moved-from buffer is empty. The fd it was
// mapped from may be closed afterwards (the mapping keeps the buffer alive), but V4l2Capture
// unmaps before closing anyway.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <span>

#include "common/result.h"
#include "common/unique_handle.h"

namespace mogao {

class MappedBuffer {
public:
    // mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, offset). PROT_READ is enough for a capture
    // queue (videobuf2 only demands VM_READ there) and for reading a scanout buffer back.
    // Errors: EINVAL for length 0, else mmap's errno.
    [[nodiscard]] static Result<MappedBuffer> map(int fd, std::size_t length, off_t offset);

    MappedBuffer() = default;

    [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept {
        return {static_cast<const std::uint8_t*>(mapping_.get().address), mapping_.get().length};
    }
    [[nodiscard]] bool valid() const noexcept { return mapping_.valid(); }

private:
    // munmap needs the length too, so address and length move together; {nullptr, 0} is empty.
    struct Mapping {
        void* address = nullptr;
        std::size_t length = 0;
        bool operator==(const Mapping&) const = default;
    };
    struct Traits {
        using Value = Mapping;
        static constexpr Mapping null() noexcept { return {}; }
        static void close(Mapping mapping) noexcept;
    };
    MappedBuffer(void* address, std::size_t length) noexcept : mapping_(Mapping{address, length}) {}

    UniqueHandle<Traits> mapping_;
};

}  // namespace mogao
