# SPDX-License-Identifier: Apache-2.0
"""Builds the mogao scene in Blender Cycles from bench/peer's export and renders it (docs/quality.md,
"A peer: Blender Cycles"). Run by bench/peer/run inside Blender:

  blender -b --factory-startup --python-exit-code 1 -P bench/peer/cycles_scene.py -- \
      --dir DIR --spp 1,4,16,64|none [--ref-spp 1024|0] [--threads 1] [--ref-threads 2] [--window FILE]

Reads DIR/scene.obj, DIR/peer.json (mogao_peer_bench export). Writes DIR/cycles-<spp>.pfm (seed 1, on
--threads threads) and DIR/cycles-ref-a.pfm, cycles-ref-b.pfm (two halves of ref-spp/2 samples, seeds 1000/1001),
DIR/cycles-times.csv (spp, CPU s of the Blender process during bpy.ops.render.render, wall s) and
DIR/cycles-calibration.csv. Linear radiance, PFM rows bottom up (as Blender's pixel buffers).

Mapping (each one checked or stated in docs/quality.md):
  * material: f = (1 - k_s) a / pi + k_s GGX  ->  Add Shader(Diffuse BSDF colour (1 - k_s) a,
    Glossy BSDF 'GGX' colour k_s, roughness sqrt(alpha)) (Cycles' roughness r gives alpha = r^2). Exact
    in form; Cycles' single-scattering GGX uses the separable Smith G1(o) G1(i), ours the
    height-correlated G2 (differs at grazing angles only). Principled BSDF is not used: its Fresnel
    term and specular tint have no counterpart in our model. A textured material (peer.json "texture")
    multiplies its diffuse colour by an Image Texture node (sRGB, bilinear 'Linear', REPEAT or EXTEND as
    both wrap modes say): ours filters the same texels by ray-cone mip level, Cycles has no mip chain.
  * lights: strength chosen so that a white Lambert plane receives our irradiance. The factor per light
    type is MEASURED here on every run (calibrate()): a white plane under each light alone, compared
    with the analytic irradiance; so no assumption about Blender's watts conventions enters. Point:
    radius 0; sun: angle 0; area: rectangle, one-sided, invisible to the camera (ours is invisible to
    camera rays); environment: world background colour.
  * camera: pinhole, vertical fov (sensor fit vertical), camera-to-world = [R | eye] from peer.json
    (both look along local -z with +y up); pixel filter box 1 px (ours: uniform jitter in the pixel).
  * integrator: max 6 bounces of every kind (our reference knobs), no clamping, no filter glossy,
    no denoiser, no adaptive sampling, caustics on: unbiased path tracing as ours.
"""
import argparse
import json
import math
import os
import sys
import time

import bpy
import mathutils
import numpy as np


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser()
    p.add_argument("--dir", required=True)
    p.add_argument("--spp", default="1,4,16,64", help="'none': no curve (the reference alone)")
    p.add_argument("--ref-spp", type=int, default=1024, help="0: no reference (the curve alone)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--ref-threads", type=int, default=2)
    p.add_argument("--reps", type=int, default=1)
    p.add_argument("--window", default="", help="write 'START END': CLOCK_MONOTONIC s around the spp renders "
                   "(bench/profile/run profiles them alone)")
    return p.parse_args(argv)


def setup_render(width, height):
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.render.resolution_x, s.render.resolution_y, s.render.resolution_percentage = width, height, 100
    s.render.pixel_aspect_x = s.render.pixel_aspect_y = 1.0
    s.render.use_persistent_data = True  # keep the BVH between renders: the timed renders do not rebuild it
    s.cycles.use_denoising = False
    s.cycles.use_adaptive_sampling = False
    s.cycles.max_bounces = 6
    for kind in ("diffuse", "glossy", "transmission", "volume", "transparent_max"):
        setattr(s.cycles, kind if kind.endswith("_max") else kind + "_bounces", 6)
    s.cycles.sample_clamp_direct = 0.0
    s.cycles.sample_clamp_indirect = 0.0
    s.cycles.blur_glossy = 0.0
    s.cycles.caustics_reflective = True
    s.cycles.caustics_refractive = True
    s.cycles.pixel_filter_type = "BOX"
    s.cycles.filter_width = 1.0
    s.view_settings.view_transform = "Standard"
    s.view_settings.look = "None"
    s.view_settings.exposure = 0.0
    s.view_settings.gamma = 1.0
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    s.render.image_settings.exr_codec = "NONE"
    s.render.threads_mode = "FIXED"


def render_pixels(tmp_exr):
    """Renders, returns (H, W, 3) float32 rows bottom up, CPU s, wall s of the render call."""
    c0, w0 = time.process_time(), time.perf_counter()
    bpy.ops.render.render()
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    bpy.data.images["Render Result"].save_render(tmp_exr)
    img = bpy.data.images.load(tmp_exr, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[:, :, :3].copy(), cpu, wall


def write_pfm(path, rgb_bottom_up):
    h, w, _ = rgb_bottom_up.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(rgb_bottom_up.astype("<f4").tobytes())


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def add_camera(matrix, fov_deg):
    cam = bpy.data.cameras.new("cam")
    cam.type = "PERSP"
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(fov_deg)
    cam.clip_start = 1e-3
    obj = bpy.data.objects.new("cam", cam)
    bpy.context.scene.collection.objects.link(obj)
    obj.matrix_world = matrix
    bpy.context.scene.camera = obj


def look_from(eye, rotation_rows):
    m = mathutils.Matrix.Identity(4)
    for r in range(3):
        for c in range(3):
            m[r][c] = rotation_rows[r][c]
        m[r][3] = eye[r]
    return m


def frame(x_axis, y_axis, centre):
    """4x4 with columns x, y, x cross y (local -z = where a Blender light shines), translation centre."""
    x, y = mathutils.Vector(x_axis).normalized(), mathutils.Vector(y_axis).normalized()
    z = x.cross(y)
    m = mathutils.Matrix.Identity(4)
    for r in range(3):
        m[r][0], m[r][1], m[r][2], m[r][3] = x[r], y[r], z[r], centre[r]
    return m


def add_light(spec, factors):
    """One light of peer.json; factors[type] = Blender strength per unit of our quantity (calibrated; for
    area lights per unit radiance and per m^2 of the 1 m^2 calibration light)."""
    t = spec["type"]
    factor = factors.get(t, 1.0)
    if t == "environment":
        world = bpy.context.scene.world or bpy.data.worlds.new("world")
        bpy.context.scene.world = world
        world.use_nodes = True
        bg = world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (*spec["radiance"], 1.0)
        bg.inputs["Strength"].default_value = 1.0
        return
    quantity = {"point": "intensity", "sun": "irradiance", "area": "radiance"}[t]
    value = spec[quantity]
    peak = max(value)
    light = bpy.data.lights.new(t, {"point": "POINT", "sun": "SUN", "area": "AREA"}[t])
    light.color = [v / peak for v in value] if peak > 0 else (0, 0, 0)
    light.energy = factor * peak  # area: per m^2 (Blender's strength is a power), scaled below
    light.cycles.cast_shadow = spec.get("cast_shadows", True)
    obj = bpy.data.objects.new(t, light)
    if t == "point":
        light.shadow_soft_size = 0.0
        obj.location = spec["position"]
    elif t == "sun":
        light.angle = 0.0
        d = mathutils.Vector(spec["direction_to_light"]).normalized()
        obj.rotation_euler = d.to_track_quat("Z", "Y").to_euler()  # local +z toward the light: shines along -d
    else:
        u, v = mathutils.Vector(spec["edge_u"]), mathutils.Vector(spec["edge_v"])
        if abs(u.normalized().dot(v.normalized())) > 1e-6:
            raise SystemExit("area light: edges not perpendicular, a parallelogram has no Blender equivalent")
        light.shape = "RECTANGLE"
        light.size, light.size_y = u.length, v.length
        light.energy *= u.length * v.length
        centre = mathutils.Vector(spec["corner"]) + 0.5 * u + 0.5 * v
        obj.matrix_world = frame(u, -v, centre)  # x u, y -v: local -z = u x v, our emitting side
        obj.visible_camera = False
    bpy.context.scene.collection.objects.link(obj)


def make_material(name, spec, folder=None):
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    ks = spec["specular"]
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*[(1 - k) * a for k, a in zip(ks, spec["albedo"])], 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert (Oren-Nayar off)
    if spec.get("texture"):
        # Our tint: (1 - k_s) a times the texture's linear colour (sRGB decoded, as texture.h), bilinear on
        # level 0 (Cycles has no mip chain: ours filters by ray cone, a model mismatch the report measures).
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = bpy.data.images.load(os.path.join(folder, spec["texture"]))
        tex.image.colorspace_settings.name = "sRGB"
        tex.interpolation = "Linear"
        tex.extension = "EXTEND" if spec.get("wrap") == ["clamp", "clamp"] else "REPEAT"
        tint = nodes.new("ShaderNodeVectorMath")
        tint.operation = "MULTIPLY"
        tint.inputs[1].default_value = [(1 - k) * a for k, a in zip(ks, spec["albedo"])]
        links.new(tex.outputs["Color"], tint.inputs[0])
        links.new(tint.outputs["Vector"], diffuse.inputs["Color"])
    if max(ks) <= 0:
        links.new(diffuse.outputs[0], out.inputs["Surface"])
        return mat
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    glossy.inputs["Color"].default_value = (*ks, 1.0)
    glossy.inputs["Roughness"].default_value = math.sqrt(spec["ggx_alpha"])
    add = nodes.new("ShaderNodeAddShader")
    links.new(diffuse.outputs[0], add.inputs[0])
    links.new(glossy.outputs[0], add.inputs[1])
    links.new(add.outputs[0], out.inputs["Surface"])
    return mat


def rect_corner_form_factor(x, y):
    """Form factor from a point to an x by y rectangle (units of its height) with one corner above it,
    parallel to the receiver (Howell, A Catalog of Radiation Heat Transfer Configuration Factors, B-3)."""
    a, b = x / math.sqrt(1 + x * x), y / math.sqrt(1 + y * y)
    return (a * math.atan(y / math.sqrt(1 + x * x)) + b * math.atan(x / math.sqrt(1 + y * y))) / (2 * math.pi)


def calibrate(spp=256):
    """Blender strength per unit of our light quantity, measured: a white Lambert plane at y = 0 under
    each light alone (the plane is the only geometry: light leaving it never returns, so the image is direct
    light at any bounce count), seen by a 10-degree camera 1 m above (its centre 2x2 pixels); its radiance is E / pi.
    Returns {type: factor} and rows (type, our irradiance, Cycles radiance at strength 1)."""
    h, side = 2.0, 1.0
    expected = {  # irradiance on the plane at the origin for unit intensity / irradiance / radiance
        "point": 1.0 / (h * h),
        "sun": 1.0,
        "area": math.pi * 4 * rect_corner_form_factor(0.5 * side / h, 0.5 * side / h),
        # a 2 m x 1 m light: checks that Blender's area strength scales with the area as add_light assumes
        "area-2x1": math.pi * 4 * rect_corner_form_factor(1.0 / h, 0.5 / h),
    }
    specs = {
        "point": {"type": "point", "position": [0, h, 0], "intensity": [1, 1, 1]},
        "sun": {"type": "sun", "direction_to_light": [0, 1, 0], "irradiance": [1, 1, 1]},
        "area": {"type": "area", "corner": [-0.5 * side, h, -0.5 * side], "edge_u": [side, 0, 0],
                 "edge_v": [0, 0, side], "radiance": [1, 1, 1]},  # emits toward u x v = -y
        "area-2x1": {"type": "area", "corner": [-1.0, h, -0.5], "edge_u": [2.0, 0, 0], "edge_v": [0, 0, 1.0],
                     "radiance": [1, 1, 1]},
    }
    factors, rows = {}, []
    for t, spec in specs.items():
        clear()
        bpy.ops.mesh.primitive_plane_add(size=10.0, rotation=(-math.pi / 2, 0, 0))  # normal +z -> +y
        bpy.context.active_object.data.materials.append(
            make_material("white", {"albedo": [1, 1, 1], "specular": [0, 0, 0], "ggx_alpha": 1}))
        add_light(spec, {"point": 1.0, "sun": 1.0, "area": 1.0, "area-2x1": 1.0})
        add_camera(look_from([0, 1, 0], [[1, 0, 0], [0, 0, 1], [0, -1, 0]]), 10.0)
        setup_render(8, 8)
        s = bpy.context.scene
        s.cycles.samples = spp
        s.render.threads = 2
        px, _, _ = render_pixels(os.path.join(bpy.app.tempdir, "calibration.exr"))
        measured = float(px[3:5, 3:5].mean())  # centre 2x2 pixels (within 1.1 cm): radiance = E_cycles / pi
        factors[t] = expected[t] / (math.pi * measured)
        rows.append((t, expected[t], measured, factors[t]))
    if abs(factors["area-2x1"] / factors["area"] - 1) > 0.02:
        raise SystemExit(f"calibration: area strength does not scale with the area: {rows}")
    return factors, rows


def obj_bounds(path):
    """Bounds of the file's vertices and its face count."""
    faces, verts = 0, []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(line.split()[1:4])
            elif line.startswith("f "):
                faces += 1
    v = np.array(verts, dtype=float)
    return v.min(axis=0), v.max(axis=0), faces


def build_scene(d, peer, factors):
    clear()
    obj_path = os.path.join(d, "scene.obj")
    bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="Y", up_axis="Z")  # no axis change: +y stays up
    lo, hi, faces = np.full(3, np.inf), np.full(3, -np.inf), 0
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        co = np.empty(len(obj.data.vertices) * 3)
        obj.data.vertices.foreach_get("co", co)
        w = np.array(obj.matrix_world)
        co = co.reshape(-1, 3) @ w[:3, :3].T + w[:3, 3]
        lo, hi = np.minimum(lo, co.min(axis=0)), np.maximum(hi, co.max(axis=0))
        faces += len(obj.data.polygons)
        if obj.data.has_custom_normals:
            obj.data.use_auto_smooth = True
            obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
    # The importer drops vertices no face uses (the file keeps every loaded vertex), so the imported bounds
    # must lie inside the file's, and every face must arrive: a moved, scaled or rotated import fails.
    flo, fhi, ffaces = obj_bounds(obj_path)
    if (lo < flo - 1e-4).any() or (hi > fhi + 1e-4).any() or faces != ffaces:
        raise SystemExit(f"OBJ import changed the scene: bounds {lo} {hi} faces {faces}, file {flo} {fhi} {ffaces}")
    print("imported %d triangles, bounds %s %s" % (faces, lo, hi), flush=True)
    for name, spec in peer["materials"].items():
        make_material(name, spec, d)
    for spec in peer["lights"]:
        add_light(spec, factors)
    cam = peer["camera"]
    add_camera(look_from(cam["eye"], cam["rotation_rows"]), cam["vertical_fov_deg"])
    setup_render(cam["width"], cam["height"])


def main():
    a = parse()
    factors, rows = calibrate()
    with open(os.path.join(a.dir, "cycles-calibration.csv"), "w") as f:
        f.write("light,our_irradiance_per_unit,cycles_radiance_per_strength,strength_per_unit\n")
        for r in rows:
            f.write("%s,%.6g,%.6g,%.6g\n" % r)
    print("calibration", rows, flush=True)
    with open(os.path.join(a.dir, "peer.json")) as f:
        peer = json.load(f)
    t0 = time.perf_counter()
    build_scene(a.dir, peer, factors)
    s = bpy.context.scene
    tmp = os.path.join(bpy.app.tempdir, "frame.exr")
    s.render.threads, s.cycles.samples, s.cycles.seed = a.threads, 1, 0
    _, warm_cpu, warm_wall = render_pixels(tmp)  # scene sync and BVH build (kept: persistent data)
    print("import and warm-up %.1f s (first render %.2f s CPU), sampling pattern %s"
          % (time.perf_counter() - t0, warm_cpu, s.cycles.sampling_pattern), flush=True)
    times = ["spp,cpu_s,wall_s"]
    window_start = time.monotonic()  # CLOCK_MONOTONIC, as perf record -k mono
    for spp in [] if a.spp == "none" else [int(x) for x in a.spp.split(",")]:
        s.cycles.samples, s.cycles.seed = spp, 1
        best = None
        for _ in range(a.reps):
            px, cpu, wall = render_pixels(tmp)
            best = (cpu, wall) if best is None or cpu < best[0] else best
        write_pfm(os.path.join(a.dir, "cycles-%d.pfm" % spp), px)
        times.append("%d,%.6f,%.6f" % (spp, *best))
        print(times[-1], flush=True)
    if a.window:
        with open(a.window, "w") as f:
            f.write("%.6f %.6f\n" % (window_start, time.monotonic()))
    s.render.threads = a.ref_threads
    for half, seed in (("a", 1000), ("b", 1001)) if a.ref_spp > 0 else ():
        s.cycles.samples, s.cycles.seed = a.ref_spp // 2, seed
        px, cpu, wall = render_pixels(tmp)
        write_pfm(os.path.join(a.dir, "cycles-ref-%s.pfm" % half), px)
        print("reference half %s: %d spp, %.1f s wall" % (half, a.ref_spp // 2, wall), flush=True)
    if len(times) > 1:
        with open(os.path.join(a.dir, "cycles-times.csv"), "w") as f:
            f.write("\n".join(times) + "\n")
            f.write("# warm-up render (sync + BVH + 1 spp) cpu_s %.6f wall_s %.6f\n" % (warm_cpu, warm_wall))


main()
