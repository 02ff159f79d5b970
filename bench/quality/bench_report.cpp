// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/bench_report.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace mogao::bench {

int arg_int(int argc, char** argv, const char* name, int fallback) {
    for (int i = 1; i + 1 < argc; ++i)
        if (std::strcmp(argv[i], name) == 0) return std::atoi(argv[i + 1]);
    return fallback;
}

std::string arg_str(int argc, char** argv, const char* name, const char* fallback) {
    for (int i = 1; i + 1 < argc; ++i)
        if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
    return fallback;
}

std::string run_line(const std::string& command) {
    std::string out;
    if (FILE* pipe = popen(command.c_str(), "r")) {
        std::array<char, 256> buffer{};
        while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) out += buffer.data();
        pclose(pipe);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

double load_average() {
    std::ifstream f("/proc/loadavg");
    double load = std::nan("");
    f >> load;
    return load;
}

std::string cpu_name() {
    std::ifstream f("/proc/cpuinfo");
    for (std::string line; std::getline(f, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown CPU";
}

std::string fmt(const char* format, double value) {
    std::array<char, 64> b{};
    std::snprintf(b.data(), b.size(), format, value);
    return b.data();
}

std::string run_context() {
    const std::time_t now = std::time(nullptr);
    std::array<char, 32> when{};
    std::strftime(when.data(), when.size(), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    return std::string(when.data()) + ", commit `" + run_line("git rev-parse --short HEAD 2>/dev/null") + "`, " +
           cpu_name() + " (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
}

void write_generated_block(const std::string& file, const std::string& tag, const std::string& block) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file);
    std::stringstream buffer;
    buffer << in.rdbuf();
    std::string text = buffer.str();
    const std::string start = "<!-- generated:" + tag + " -->\n";
    const std::string end = "<!-- /generated -->";
    const std::size_t a = text.find(start);
    const std::size_t b = a == std::string::npos ? a : text.find(end, a);
    if (b == std::string::npos) throw std::runtime_error(file + " has no '<!-- generated:" + tag + " -->' block");
    text.replace(a + start.size(), b - a - start.size(), block);
    std::ofstream out(file);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + file);
}

void print_and_write_block(int argc, char** argv, const std::string& tag, const std::string& block) {
    std::printf("%s", block.c_str());
    const std::string docs = arg_str(argc, argv, "--write-docs", "");
    if (!docs.empty()) write_generated_block(docs, tag, block);
}

int run_main(const char* name, int (*run)(int, char**), int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", name, e.what());
        return 1;
    }
}

}  // namespace mogao::bench
