// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/calibration_cli.h"

#include <sstream>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_test_util.h"
#include "common/program_cli.h"

namespace mogao {
namespace {

struct CliRun {
    int code = -1;
    std::string out;
    std::string err;
};

// mogao-calibrate's MPCDI subcommands alone, as its main parses and runs them (one of them required here).
CliRun run(std::vector<std::string> args) {
    args.insert(args.begin(), "mogao-calibrate");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    std::ostringstream out;
    std::ostringstream err;
    CLI::App app{"mogao-calibrate"};
    cli::prepare(app, "mogao-calibrate");
    app.require_subcommand(1);
    MpcdiCommands cmds;
    add_mpcdi_commands(app, cmds);
    CliRun r;
    try {
        app.parse(static_cast<int>(argv.size()), argv.data());
        r.code = run_mpcdi_commands(cmds, out, err).value_or(-1);
    } catch (const CLI::ParseError& e) {
        r.code = cli::exit_status(app, e, out, err);
    }
    r.out = out.str();
    r.err = err.str();
    return r;
}

TEST(CalibrationCli, IdealWritesAFileThatPassesTheCheck) {
    test::ScratchDir dir;
    const std::string file = (dir / "ideal.mpcdi").string();
    const CliRun r = run({"ideal", "--projectors", "3", "--overlap", "0.15", "--projector-size", "256x192", "--content",
                          "480x270", "--out", file, "--check"});
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("OK"), std::string::npos) << r.out;
    const MpcdiFile f = read_mpcdi(file);
    EXPECT_EQ(f.buffers.at(0).regions.size(), 3U);
    EXPECT_EQ(f.buffers[0].resolution, (ImageSize{480, 270}));

    const CliRun info = run({"mpcdi-info", file});
    EXPECT_EQ(info.code, 0) << info.err;
    EXPECT_NE(info.out.find("profile 2d, level 3"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("region \"proj2\" 256x192"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("as a screen calibration: content 480x270, 3 projector(s)"), std::string::npos) << info.out;
}

TEST(CalibrationCli, BadCommandLinesExitTwo) {
    test::ScratchDir dir;
    const std::string out = (dir / "x.mpcdi").string();
    EXPECT_EQ(run({"ideal", "--overlap", "0.5", "--out", out}).code, 2);
    EXPECT_EQ(run({"ideal", "--projectors", "0", "--out", out}).code, 2);
    EXPECT_EQ(run({"ideal", "--projector-size", "1024x", "--out", out}).code, 2);
    EXPECT_EQ(run({"ideal", "--content", "0x5", "--out", out}).code, 2);
    EXPECT_EQ(run({"ideal", "--alpha-bits", "12", "--out", out}).code, 2);
    EXPECT_EQ(run({"ideal"}).code, 2);  // --out is required
    EXPECT_EQ(run({"mpcdi-info", (dir / "missing.mpcdi").string()}).code, 2);
    EXPECT_EQ(run({}).code, 2);
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrationCli, UnreadableFilesExitOne) {
    test::ScratchDir dir;
    test::write_bytes(dir / "bad.mpcdi", {'n', 'o'});
    const CliRun r = run({"mpcdi-info", (dir / "bad.mpcdi").string()});
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("not a ZIP archive"), std::string::npos) << r.err;
    const CliRun w = run({"ideal", "--out", (dir / "no-dir" / "x.mpcdi").string()});
    EXPECT_EQ(w.code, 1);
}

TEST(CalibrationCli, InfoOnAFixtureReportsItsNotes) {
    MOGAO_REQUIRE_FIXTURES();
    const CliRun r = run({"mpcdi-info", test::fixture("examples/SampleMPCDI.mpcdi").string()});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("profile sl, level 4"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("frustum yaw 7 pitch -8"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("note: region \"Proj0\": <gammaEmbedded>0"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace mogao
