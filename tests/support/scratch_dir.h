// SPDX-License-Identifier: Apache-2.0
// ScratchDir: a fresh, empty folder for one test, removed with everything in it when the object
// goes out of scope. Named <temp>/mogao-<tag>-<pid>-<test name>, so tests of parallel ctest runs
// (one process each) and tests of one binary never share a folder; a folder left by a crashed run
// with the same pid is emptied first.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace mogao::testing {

class ScratchDir {
public:
    explicit ScratchDir(const std::string& tag) {
        const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = std::filesystem::temp_directory_path() /
                ("mogao-" + tag + "-" + std::to_string(::getpid()) + "-" + (test != nullptr ? test->name() : "none"));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ignored;  // a destructor must not throw; a leftover folder is harmless
        std::filesystem::remove_all(path_, ignored);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace mogao::testing
