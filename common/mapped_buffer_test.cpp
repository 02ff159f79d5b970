// SPDX-License-Identifier: Apache-2.0
#include "common/mapped_buffer.h"

#include <sys/mman.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/unique_fd.h"

namespace mogao {
namespace {

static_assert(!std::is_copy_constructible_v<MappedBuffer> && std::is_nothrow_move_constructible_v<MappedBuffer> &&
              std::is_nothrow_move_assignable_v<MappedBuffer>);

// A memfd standing in for a V4L2 buffer: one page filled with `fill`.
UniqueFd page_file(unsigned char fill) {
    UniqueFd fd(::memfd_create("mapped_buffer_test", MFD_CLOEXEC));
    EXPECT_TRUE(fd.valid()) << std::strerror(errno);
    const std::vector<unsigned char> bytes(static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)), fill);
    EXPECT_EQ(::write(fd.get(), bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
    return fd;
}

// Whether [address, address + length) is mapped in this process: mincore fails with ENOMEM for
// any unmapped page in the range.
bool is_mapped(const void* address, std::size_t length) {
    std::vector<unsigned char> pages((length + static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)) - 1) /
                                     static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)));
    return ::mincore(const_cast<void*>(address), length, pages.data()) == 0;
}

TEST(MappedBuffer, MoveLeavesTheSourceEmptyAndTheTargetUnmapsOnce) {
    const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    UniqueFd fd = page_file(0x5a);
    auto mapped = MappedBuffer::map(fd.get(), page, 0);
    ASSERT_TRUE(mapped) << mapped.error().message;
    const std::uint8_t* address = mapped->bytes().data();
    ASSERT_TRUE(is_mapped(address, page));

    std::optional<MappedBuffer> source(std::move(mapped).value());
    MappedBuffer target = std::move(*source);
    EXPECT_FALSE(source->valid());  // NOLINT(bugprone-use-after-move)
    EXPECT_TRUE(source->bytes().empty());
    source.reset();
    EXPECT_TRUE(is_mapped(address, page)) << "destroying the moved-from buffer unmapped it";
    ASSERT_EQ(target.bytes().data(), address);
    ASSERT_EQ(target.bytes().size(), page);
    EXPECT_EQ(target.bytes()[page - 1], 0x5a);

    {
        MappedBuffer last = std::move(target);
        EXPECT_FALSE(target.valid());  // NOLINT(bugprone-use-after-move)
    }
    EXPECT_FALSE(is_mapped(address, page)) << "the last owner did not unmap";
}

TEST(MappedBuffer, AssignmentUnmapsTheOldMappingAndTakesTheNewOne) {
    const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    UniqueFd fd_a = page_file(0x11);
    UniqueFd fd_b = page_file(0x22);
    auto a = MappedBuffer::map(fd_a.get(), page, 0);
    auto b = MappedBuffer::map(fd_b.get(), page, 0);
    ASSERT_TRUE(a && b);
    const std::uint8_t* old_address = a->bytes().data();
    const std::uint8_t* new_address = b->bytes().data();

    MappedBuffer target = std::move(a).value();
    target = std::move(b).value();
    EXPECT_FALSE(is_mapped(old_address, page));
    EXPECT_TRUE(is_mapped(new_address, page));
    EXPECT_EQ(target.bytes().data(), new_address);
    EXPECT_EQ(target.bytes()[0], 0x22);

    MappedBuffer empty;
    EXPECT_FALSE(empty.valid());
    target = std::move(empty);  // an empty buffer replaces it: unmapped, nothing owned
    EXPECT_FALSE(target.valid());
    EXPECT_FALSE(is_mapped(new_address, page));
}

TEST(MappedBuffer, ZeroLengthIsEINVAL) {
    UniqueFd fd = page_file(0);
    auto mapped = MappedBuffer::map(fd.get(), 0, 0);
    ASSERT_FALSE(mapped);
    EXPECT_EQ(mapped.code(), EINVAL);
}

}  // namespace
}  // namespace mogao
