// SPDX-License-Identifier: Apache-2.0
// The kiosk's configuration file (TOML, read with toml11): where the farm is and how to trust it,
// which outputs to drive, the projector calibration, what to ask the farm to render, how the
// scripted visitor moves, and where statistics go. The schema, one row per key with its member, type,
// limit, default and description: kiosk/config/kiosk_config_schema.h (its reference: docs/kiosk.md);
// the example: kiosk/config/kiosk.example.toml.
//
// Units: metres, degrees, hertz, seconds; sizes are "WIDTHxHEIGHT" strings in pixels.
// Relative paths in the file are resolved against the folder of the configuration file, so a
// configuration and its PKI/calibration can move together.
//
// Errors: KioskConfigError, whose message starts with the file name (and the line when toml11
// knows it) and names the field as "[section].key", with the value and the limit or reason:
//   kiosk.toml:14: [quality].spp = 0 is outside [1, 4096]
//   kiosk.toml: [farm].endpoint is required (the farm as "[address]:port")
//   kiosk.toml:3: [farm].ca: '/etc/mogao/pki/ca.pem' does not exist
//   kiosk.toml:20: [outputs].colour: unknown field (known: backend, device, sizes, png_dir, ...)
// Unknown sections and keys are errors (a typo must not silently fall back to a default). A
// parse returns a complete configuration or throws; it never returns a partial one, so a caller
// reloading a configuration keeps its last good one on error.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "appliance/navigation/navigator.h"
#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/tag_tracker.h"
#include "common/pixel_rect.h"
#include "common/size_text.h"
#include "common/view_request.h"
#include "drivers/camera/camera_source.h"

namespace mogao {

struct KioskConfigError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// [farm]: the link (renderfarm/link/link_client.h).
struct FarmConfig {
    std::string endpoint;        // required, "[address]:port", IPv6 literal, port 1..65535
    std::string server_name;     // optional DNS SAN to expect; empty: the endpoint's address
    std::filesystem::path ca;    // required, PEM of the farm CA
    std::filesystem::path cert;  // required, PEM of this appliance's certificate
    std::filesystem::path key;   // required, PEM of its private key
};

enum class OutputKind { headless, kms };

// [display] and [outputs].
struct OutputsConfig {
    double rate_hz = 30.0;  // [display].rate_hz: request + repaint tick, [0.5, 240]
    // [display].late_warp_duty: the largest share of the rasteriser's time the late warp's repaints
    // may take (kiosk/loop/repaint_pacer.h), (0, 1]; 1 = a repaint at every tick that moved the wall.
    double late_warp_duty = 1.0;
    // [display].flip_timeout_s: an output whose page flip has not completed after this long stops
    // the kiosk (exit 1) for systemd to restart it and set every mode again; 0 = off, else [1, 600].
    // 30 s: far above a healthy round anywhere measured (seconds on llvmpipe under QEMU TCG).
    double flip_timeout_s = 30.0;
    OutputKind backend = OutputKind::kms;  // "headless" | "kms"
    std::filesystem::path device;          // kms: /dev/dri/cardN; empty = first card with an output
    std::vector<ImageSize> sizes;          // headless: one per output; empty = the projectors' sizes
    std::filesystem::path png_dir;         // headless: PNG folder (created); empty = no PNGs
    int png_every = 1;                     // headless: PNGs of every k-th displayed round, [1, 1000000]
    bool composite = true;                 // headless: screen-composite.png (CPU reference) at exit
};

// [calibration]: an MPCDI file (2d profile) or the ideal layout (appliance/warp/ideal_calibration.h).
struct CalibrationConfig {
    std::filesystem::path mpcdi;  // source = FILE; empty: source = "ideal"
    bool watch = true;            // MPCDI: swap in the file when it changes (inotify; docs/kiosk.md)
    bool indirect_light =
        true;               // MPCDI: take the screen's own light off each frame (kiosk/display/frame_indirect_light.h)
    int projectors = 3;     // ideal: [1, 64]
    double overlap = 0.15;  // ideal: [0, 0.5)
    ImageSize output{1024, 768};  // ideal: each projector, [1, 16384] per side
    double gamma = 2.2;           // ideal: projector response gamma, (0, 10]
};

// [quality]: the render the kiosk requests (common/view_request.h).
struct QualityConfig {
    std::string preset;             // "": none; else a name of common/quality_preset.h, whose
                                    // request quality fills the fields below unless set
    ImageSize content{1920, 1080};  // content frame, [16, 16384] per side
    int spp = 1;                    // [1, 4096]
    int jpeg_quality = 85;          // [1, 100]
    int max_bounces = 0;            // [0, 64]
    int ao_samples = 0;             // [0, 1024]
    int area_light_samples = 1;     // [1, 1024]
};

enum class NavigationSource { path, tracking };

// What the tracking thread does when a replay camera runs out of frames (kiosk/navigation/tracking_thread.h).
enum class ReplayEnd {
    stop,  // the kiosk stops (exit 0) once the last sample has been shown: demos and tests
    loop,  // the replay starts again (timestamps continue), the kiosk runs on
    idle,  // no more samples: the view decelerates to rest and stays; the kiosk runs on
};

// [navigation].camera_exposure_us when absent with a live camera (a camera without a manual
// exposure control keeps its own; see drivers/camera/camera_controls.h). 2 ms: on the rendered
// grotto set a hand-held tag then blurs by under a pixel and its corners stay within the 0.6 px
// median corner-error goal in the room and in the dim hall, where 8 ms (the former default) blurs it by 3.4 px and
// loses tags; the detector keeps finding the tag at the gain this needs, and also with the gain
// left alone (docs/tracking.md, "Exposure of the tracking camera"; bench/tracking-grotto/exposure-study).
inline constexpr double kDefaultExposureUs = 2000.0;

// [navigation] with source = "tracking": camera -> TagTracker -> Navigator (docs/kiosk.md).
struct TrackingConfig {
    std::string camera;                      // as written: "replay:<folder>" | "v4l2:/dev/videoN" | "libcamera:[<id>]"
    CameraSourceSpec source;                 // parsed; replay folder resolved against the file's folder; live
                                             // cameras: controls and colour from camera_exposure_us,
                                             // camera_gain, camera_white_balance_k, camera_colour
    std::filesystem::path intrinsics_file;   // [navigation].intrinsics (replay default: <folder>/camera.json)
    CameraIntrinsics intrinsics;             // read; live camera: rescaled to camera_size when that differs
    double tag_size_m = 0.10;                // (0, 10]: side of the tag's black border square
    int tag_id = -1;                         // -1 (omitted): the largest tag of the family
    DetectorSettings detector;               // [navigation.detector]
    RoiSettings roi;                         // [navigation.roi]: region-of-interest tracking (tag_tracker.h)
    NavigationParams params;                 // [navigation.control]; eye_height_m from [navigation]
    ReplayEnd replay_end = ReplayEnd::stop;  // replay only
};

// [navigation]: how the visitor moves -- the scripted visitor (common/camera_path.h) or
// the tracked tag. The appliance has no scene, so the scene's viewer start and eye height are given
// here; they are the start pose of both.
struct NavigationConfig {
    NavigationSource source = NavigationSource::path;
    std::string path = "walk";             // "walk" | "orbit" | a JSON path file (must exist)
    int path_frames = 900;                 // requests per loop of the path, [2, 1000000]
    Eigen::Vector3d start{0.0, 0.0, 5.0};  // floor point of the viewer's start, world metres
    double start_yaw_deg = 0.0;            // |.| <= 3600
    double eye_height_m = 1.6;             // (0, 100]: also the screen camera's eye height
    TrackingConfig tracking;               // source = "tracking" only
};

// The viewer's start pose: eye at start + eye height, start yaw, level.
[[nodiscard]] ViewerPose start_pose(const NavigationConfig& navigation);

// [stats].
struct StatsConfig {
    std::filesystem::path file;          // JSON written at exit; empty = none
    double log_period_s = 10.0;          // stderr summary period, [0.1, 86400]
    std::filesystem::path status_file;   // kiosk/stats/kiosk_status.h, rewritten while running; empty = none
    double status_period_s = 1.0;        // its rewrite period, [0.1, 3600]
    std::filesystem::path metrics_file;  // kiosk/stats/kiosk_metrics.h, rewritten with the status; empty = none
    int frames_kept =
        4096;  // KioskStats::kDefaultFramesKept: per-frame records kept for the statistics file, [0, 1000000]
    std::filesystem::path frame_log;  // every frame's record as a JSON line (kiosk/stats/frame_log.h); empty = none
};

// [status]: the state on the wall (kiosk/display/on_wall_status.h, docs/kiosk.md "On-wall status").
enum class OnWall {
    off,        // never (SIGUSR2 is logged and ignored)
    on_demand,  // while toggled on by SIGUSR2, or while trigger_file exists
    always,
};
struct StatusConfig {
    OnWall on_wall = OnWall::on_demand;
    std::filesystem::path trigger_file;  // on_demand: the panel shows while this file exists; empty = none
    double farm_lost_after_s = 10.0;     // no farm frame for this long: the indicator; 0 = never, [0, 86400]
    // The link's certificates expiring within this many days: a warning line on the status panel
    // and "expires_soon" in the status file; 0 = never, [0, 3650].
    double certificate_warning_days = 30.0;
};

// [selfcal]: continuous self-recalibration (kiosk/live_calibration/selfcal_worker.h, docs/kiosk.md
// "Self-recalibration"). Only read in full when enabled; then [calibration].source must be an MPCDI
// file (the corrections are written back to it) and the models file must exist.
struct SelfcalConfig {
    enum class CameraKind { v4l2, rig };
    bool enabled = false;
    std::string camera;  // as written: "v4l2:/dev/videoN" | "rig:<rig.toml>"
    CameraKind kind = CameraKind::v4l2;
    CameraSourceSpec source;          // v4l2: device; size (0x0: the models' camera); controls
                                      // (exposure and gain locked or manual, never automatic)
    std::filesystem::path rig;        // rig: the virtual rig file -- a SIMULATED screen camera
                                      // (tests and demos), never a measurement of the wall
    std::filesystem::path models;     // autocal/model_store.h; default <mpcdi>.models.json
    double rate_hz = 2.0;             // monitored frames a second, (0, 2]
    double hold_s = 2.0;              // drift held this long before correcting, [0, 600]
    double transition_s = 3.0;        // correction blended in over this long, [0, 600]
    double drift_threshold_px = 0.5;  // (0, 100] projector pixels
    // The content-independent fallback (selfcal::PatternOptions): when the content gives too little
    // evidence, a complementary dot-pattern pair of this amplitude (fraction of full white, (0, 0.2])
    // is added to the wall for one camera frame each. Off by default: without it a plain scene waits.
    bool pattern = false;
    double pattern_amplitude = 0.02;
};

struct KioskConfig {
    std::filesystem::path source;  // the file it was read from
    FarmConfig farm;
    OutputsConfig outputs;
    CalibrationConfig calibration;
    QualityConfig quality;
    CylinderScreen screen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};  // [screen]; eye_m from navigation
    // [screen].guard_deg: the late rotational warp's band each side of the arc (appliance/warp/
    // late_warp.h), [0, (360 - arc_deg) / 2] degrees; 0 = off (the farm renders the arc only).
    double guard_deg = 0.0;
    NavigationConfig navigation;
    StatsConfig stats;
    StatusConfig status;
    SelfcalConfig selfcal;
};

// Reads and validates `file`. Throws KioskConfigError.
[[nodiscard]] KioskConfig load_kiosk_config(const std::filesystem::path& file);
// Only [display] and [outputs] of a kiosk configuration (other sections are not read: the service
// card's fallback configuration, kiosk/display/service_screen.h). Same errors as load_kiosk_config.
[[nodiscard]] OutputsConfig load_outputs_config(const std::filesystem::path& file);
[[nodiscard]] OutputsConfig parse_outputs_config(std::string_view text, const std::filesystem::path& name);

// Validates TOML `text` as if read from `name` (messages and relative paths use it).
[[nodiscard]] KioskConfig parse_kiosk_config(std::string_view text, const std::filesystem::path& name);

// "WIDTHxHEIGHT": parse_size (common/size_text.h).

}  // namespace mogao
