// SPDX-License-Identifier: Apache-2.0
// The kiosk's state on the wall (docs/kiosk.md, "On-wall status"): a few lines of text drawn with the
// kiosk's bitmap font (bitmap_font.h) into the CONTENT frame, once per projector, at the content
// point each projector's output shows at 80 % of its height, horizontally centred in it. Drawn in
// content space, the text goes through the same warp and blend as the picture: it lands upright and
// undistorted on the curved screen, inside every projector's image (in an overlap it is lit by both,
// like the picture). A dark box behind light text keeps it readable over any content.
//
// Two uses:
//   status panel  (on demand: SIGUSR2 or [status].trigger_file; or always): self-recalibration state
//                 (calibrated / drift detected / correcting / cannot correct / waiting / off), the farm
//                 link, the calibration in use with its last refused update, and the link's
//                 certificates: a warning line for each that expires within
//                 KioskStatus::certificate_warning_days of KioskStatus::written_ns (the clock), else
//                 the days left of the first to expire
//   farm lost     a single discreet line ("FARM LOST 12 S - LAST FRAME") over the held last frame once
//                 no farm frame has arrived for [status].farm_lost_after_s; gone with the next frame.
// Pure functions; the kiosk's loop calls them on its copy of the frame it shows.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/image.h"
#include "common/projector_calibration.h"
#include "kiosk/stats/kiosk_status.h"

namespace mogao {

// The status panel's lines (upper case, the font's characters only), at most 36 characters each.
[[nodiscard]] std::vector<std::string> status_panel_lines(const KioskStatus& status);

// "FARM LOST <s> S - LAST FRAME" for the farm-lost indicator.
[[nodiscard]] std::string farm_lost_line(double lost_s);

// Draws `lines` (top to bottom) into `content` once per projector of `screen` (see above); text
// scale: as large as fits the middle 70 % of that projector's image, at most 1 font pixel per 135
// content rows, at least 1. Characters outside the
// font are drawn as '?'. Projectors whose output centre has no content (warp invalid there) get
// none. No-op for no lines.
void draw_on_wall(Rgb8Image& content, const ScreenCalibration& screen, const std::vector<std::string>& lines);

}  // namespace mogao
