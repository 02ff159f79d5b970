// SPDX-License-Identifier: Apache-2.0
// mogao-kiosk-status-page: the technician's one-page status view (docs/monitoring.md, "Status page")
// from the kiosk's status file and, optionally, the calibration's output folder:
//
//   mogao-kiosk-status-page --status /run/mogao/kiosk-status.json
//       --calibration /var/lib/mogao/calibration --out status.html
//
// One self-contained HTML file (inline CSS, the calibration's preview as a data: URI, no script, no
// network), written atomically. The service mode's `status` action puts it on the USB stick next to
// the status file (kiosk/service_mode/mogao-service).
// Exit codes: 0 written; 1 the status file is missing or not the kiosk's status file, or the page
// cannot be written (the message names the file); 2 bad command line.
#include <cstdint>
#include <exception>
#include <filesystem>
#include <iostream>
#include <span>
#include <string>

#include <CLI/CLI.hpp>

#include "common/file_io.h"
#include "common/link_types.h"
#include "common/program_cli.h"
#include "kiosk/stats/kiosk_status_page.h"

int main(int argc, char** argv) {
    using namespace mogao;
    CLI::App app{
        "The kiosk's status as one self-contained HTML page for the museum technician "
        "(docs/monitoring.md, \"Status page\")"};
    cli::prepare(app, "mogao-kiosk-status-page");
    std::filesystem::path status_file = "/run/mogao/kiosk-status.json";  // the appliance's ([stats] status_file)
    std::filesystem::path calibration_dir;
    std::filesystem::path out;
    app.add_option("--status", status_file, "the kiosk's status file ([stats] status_file)");
    app.add_option("--calibration", calibration_dir,
                   "the calibration's output folder (report.json, preview.png or camera-white.png); "
                   "default: the folder of the status's calibration.source when it holds a report.json");
    app.add_option("--out", out, "the HTML file to write")->required();
    if (auto code = cli::parse(app, argc, argv)) return *code;
    try {
        StatusPageInput in;
        in.status_file = status_file;
        in.status = read_status_page_status(status_file);
        in.calibration = read_calibration_folder(calibration_folder_for(in.status, calibration_dir));
        in.made_ns = realtime_ns();
        const std::string html = kiosk_status_page_html(in);
        write_file_atomically(out, std::span(reinterpret_cast<const std::uint8_t*>(html.data()), html.size()), 0644);
        for (const std::string& p : in.calibration.problems)
            std::cerr << "mogao-kiosk-status-page: note: " << p << "\n";
        std::cout << "mogao-kiosk-status-page: wrote " << out.string() << " (" << html.size() << " bytes)\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-kiosk-status-page: " << e.what() << "\n";
        return 1;
    }
}
