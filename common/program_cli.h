// SPDX-License-Identifier: Apache-2.0
// The command-line conventions every mogao program follows (docs/cli.md), in one place:
//
//   --version    prints "<program> <version>" (the project's version, CMakeLists.txt) and exits 0;
//   --help       lists every option with its default value ("=VALUE" after the type) and exits 0;
//   a usage error (unknown flag, missing or out-of-range value) prints CLI11's message naming the
//                flag and the limit to stderr and exits 2 -- on every MPI rank alike.
//
// Use: mogao::cli::prepare(app, "mogao-NAME") right after constructing the CLI::App, before adding options (so
// that every option captures its default), then
//   if (auto code = mogao::cli::parse(app, argc, argv)) return *code;
// Status codes beyond these (1: the job failed, 3..: program-specific) stay each program's own.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>

namespace mogao::cli {

inline constexpr int kUsageError = 2;  // the exit status of a bad command line, on every program

// The project's version string, e.g. "0.1.0".
[[nodiscard]] const char* version();

// Names the program (usage lines, --version), adds --version, and makes every option added
// afterwards (subcommands included) show its default in --help.
void prepare(CLI::App& app, const std::string& program);

// Parses; nullopt when the program should go on, else its exit status: 0 after --help/--version
// (printed to stdout), kUsageError after a usage error (printed to stderr). `quiet` suppresses the
// printing (MPI ranks other than the one that reports).
[[nodiscard]] std::optional<int> parse(CLI::App& app, int argc, const char* const* argv, bool quiet = false);

// The exit status for a ParseError caught by the caller (0 for help/version, else kUsageError),
// printing it unless quiet.
[[nodiscard]] int exit_status(const CLI::App& app, const CLI::ParseError& error, bool quiet = false);
// The same, printing to the given streams (programs whose entry point takes them, for tests).
[[nodiscard]] int exit_status(const CLI::App& app, const CLI::ParseError& error, std::ostream& out, std::ostream& err);

// Flags that more than one program declares, declared here once so that a name keeps one meaning
// and one help text everywhere (docs/cli.md, "Flag names"; the test cli_flag_names):
//   --duration-s SECONDS  stop after this long (0, the default: until SIGTERM/SIGINT): mogao-kiosk, mogao-farm serve;
CLI::Option* add_duration_flag(CLI::App& app, double& seconds);
//   --path  the scripted camera path's help text (mogao-kiosk, mogao-farm render).
inline constexpr const char* kPathHelp =
    "Scripted camera path: walk | orbit | a JSON path file (mogao-kiosk: instead of [navigation].path and .source)";

}  // namespace mogao::cli
