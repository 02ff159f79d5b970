// SPDX-License-Identifier: Apache-2.0
// Quality curves: time against error for every quality knob, against converged references
// (docs/quality.md). Usually run through bench/quality/run, which also plots and fills the doc.
//
//   mogao_quality_bench [--scene scenes/grotto.json] [--scans DIR] [--width 240] [--height 136]
//       [--views walk,mask,still] [--ref-spp 1024] [--ref-budget-s 1e9] [--threads 2]
//       [--cache-dir DIR] [--renderer-version TEXT] [--reps 1] [--max-spp 256] [--max-ref-knob-spp 64]
//       [--base-spp 1,16] [--references-only | --presets-only] --out DIR
//
// Writes DIR/curves.csv (one row per frame: view, knob, value, spp, CPU ms, PSNR dB, relMSE, SSIM,
// default, note) and DIR/references.csv (per view: reference spp, seconds, the noise floor measured
// between its two halves). Curves are timed on one thread; references render on --threads.
// Exits 77 when the scene needs the real scans and they are absent.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/quality/knob_sweeps.h"
#include "bench/quality/reference_render.h"
#include "common/png_io.h"
#include "renderfarm/denoise/frame_error.h"
#include "renderfarm/scene/scene_file.h"

namespace {

using namespace mogao;
using namespace mogao::quality;

struct Options {
    std::filesystem::path scene_file = std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "grotto.json";
    SceneLoadOptions load;
    int width = 240, height = 136;
    std::vector<std::string> views{"walk", "mask", "still"};
    ReferencePlan plan;
    SweepOptions sweep;
    bool references_only = false;
    std::filesystem::path out_dir;
};

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream in(text);
    for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
    return parts;
}

Options parse(int argc, char** argv) {
    Options o;
    o.plan.cache_dir = default_cache_dir();
    o.plan.renderer_version = "unversioned";
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--references-only") {
            o.references_only = true;
            continue;
        }
        if (flag == "--presets-only") {
            o.sweep.presets_only = true;
            continue;
        }
        if (i + 1 >= argc) throw std::invalid_argument("flag " + flag + " needs a value");
        const std::string v = argv[++i];
        if (flag == "--scene") o.scene_file = v;
        else if (flag == "--scans") o.load.scans_dir = v;
        else if (flag == "--width") o.width = std::stoi(v);
        else if (flag == "--height") o.height = std::stoi(v);
        else if (flag == "--views") o.views = split(v);
        else if (flag == "--ref-spp") o.plan.spp_per_half = std::stoi(v) / 2;
        else if (flag == "--ref-budget-s") o.plan.budget_seconds = std::stod(v);
        else if (flag == "--threads") o.plan.threads = std::stoi(v);
        else if (flag == "--cache-dir") o.plan.cache_dir = v;
        else if (flag == "--renderer-version") o.plan.renderer_version = v;
        else if (flag == "--reps") o.sweep.reps = std::stoi(v);
        else if (flag == "--max-spp") o.sweep.max_spp = std::stoi(v);
        else if (flag == "--max-ref-knob-spp") o.sweep.max_reference_knob_spp = std::stoi(v);
        else if (flag == "--base-spp") {
            o.sweep.base_spp.clear();
            for (const std::string& s : split(v)) o.sweep.base_spp.push_back(std::stoi(s));
        } else if (flag == "--out") o.out_dir = v;
        else throw std::invalid_argument("unknown flag " + flag);
    }
    if (o.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
    if (o.width < 16 || o.height < 16) throw std::invalid_argument("--width/--height must be >= 16 (SSIM window)");
    if (o.plan.spp_per_half < 1) throw std::invalid_argument("--ref-spp must be >= 2");
    o.plan.batch_spp = std::min(o.plan.batch_spp, o.plan.spp_per_half);
    return o;
}

std::string read_text(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file.string());
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_curves(const std::filesystem::path& file, const std::vector<Measurement>& rows) {
    std::ofstream out(file);
    out << "view,knob,value,spp,ms,psnr_db,relmse,ssim,default,note\n";
    for (const Measurement& m : rows) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s,%s,%s,%d,%.3f,%.4f,%.6g,%.5f,%d,", m.view.c_str(), m.knob.c_str(),
                      m.value.c_str(), m.spp, m.ms, m.psnr_db, m.relmse, m.ssim, m.is_default ? 1 : 0);
        out << buf << '"' << m.note << "\"\n";
    }
    if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
}

int run(const Options& o) {
    if (read_text(o.scene_file).find("{scans}") != std::string::npos &&
        !std::filesystem::exists(resolve_scans_dir(o.scene_file, o.load))) {
        std::printf("SKIP: real scans not found at %s\n", resolve_scans_dir(o.scene_file, o.load).c_str());
        return 77;
    }
    const Scene scene = load_scene(o.scene_file, o.load, nullptr);
    ReferencePlan plan = o.plan;
    plan.scene_text = read_text(o.scene_file);
    std::filesystem::create_directories(o.out_dir);
    Renderer renderer(scene, RendererOptions{});
    std::ofstream refs(o.out_dir / "references.csv");
    refs << "view,label,width,height,spp,bounces,seconds,halves_psnr_db,halves_relmse,halves_ssim,floor_psnr_db,"
            "floor_relmse\n";
    std::vector<Measurement> rows;
    for (const QualityView& view : quality_views(scene, o.width, o.height)) {
        if (std::find(o.views.begin(), o.views.end(), view.name) == o.views.end()) continue;
        const CachedReference ref = obtain_reference(renderer, view, plan);
        const ReferenceFloor f = reference_floor(ref, scene.exposure, scene.tone_map);
        char buf[512];
        std::snprintf(buf, sizeof buf, "%s,\"%s\",%d,%d,%d,%d,%.1f,%.3f,%.6g,%.5f,%.3f,%.6g\n", view.name.c_str(),
                      view.label.c_str(), ref.half_a.size.width, ref.half_a.size.height, 2 * ref.spp_per_half,
                      kReferenceBounces, ref.seconds, f.halves_psnr_db, f.halves_relmse, f.halves_ssim, f.floor_psnr_db,
                      f.floor_relmse);
        refs << buf << std::flush;
        write_png(o.out_dir / (view.name + "-reference.png"),
                  display_frame(reference_image(ref), scene.exposure, scene.tone_map));
        std::fprintf(stderr, "reference %s: %s", view.name.c_str(), buf);
        if (o.references_only) continue;
        const std::vector<Measurement> v = sweep_knobs(scene, renderer, view, reference_image(ref), o.sweep);
        rows.insert(rows.end(), v.begin(), v.end());
        write_curves(o.out_dir / "curves.csv", rows);  // after each view: a partial run keeps its rows
    }
    if (!refs.flush()) throw std::runtime_error("cannot write references.csv");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse(argc, argv));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_quality_bench: %s\n", e.what());
        return 1;
    }
}
