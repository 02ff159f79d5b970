// SPDX-License-Identifier: Apache-2.0
// The monitor's per-frame measurement (docs/calibration.md, "Self-recalibration"): from the
// content being projected, predict what the camera should see under the current calibration,
// match features between prediction and camera frame (ORB: Rublee, Rabaud, Konolige, Bradski 2011;
// Lowe's ratio test, Lowe 2004), and turn the matches into a robust pose of the camera and of each
// projector (robust_pose.h), using what is known: the screen is the cylinder, devices are rigid
// with fixed intrinsics and lens distortion (a bump moves a pose, never a lens), so every fit is
// on undistorted normalised rays, pinhole maths, and pixels come through the distortion
// (autocal::device_image, device_ray). Visitors in front of the screen are masked first (cells whose
// brightness disagrees with the prediction in a coherent blob; monitor.cpp, occluder_mask) so
// that the content they carry displaced never reaches a fit.
//
// Model of a match. A feature of content point c (normalised u, v) is predicted at camera image
// position q_pred (the current models: c's screen point S(c) seen by the camera) and observed at
// q_obs. Projector k shows c at its pixel x_k = P_k(S(c)) (its warp was built from its model), so
//   - if only the camera moved: q_obs = camera'(S(c)): a pose fit of the camera on (S(c), q_obs);
//   - if projector k moved: its pixel x_k now lands on S_obs = camera ray through q_obs hit with
//     the cylinder, so a pose fit of projector k on (S_obs, x_k) gives its new pose.
// The camera is fitted first on all matches but those of suspected projectors (RANSAC: the projectors that did not move
// are the consensus, which assumes fewer than half the matched features belong to moved projectors; a fit that moves
// the camera while the screen's edges in the frame stay put is rejected, edges_moved), and the projectors
// against that camera: a bumped camera is not seen as every projector moving. A match counts for projector k only where
// k's blend weight at the predicted point is at least `owner_min_blend` (in overlaps a moved projector shows a double
// image). Images: camera frames CV_32FC1 linear in [0, 1], camera resolution, pixel-index coordinates of OpenCV
// keypoints + 0.5 = image positions. Content frames CV_32FC1 linear grey, any size.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/selfcal/robust_pose.h"
#include "common/projector_calibration.h"

namespace mogao::selfcal {

// The calibrated system: screen, camera (intrinsics and pose) and each projector's model, in the
// order of the calibration's projectors.
struct SystemModel {
    autocal::ScreenModel screen;
    autocal::DeviceModel camera;
    std::vector<autocal::DeviceModel> projectors;
};

struct MonitorOptions {
    int orb_features = 3000;       // per image
    double ratio = 0.8;            // Lowe's ratio test
    double max_shift_px = 80.0;    // predicted -> observed, camera pixels
    double owner_min_blend = 0.6;  // a match belongs to a projector above this blend weight
    // In an overlap the camera sees the blend of the projectors' images: for a small move of
    // projector k alone, a feature where k's weight is w appears displaced by about w times k's
    // displacement (the weighted mean of two nearly coincident copies). Matches whose observed
    // shift is under this many camera pixels are un-mixed (screen displacement divided by w);
    // larger shifts separate the copies (the stronger one is matched) and are left as seen. 0: off.
    double unmix_max_shift_px = 1.5;
    // Visitors (occluders) in front of the screen: cells of `occluder_cell_px` camera pixels whose
    // observed mean brightness differs from the predicted one (times the frame's robust gain) by more
    // than the factor `occluder_ratio` (below it or above its inverse), in connected blobs of at
    // least `occluder_min_cells` cells, grown by one cell, lose their matches before any fit
    // (monitor.cpp, occluder_mask). 0: off.
    double occluder_ratio = 0.7;
    int occluder_cell_px = 16;
    int occluder_min_cells = 4;
    // The camera fit is checked against the screen's edges (Monitor::edges_moved): a fitted camera
    // move whose edges the frame shows unmoved is rejected (the frame gives no camera measurement).
    bool check_edges = true;
    RobustPoseOptions camera_fit{1.0, 300, 1.345, 12, 20};
    RobustPoseOptions projector_fit{6.0, 300, 1.345, 12, 12, 0.002};
};

struct ProjectorMeasurement {
    int matches = 0;              // matches owned by this projector
    PoseFit fit;                  // fit.ok = false: no measurement this frame
    Pose6 delta = Pose6::Zero();  // fitted pose against the reference model
};

struct FrameMeasurement {
    int predicted_features = 0;
    int observed_features = 0;
    int matches = 0;
    int occluded_matches = 0;            // matches dropped because they fell on a detected occluder
    double occluded_fraction = 0.0;      // of the lit screen's cells, the occluder mask's share
    PoseFit camera;                      // camera.ok = false: the reference camera was used
    bool camera_edges_disagree = false;  // the camera fit moved, the screen's edges in the frame did not: rejected
    // The consensus fit showed no camera move, but a fit to one projector's matches alone moved the
    // screen's edges as the frame shows them: that fit is the camera (Monitor::measure).
    bool camera_from_edges = false;
    Pose6 camera_delta = Pose6::Zero();
    std::vector<ProjectorMeasurement> projectors;
};

class Monitor {
public:
    // Throws std::invalid_argument when the calibration's projectors and the models differ.
    Monitor(const SystemModel& model, const ScreenCalibration& calibration, const MonitorOptions& options = {});

    // New reference (after a correction or a re-based camera): rebuilds the camera -> content maps.
    void set_reference(const SystemModel& model, const ScreenCalibration& calibration);

    // What the camera should see of `content` (linear, unscaled by exposure; 0 off the screen).
    [[nodiscard]] cv::Mat1f predict(const cv::Mat1f& content) const;

    // One frame's matches and fits. `suspects` (empty or one flag per projector): projectors
    // believed to be moving, whose matches (and the overlaps' unowned ones) the camera fit leaves
    // out, so that a small projector move inside the camera's RANSAC threshold cannot pull the
    // camera. Throws std::invalid_argument for a camera frame of the wrong size.
    // pattern_pair: `content` is the fallback's pattern P and `camera_frame` the difference of
    // the +a P and -a P frames (SelfCalibrator::step_pattern): both are smoothed and mapped
    // linearly for the detector.
    [[nodiscard]] FrameMeasurement measure(const cv::Mat1f& content, const cv::Mat1f& camera_frame,
                                           const std::vector<bool>& suspects = {}, bool pattern_pair = false) const;

    [[nodiscard]] const SystemModel& model() const { return model_; }

    // The absolute check of a camera fit: the screen is fixed, so if the camera moved to `camera`
    // its edges (top, bottom, ends; projectors overfill them, beyond is unlit) moved in the image
    // with it. Over the camera pixels within kEdgeBand pixels of the reference's edges, those that
    // `camera` would see on the screen and the reference not ("gained") and the reverse ("lost"):
    // true when the gained strip is lit and the lost one dark (mean > 2x the other + kEdgeContrast),
    // false for the reverse (the edges are where the reference has them), nullopt when either strip
    // has under kMinEdgePixels pixels (the edges not in view, or a move under a pixel) or neither holds.
    [[nodiscard]] std::optional<bool> edges_moved(const autocal::DeviceModel& camera, const cv::Mat1f& frame) const;
    // The same test between two candidate cameras: true when the frame's lit screen agrees with a's
    // edges over b's (a's strip lit, b's dark), false for the reverse, nullopt when undecided.
    // edges_moved(c) is edges_prefer(c, reference).
    [[nodiscard]] std::optional<bool> edges_prefer(const autocal::DeviceModel& a, const autocal::DeviceModel& b,
                                                   const cv::Mat1f& frame) const;
    static constexpr int kEdgeBand = 12;  // camera pixels
    static constexpr int kMinEdgePixels = 40;
    static constexpr double kEdgeContrast = 0.002;  // linear camera units (about half an 8-bit code)

private:
    // measure()'s matches as screen points: each match's screen point under the reference (from its predicted
    // position), its observed position (normalised, undistorted), its owner (projector index, 255 none) and its
    // un-mixing factor (1 / the owner's blend weight where un-mixed, else 1; MonitorOptions::unmix_max_shift_px).
    struct ScreenMatches {
        std::vector<Eigen::Vector3d> s_pred;
        std::vector<Eigen::Vector2d> obs_n;
        std::vector<int> owner;
        std::vector<double> unmix;
    };
    [[nodiscard]] ScreenMatches match_on_screen(const cv::Mat1f& content, const cv::Mat1f& camera_frame,
                                                bool pattern_pair, FrameMeasurement& m) const;
    // The camera's fit on the matches of projectors not suspected (m.camera, camera_delta and the edges' verdicts).
    void fit_camera(const ScreenMatches& sm, const cv::Mat1f& camera_frame, const std::vector<bool>& suspects,
                    bool pattern_pair, FrameMeasurement& m) const;
    // Each projector's fit on its own matches, seen through the camera m.camera holds (or the reference's).
    void fit_projectors(const ScreenMatches& sm, FrameMeasurement& m) const;

    // A camera fitted to each projector's matches alone (k's own, `owner`): among those whose edges
    // moved (edges_moved == true), the one whose edges the frame prefers to the others'; or none.
    [[nodiscard]] std::optional<PoseFit> camera_from_one_projector(const autocal::DeviceModel& camera,
                                                                   const std::vector<Eigen::Vector3d>& points,
                                                                   const std::vector<Eigen::Vector2d>& image,
                                                                   const std::vector<int>& owner,
                                                                   const cv::Mat1f& frame) const;
    static constexpr int kMinHypothesisMatches = 30;  // a projector's matches to fit the camera on

    struct EdgePixel {
        int x = 0;
        int y = 0;
        cv::Point2d ray;            // normalised, undistorted
        bool on_reference = false;  // the reference camera sees the screen there
    };
    std::vector<EdgePixel> edge_band_;
    SystemModel model_;
    MonitorOptions options_;
    cv::Mat1f map_u_;  // per camera pixel: content u under the reference (NaN: not on the lit screen)
    cv::Mat1f map_v_;
    cv::Mat1b owner_;         // projector index, 255 none (off screen or overlap)
    cv::Mat1f owner_weight_;  // the owner's blend weight (0 where none)
    cv::Mat1b mask_;          // 255 where the lit screen is predicted
};

// Screen point (x, y, z) of content (u, v) on the cylinder.
[[nodiscard]] Eigen::Vector3d screen_point(const autocal::ScreenModel& screen, double u, double v);

}  // namespace mogao::selfcal
