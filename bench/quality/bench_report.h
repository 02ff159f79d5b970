// SPDX-License-Identifier: Apache-2.0
// What every benchmark that writes docs/ needs: the run's context line (commit, CPU, load) and the
// replacement of one generated block of a Markdown file, so figures are regenerated, never pasted.
#pragma once

#include <string>

namespace mogao::bench {

// The value after `name` on a benchmark's command line (--name VALUE), or `fallback`.
[[nodiscard]] int arg_int(int argc, char** argv, const char* name, int fallback);
[[nodiscard]] std::string arg_str(int argc, char** argv, const char* name, const char* fallback);

// The first line a command prints, trailing blanks removed ("" when it cannot run).
[[nodiscard]] std::string run_line(const std::string& command);
// The 1-minute load average (NaN when /proc/loadavg cannot be read).
[[nodiscard]] double load_average();
// /proc/cpuinfo's first "model name".
[[nodiscard]] std::string cpu_name();
// printf of one number.
[[nodiscard]] std::string fmt(const char* format, double value);
// "2026-11-26 04:30 UTC, commit `abc1234`, <CPU> (N threads)".
[[nodiscard]] std::string run_context();
// Replaces what lies between "<!-- generated:TAG -->\n" and the next "<!-- /generated -->" in
// `file` with `block`. Throws std::runtime_error naming the file when it cannot be read or written
// or has no such block.
void write_generated_block(const std::string& file, const std::string& tag, const std::string& block);
// Prints `block` to stdout and, when the command line has --write-docs FILE, writes it as FILE's
// generated block `tag` (write_generated_block).
void print_and_write_block(int argc, char** argv, const std::string& tag, const std::string& block);
// A benchmark's main: run(argc, argv), or on an exception "NAME: what" on stderr and exit status 1.
[[nodiscard]] int run_main(const char* name, int (*run)(int, char**), int argc, char** argv);

}  // namespace mogao::bench
