// SPDX-License-Identifier: Apache-2.0
#include "common/mapped_buffer.h"

#include <sys/mman.h>

namespace mogao {

Result<MappedBuffer> MappedBuffer::map(int fd, std::size_t length, off_t offset) {
    if (length == 0) return make_error(EINVAL, "mmap: buffer length is 0 (the driver reported an empty buffer)");
    void* address = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, offset);
    if (address == MAP_FAILED) return errno_error("mmap of a " + std::to_string(length) + "-byte device buffer");
    return MappedBuffer(address, length);
}

void MappedBuffer::Traits::close(Mapping mapping) noexcept {
    // munmap only fails for arguments that did not come from mmap; nothing to do about it here.
    ::munmap(mapping.address, mapping.length);
}

}  // namespace mogao
