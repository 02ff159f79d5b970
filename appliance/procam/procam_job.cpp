// SPDX-License-Identifier: Apache-2.0
// The bench calibration job (procam_job.h).
#include "appliance/procam/procam_job.h"

#include <stdexcept>
#include <string>

#include "appliance/procam/capture_folder.h"
#include "appliance/procam/procam_error.h"

namespace mogao::procam {

BoardObservation observe_folder(const std::filesystem::path& folder, const GrayLayout& layout, const ProcamJob& job,
                                ImageSize& camera) {
    const std::vector<cv::Mat> images = load_capture_folder(folder, layout);
    const DecodedPixels decoded = decode_gray(images, layout, job.decode);
    camera = ImageSize{images[0].cols, images[0].rows};
    // Errors name the whole folder; the file names the capture by its folder's name.
    BoardObservation o = observe_board(folder.string(), images[static_cast<std::size_t>(layout.white_index())], decoded,
                                       job.board, job.homography);
    o.name = folder.filename().string();
    if (o.name.empty()) o.name = folder.parent_path().filename().string();
    return o;
}

ProcamJobResult run_procam_job(const ProcamJob& job) {
    if (job.captures.size() < 2) {
        throw std::invalid_argument("procam: needs at least 2 capture folders (board poses), got " +
                                    std::to_string(job.captures.size()));
    }
    const GrayLayout layout = gray_layout(job.projector);
    (void)board_points(job.board);  // checks the board before any image is read
    ProcamJobResult r;
    ImageSize camera{};
    for (const std::filesystem::path& folder : job.captures) {
        ImageSize size{};
        r.views.push_back(observe_folder(folder, layout, job, size));
        if (camera.width != 0 && (size.width != camera.width || size.height != camera.height)) {
            throw ProcamError(folder.string() + ": camera images " + std::to_string(size.width) + "x" +
                              std::to_string(size.height) + " differ from the first capture's " +
                              std::to_string(camera.width) + "x" + std::to_string(camera.height));
        }
        camera = size;
    }
    r.calibration = calibrate_procam(r.views, camera, job.projector, job.calibration);
    if (r.views.size() >= 3) r.held_out = leave_one_out(r.views, camera, job.projector, job.calibration);
    r.file = procam_json(r.calibration, r.held_out);
    for (std::size_t i = 0; i < r.views.size(); ++i) {
        nlohmann::json& c = r.file["captures"][i];
        c["lit_fraction"] = r.views[i].lit_fraction;
        c["decoded_fraction"] = r.views[i].decoded_fraction;
        c["corners_dropped"] = r.views[i].corners_dropped;
    }
    return r;
}

}  // namespace mogao::procam
