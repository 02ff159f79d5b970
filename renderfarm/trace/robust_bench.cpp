// SPDX-License-Identifier: Apache-2.0
// Not a test: what Scene::robust_intersection (RTC_SCENE_FLAG_ROBUST on every mesh BVH) costs.
// Renders the same frame of a closed room (a box seen from inside) with a sphere, sun and sky,
// with and without the flag, in the same run on one thread, and prints the ratio (best of N CPU
// times, render_timing.h). docs/renderer.md, "Numerical stability".
//   mogao_bench_robust [--width W --height H --reps N]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "renderfarm/scene/procedural.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace {

mogao::Scene room(bool robust) {
    mogao::Scene scene;
    scene.robust_intersection = robust;
    scene.meshes = {mogao::make_box(10.0, 5.0, 10.0), mogao::make_uv_sphere(1.0, 256, 128)};
    scene.materials = {mogao::Material{}};
    mogao::Instance box{"room", 0, 0, Eigen::Affine3d::Identity()};
    box.object_to_world.translate(Eigen::Vector3d(0.0, 2.5, 0.0));
    mogao::Instance ball{"ball", 1, 0, Eigen::Affine3d::Identity()};
    ball.object_to_world.translate(Eigen::Vector3d(0.0, 1.0, -2.0));
    scene.instances = {box, ball};
    scene.point_lights = {mogao::PointLight{{1.0, 4.0, 1.0}, mogao::Rgb(20.f, 20.f, 20.f), true}};
    return scene;
}

}  // namespace

int main(int argc, char** argv) {
    int width = 320;
    int height = 180;
    int reps = 3;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const int value = std::atoi(argv[i + 1]);
        if (key == "--width") width = value;
        else if (key == "--height") height = value;
        else if (key == "--reps") reps = value;
        else {
            std::fprintf(stderr, "usage: mogao_bench_robust [--width W --height H --reps N]\n");
            return 2;
        }
    }
    mogao::ViewRequest request = mogao::test::look_at({3.0, 1.6, 4.0}, {0.0, 1.0, -2.0}, {width, height}, 70.0);
    request.quality.max_bounces = 1;
    const mogao::RendererOptions options{"threads=1", true};
    const mogao::RenderTimings fast = mogao::time_render_vs_embree(room(false), request, options, reps);
    const mogao::RenderTimings robust = mogao::time_render_vs_embree(room(true), request, options, reps);
    std::printf("%dx%d, %llu rays per frame\n", width, height, static_cast<unsigned long long>(fast.render_rays));
    std::printf("default: camera rays %.2f ms, render %.2f ms\n", fast.camera_rays_s * 1e3, fast.render_s * 1e3);
    std::printf("robust:  camera rays %.2f ms, render %.2f ms\n", robust.camera_rays_s * 1e3, robust.render_s * 1e3);
    std::printf("ratio robust/default: camera rays %.3f, render %.3f\n", robust.camera_rays_s / fast.camera_rays_s,
                robust.render_s / fast.render_s);
    return 0;
}
