#include "drivers/camera/mapped_buffer.h"

#include <sys/mman.h>

#include <utility>

namespace mogao {

Result<MappedBuffer> MappedBuffer::map(int fd, std::size_t length, off_t offset) {
    if (length == 0) return make_error(EINVAL, "mmap: buffer length is 0 (the driver reported an empty buffer)");
    void* address = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, offset);
    if (address == MAP_FAILED) return errno_error("mmap of a " + std::to_string(length) + "-byte device buffer");
    return MappedBuffer(address, length);
}

MappedBuffer::MappedBuffer(MappedBuffer&& other) noexcept
    : address_(std::exchange(other.address_, nullptr)), length_(std::exchange(other.length_, 0)) {}

MappedBuffer& MappedBuffer::operator=(MappedBuffer&& other) noexcept {
    if (this != &other) {
        reset();
        address_ = std::exchange(other.address_, nullptr);
        length_ = std::exchange(other.length_, 0);
    }
    return *this;
}

MappedBuffer::~MappedBuffer() { reset(); }

void MappedBuffer::reset() noexcept {
    // munmap only fails for arguments that did not come from mmap; nothing to do about it here.
    if (address_ != nullptr) ::munmap(address_, length_);
    address_ = nullptr;
    length_ = 0;
}

}  // namespace mogao
