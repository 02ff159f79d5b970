// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/procedural.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <fmt/format.h>

namespace mogao {
namespace {

constexpr double kPi = std::numbers::pi;

void require_range(const char* name, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi))
        throw std::invalid_argument(fmt::format("{} = {} is outside [{}, {}]", name, value, lo, hi));
}

// splitmix64: a fixed, platform-independent hash, so the room is identical on every rank and host.
std::uint64_t splitmix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}
double unit_random(std::uint32_t seed, std::uint64_t index) {
    return static_cast<double>(splitmix((std::uint64_t{seed} << 32) ^ index) >> 11) * 0x1.0p-53;
}

// Smooth, 2π-periodic bumpiness in [-1, 1]: a few sinusoids with seeded phases and frequencies.
struct WallNoise {
    static constexpr int kTerms = 6;
    double phase_a[kTerms]{}, phase_b[kTerms]{}, freq_y[kTerms]{};
    explicit WallNoise(std::uint32_t seed) {
        for (int k = 0; k < kTerms; ++k) {
            phase_a[k] = 2 * kPi * unit_random(seed, 3u * k);
            phase_b[k] = 2 * kPi * unit_random(seed, 3u * k + 1);
            freq_y[k] = 0.5 + 2.5 * unit_random(seed, 3u * k + 2);
        }
    }
    double operator()(double theta, double y) const {
        double sum = 0, norm = 0;
        for (int k = 0; k < kTerms; ++k) {
            const double amplitude = 1.0 / (k + 1);
            sum += amplitude * std::sin((2 * k + 3) * theta + phase_a[k]) * std::cos(freq_y[k] * y + phase_b[k]);
            norm += amplitude;
        }
        return sum / norm;
    }
};

std::uint32_t add_vertex(Mesh& mesh, double x, double y, double z) {
    mesh.positions.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
}

// Adds triangle (a, b, c), flipped if needed so that its normal points along `facing`.
void add_oriented(Mesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, const Eigen::Vector3f& facing) {
    const Eigen::Vector3f n = (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
    if (n.dot(facing) >= 0) mesh.triangles.push_back({a, b, c});
    else mesh.triangles.push_back({a, c, b});
}

}  // namespace

Mesh make_grotto_room(const GrottoRoomParams& p) {
    require_range("radius", p.radius, 0.5, 1000);
    require_range("height", p.height, 0.5, 1000);
    require_range("dome_height", p.dome_height, 0, 1000);
    require_range("entrance_deg", p.entrance_deg, 0, 179.999);
    require_range("segments", p.segments, 8, 65536);
    require_range("rings", p.rings, 1, 65536);
    require_range("roughness", p.roughness, 0, 0.2);

    Mesh mesh;
    mesh.source = "procedural:grotto_room";
    const WallNoise noise(p.seed);
    const int seg = p.segments;
    const auto theta_of = [&](int i) { return 2 * kPi * i / seg; };  // 0 = +z, toward +x
    const auto wall_radius = [&](double theta, double y) { return p.radius * (1 + p.roughness * noise(theta, y)); };
    const double half_gap = p.entrance_deg * kPi / 360;
    const auto in_entrance = [&](double theta_mid) {
        const double wrapped = std::remainder(theta_mid, 2 * kPi);
        return std::abs(wrapped) < half_gap;
    };

    // Wall (rings+1 rows) and dome (dome_rings rows above it) share one grid of vertices.
    const int dome_rings = p.dome_height > 0 ? std::max(2, p.rings / 4) : 0;
    const int rows = p.rings + 1 + dome_rings;
    std::vector<std::uint32_t> grid(static_cast<std::size_t>(rows) * seg);
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < seg; ++i) {
            const double theta = theta_of(i);
            double y, r;
            if (j <= p.rings) {
                y = p.height * j / p.rings;
                r = wall_radius(theta, y);
            } else {
                const double phi = 0.5 * kPi * (j - p.rings) / dome_rings;  // up to the apex
                y = p.height + p.dome_height * std::sin(phi);
                r = wall_radius(theta, p.height) * std::cos(phi);
            }
            grid[static_cast<std::size_t>(j) * seg + i] = add_vertex(mesh, r * std::sin(theta), y, r * std::cos(theta));
        }
    }
    for (int j = 0; j + 1 < rows; ++j) {
        for (int i = 0; i < seg; ++i) {
            const int i1 = (i + 1) % seg;
            const double theta_mid = 0.5 * (theta_of(i) + theta_of(i + 1));
            if (j < p.rings && in_entrance(theta_mid)) continue;
            const Eigen::Vector3f inward(static_cast<float>(-std::sin(theta_mid)), j < p.rings ? 0.f : -1.f,
                                         static_cast<float>(-std::cos(theta_mid)));
            const auto at = [&](int jj, int ii) { return grid[static_cast<std::size_t>(jj) * seg + ii]; };
            add_oriented(mesh, at(j, i), at(j, i1), at(j + 1, i1), inward);
            // The last dome row is the apex (radius 0): its second triangle would be degenerate.
            if (j + 2 < rows || dome_rings == 0) add_oriented(mesh, at(j, i), at(j + 1, i1), at(j + 1, i), inward);
        }
    }

    // Floor: polar grid out to the wall's foot, facing +y.
    const int floor_rings = std::max(2, p.rings / 4);
    const std::uint32_t centre = add_vertex(mesh, 0, 0, 0);
    std::vector<std::uint32_t> floor_grid(static_cast<std::size_t>(floor_rings) * seg);
    for (int k = 1; k <= floor_rings; ++k) {
        for (int i = 0; i < seg; ++i) {
            const double theta = theta_of(i);
            const double r = wall_radius(theta, 0) * k / floor_rings;
            floor_grid[static_cast<std::size_t>(k - 1) * seg + i] =
                add_vertex(mesh, r * std::sin(theta), 0, r * std::cos(theta));
        }
    }
    const Eigen::Vector3f up(0, 1, 0);
    for (int i = 0; i < seg; ++i) {
        const int i1 = (i + 1) % seg;
        add_oriented(mesh, centre, floor_grid[i], floor_grid[i1], up);
        for (int k = 1; k < floor_rings; ++k) {
            const auto at = [&](int kk, int ii) { return floor_grid[static_cast<std::size_t>(kk - 1) * seg + ii]; };
            add_oriented(mesh, at(k, i), at(k + 1, i), at(k + 1, i1), up);
            add_oriented(mesh, at(k, i), at(k + 1, i1), at(k, i1), up);
        }
    }
    return mesh;
}

Mesh make_box(double sx, double sy, double sz) {
    require_range("size_x", sx, 1e-9, 1e9);
    require_range("size_y", sy, 1e-9, 1e9);
    require_range("size_z", sz, 1e-9, 1e9);
    Mesh mesh;
    mesh.source = "procedural:box";
    const Eigen::Vector3d half(sx / 2, sy / 2, sz / 2);
    // Six faces with their own vertices so that smooth normals stay flat per face.
    for (int axis = 0; axis < 3; ++axis) {
        for (int sign : {-1, 1}) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::uint32_t corner[4];
            for (int c = 0; c < 4; ++c) {
                Eigen::Vector3d p;
                p[axis] = sign * half[axis];
                p[u] = (c == 1 || c == 2 ? 1 : -1) * half[u];
                p[v] = (c >= 2 ? 1 : -1) * half[v];
                corner[c] = add_vertex(mesh, p.x(), p.y(), p.z());
            }
            Eigen::Vector3f outward = Eigen::Vector3f::Zero();
            outward[axis] = static_cast<float>(sign);
            add_oriented(mesh, corner[0], corner[1], corner[2], outward);
            add_oriented(mesh, corner[0], corner[2], corner[3], outward);
        }
    }
    return mesh;
}

Mesh make_uv_sphere(double radius, int segments, int rings) {
    require_range("radius", radius, 1e-9, 1e9);
    require_range("segments", segments, 3, 65536);
    require_range("rings", rings, 2, 65536);
    Mesh mesh;
    mesh.source = "procedural:uv_sphere";
    for (int j = 0; j <= rings; ++j) {
        const double phi = kPi * j / rings;  // 0 at +y
        for (int i = 0; i <= segments; ++i) {
            const double theta = 2 * kPi * i / segments;
            const Eigen::Vector3d n(std::sin(phi) * std::sin(theta), std::cos(phi), std::sin(phi) * std::cos(theta));
            add_vertex(mesh, radius * n.x(), radius * n.y(), radius * n.z());
            mesh.normals.push_back(n.cast<float>());
        }
    }
    const auto at = [&](int j, int i) { return static_cast<std::uint32_t>(j * (segments + 1) + i); };
    for (int j = 0; j < rings; ++j) {
        for (int i = 0; i < segments; ++i) {
            const Eigen::Vector3f outward = (mesh.normals[at(j, i)] + mesh.normals[at(j + 1, i + 1)]).normalized();
            if (j > 0) add_oriented(mesh, at(j, i), at(j + 1, i), at(j, i + 1), outward);
            if (j + 1 < rings) add_oriented(mesh, at(j, i + 1), at(j + 1, i), at(j + 1, i + 1), outward);
        }
    }
    return mesh;
}

Mesh make_ground_plane(double size, int n) {
    require_range("size", size, 1e-9, 1e9);
    require_range("subdivisions", n, 1, 65536);
    Mesh mesh;
    mesh.source = "procedural:ground_plane";
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            add_vertex(mesh, size * (static_cast<double>(i) / n - 0.5), 0, size * (static_cast<double>(j) / n - 0.5));
            mesh.normals.emplace_back(0.f, 1.f, 0.f);
        }
    const auto at = [&](int j, int i) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    const Eigen::Vector3f up(0, 1, 0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            add_oriented(mesh, at(j, i), at(j + 1, i), at(j + 1, i + 1), up);
            add_oriented(mesh, at(j, i), at(j + 1, i + 1), at(j, i + 1), up);
        }
    return mesh;
}

}  // namespace mogao
