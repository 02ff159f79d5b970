// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/camera_intrinsics.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace mogao {
namespace {

constexpr int kMaxSide = 8192;

void require(bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
}

std::string lower_extension(const std::filesystem::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

CameraIntrinsics from_json(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw CalibrationFileError(path.string() + ": cannot be read");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw CalibrationFileError(path.string() + ": not valid JSON: " + e.what());
    }
    if (!j.is_object()) throw CalibrationFileError(path.string() + ": top level is not a JSON object");
    const auto field = [&](const char* key) -> const nlohmann::json& {
        if (!j.contains(key)) throw CalibrationFileError(path.string() + ": missing field \"" + key + "\"");
        if (!j.at(key).is_number())
            throw CalibrationFileError(path.string() + ": field \"" + key + "\" is not a number");
        return j.at(key);
    };
    const auto integer = [&](const char* key) {
        const auto& v = field(key);
        if (!v.is_number_integer())
            throw CalibrationFileError(path.string() + ": field \"" + key + "\" is not an integer");
        const auto n = v.get<long long>();
        if (n < 1 || n > kMaxSide) {
            throw CalibrationFileError(path.string() + ": field \"" + key + "\" = " + std::to_string(n) +
                                       " outside [1, " + std::to_string(kMaxSide) + "]");
        }
        return static_cast<int>(n);
    };
    CameraIntrinsics c;
    c.width = integer("image_width");
    c.height = integer("image_height");
    c.fx = field("fx").get<double>();
    c.fy = field("fy").get<double>();
    c.cx = field("cx").get<double>();
    c.cy = field("cy").get<double>();
    if (j.contains("distortion")) {
        const auto& d = j.at("distortion");
        if (!d.is_array()) throw CalibrationFileError(path.string() + ": field \"distortion\" is not an array");
        for (const auto& v : d) {
            if (!v.is_number()) throw CalibrationFileError(path.string() + ": field \"distortion\" holds a non-number");
            c.distortion.push_back(v.get<double>());
        }
    }
    return c;
}

CameraIntrinsics from_opencv(const std::filesystem::path& path) {
    CameraIntrinsics c;
    try {
        cv::FileStorage fs(path.string(), cv::FileStorage::READ);
        if (!fs.isOpened()) throw CalibrationFileError(path.string() + ": cannot be opened as OpenCV YAML/XML");
        const auto read_int = [&](const char* key) {
            const cv::FileNode n = fs[key];
            if (n.empty() || !n.isInt()) throw CalibrationFileError(path.string() + ": missing integer field " + key);
            const int v = static_cast<int>(n);
            if (v < 1 || v > kMaxSide) {
                throw CalibrationFileError(path.string() + ": " + key + " = " + std::to_string(v) + " outside [1, " +
                                           std::to_string(kMaxSide) + "]");
            }
            return v;
        };
        c.width = read_int("image_width");
        c.height = read_int("image_height");
        cv::Mat k;
        fs["camera_matrix"] >> k;
        if (k.rows != 3 || k.cols != 3)
            throw CalibrationFileError(path.string() + ": camera_matrix is not a 3x3 matrix");
        k.convertTo(k, CV_64F);
        c.fx = k.at<double>(0, 0);
        c.fy = k.at<double>(1, 1);
        c.cx = k.at<double>(0, 2);
        c.cy = k.at<double>(1, 2);
        cv::Mat d;
        fs["distortion_coefficients"] >> d;
        if (!d.empty()) {
            if (d.rows != 1 && d.cols != 1)
                throw CalibrationFileError(path.string() + ": distortion_coefficients is not a vector");
            d.convertTo(d, CV_64F);
            d = d.reshape(1, 1);
            c.distortion.assign(d.ptr<double>(0), d.ptr<double>(0) + d.cols);
        }
    } catch (const cv::Exception& e) {
        throw CalibrationFileError(path.string() + ": " + e.what());
    }
    return c;
}

}  // namespace

void validate(const CameraIntrinsics& c) {
    require(c.width >= 1 && c.width <= kMaxSide && c.height >= 1 && c.height <= kMaxSide,
            "CameraIntrinsics: image size " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                " outside [1, " + std::to_string(kMaxSide) + "]");
    require(std::isfinite(c.fx) && c.fx > 0.0 && std::isfinite(c.fy) && c.fy > 0.0,
            "CameraIntrinsics: fx and fy must be finite and > 0 (fx " + std::to_string(c.fx) + ", fy " +
                std::to_string(c.fy) + ")");
    require(std::isfinite(c.cx) && c.cx >= -0.5 && c.cx <= c.width - 0.5,
            "CameraIntrinsics: cx " + std::to_string(c.cx) +
                " outside [-0.5, width - 0.5 = " + std::to_string(c.width - 0.5) + "]");
    require(std::isfinite(c.cy) && c.cy >= -0.5 && c.cy <= c.height - 0.5,
            "CameraIntrinsics: cy " + std::to_string(c.cy) +
                " outside [-0.5, height - 0.5 = " + std::to_string(c.height - 0.5) + "]");
    const auto n = c.distortion.size();
    require(n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14,
            "CameraIntrinsics: " + std::to_string(n) + " distortion coefficients; OpenCV takes 0, 4, 5, 8, 12 or 14");
    require(std::all_of(c.distortion.begin(), c.distortion.end(), [](double v) { return std::isfinite(v); }),
            "CameraIntrinsics: a distortion coefficient is not finite");
}

CameraIntrinsics rescale(const CameraIntrinsics& c, int width, int height) {
    require(width >= 1 && height >= 1,
            "rescale: target size " + std::to_string(width) + "x" + std::to_string(height) + " below 1x1");
    const double sx = static_cast<double>(width) / c.width;
    const double sy = static_cast<double>(height) / c.height;
    CameraIntrinsics r = c;
    r.width = width;
    r.height = height;
    r.fx = c.fx * sx;
    r.fy = c.fy * sy;
    r.cx = (c.cx + 0.5) * sx - 0.5;
    r.cy = (c.cy + 0.5) * sy - 0.5;
    return r;
}

CameraIntrinsics read_intrinsics(const std::filesystem::path& path) {
    const std::string ext = lower_extension(path);
    CameraIntrinsics c;
    if (ext == ".json") {
        c = from_json(path);
    } else if (ext == ".yml" || ext == ".yaml" || ext == ".xml") {
        c = from_opencv(path);
    } else {
        throw CalibrationFileError(path.string() + ": unknown calibration format '" + ext +
                                   "' (use .json, .yml, .yaml or .xml)");
    }
    try {
        validate(c);
    } catch (const std::invalid_argument& e) {
        throw CalibrationFileError(path.string() + ": " + e.what());
    }
    return c;
}

void write_intrinsics(const std::filesystem::path& path, const CameraIntrinsics& c, double rms_px) {
    validate(c);
    nlohmann::json j{{"image_width", c.width},
                     {"image_height", c.height},
                     {"fx", c.fx},
                     {"fy", c.fy},
                     {"cx", c.cx},
                     {"cy", c.cy},
                     {"distortion", c.distortion},
                     {"pixel_convention", "opencv: centre of the top-left pixel is (0, 0)"}};
    if (rms_px >= 0.0) j["rms_reprojection_px"] = rms_px;
    std::ofstream out(path);
    out << j.dump(2) << '\n';
    if (!out) throw CalibrationFileError(path.string() + ": cannot be written");
}

}  // namespace mogao
