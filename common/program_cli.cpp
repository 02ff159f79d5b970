// SPDX-License-Identifier: Apache-2.0
#include "common/program_cli.h"

#include <iostream>
#include <sstream>
#include <string>

namespace mogao::cli {

const char* version() { return MOGAO_VERSION; }

void prepare(CLI::App& app, const std::string& program) {
    app.name(program);
    app.set_version_flag("--version", program + " " + version());
    // Defaults in --help: CLI11 shows "=VALUE" after the type of an option whose default was
    // captured; without this only options given ->capture_default_str() show theirs.
    app.option_defaults()->always_capture_default();
}

int exit_status(const CLI::App& app, const CLI::ParseError& error, std::ostream& out, std::ostream& err) {
    // CLI::App::exit prints --help/--version to `out` and the error (with "Run with --help") to `err`;
    // it is const in all but name.
    return const_cast<CLI::App&>(app).exit(error, out, err) == 0 ? 0 : kUsageError;
}

int exit_status(const CLI::App& app, const CLI::ParseError& error, bool quiet) {
    if (!quiet) return exit_status(app, error, std::cout, std::cerr);
    std::ostringstream out, err;
    return exit_status(app, error, out, err);
}

std::optional<int> parse(CLI::App& app, int argc, const char* const* argv, bool quiet) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return exit_status(app, e, quiet);
    }
    return std::nullopt;
}

CLI::Option* add_duration_flag(CLI::App& app, double& seconds) {
    return app.add_option("--duration-s", seconds, "Stop after this many seconds (0 = until SIGTERM or SIGINT)")
        ->check(CLI::Range(0.0, 1e9));
}

}  // namespace mogao::cli
