#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Fills the <!-- generated:selfcal-scenarios --> table of docs/calibration.md: runs
`mogao-calibrate-sim selfcal-simulate` on rigs/standard.toml for each scenario (bumps of 0.2, 1 and 3 degrees in
yaw, pitch and roll and of 2, 5 and 10 mm along x, y and z, two projectors at once (also alike), the camera bumped
(also with two projectors), plain and
repetitive content, a projector pushed off the screen, a long static run with noise, exposure
changes and visitors) and writes what it printed: detection time, time to under 1 projector pixel
of geometric error against the rig's ground truth, final error, CPU per monitored frame.
Figures there are never pasted.

  tools/docs/regenerate_selfcal_doc.py [--build build-calib] [--static-frames 240] [--long-static-frames 1200]
                                           [--only scenarios|autocal]

A second table (<!-- generated:selfcal-from-autocal -->) starts the monitor from a full
calibration's estimate instead of the rig's exact models: `mogao-calibrate-sim rig --rig RIG --scale S`
on the same rig, its calibration.models.json passed to `mogao-calibrate-sim selfcal-simulate --models`:
rigs/standard.toml at half resolution and at full resolution (three 1920x1080 projectors, the 1280x720
camera: the appliance's own cost per monitored frame), and the rigs/realistic*.toml rigs (a real
installation's errors, projector lens distortion kept) at half resolution, realistic-lens also at full.
--only regenerates one of the two tables.

--long-static-frames is the long static run (default 1200: 10 simulated minutes; 7200: the
simulated hour, a benchmark of about 20 minutes of a core; 0: none), run beside the others at
quarter projector resolution, with its false detections and corrections and the steady-state
share of one core.
Python 3 standard library only.
"""
import argparse, datetime, os, platform, re, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BLOCK = re.compile(r"^<!-- generated:selfcal-scenarios -->\n.*?^<!-- /generated -->$", re.S | re.M)
AUTOCAL_BLOCK = re.compile(r"^<!-- generated:selfcal-from-autocal -->\n.*?^<!-- /generated -->$", re.S | re.M)
# Rigs with a real installation's errors, and the calibration flags each needs (docs/calibration.md's rig table).
REALISTIC = {"realistic": [], "realistic-lens": [], "realistic-optics": [], "realistic-install": ["--fit-screen"],
             "realistic-screen": []}
COMMON = ["--rate-hz", "2", "--bump-at-s", "2", "--projector-scale", "0.5", "--camera-scale", "0.5"]


def long_static_scenario(frames):
    """The long static run (the simulated hour at 7200 frames is a benchmark, not a CI test): `frames`
    monitored frames at 2 Hz with camera noise, exposure ±30 %, moving content and visitors hiding
    10–40 %, the camera at half resolution as in the other rows but the projectors at a quarter (their
    images are only rendered for the simulated camera) and ground truth every 600 frames, to keep it to
    minutes."""
    minutes = frames / 2 / 60
    span = f"{minutes / 60:.2g} h" if minutes >= 60 else f"{minutes:.3g} min"
    return (f"static, {span} (projectors at quarter resolution), visitors 10–40 %, exposure ±30 %",
            ["--frames", str(frames), "--occlusion", "0.1", "--occlusion-max", "0.4", "--exposure-jitter", "0.3",
             "--projector-scale", "0.25", "--truth-every", "600"])


def scenarios(static_frames):
    out = []
    for axis in ("yaw", "pitch", "roll"):
        for deg in ("0.2", "1", "3"):
            out.append((f"proj1 {axis} {deg}°", ["--bump", f"proj1:{axis}={deg}deg", "--frames", "60"]))
    for axis in ("x", "y", "z"):
        for mm in ("2", "5", "10"):
            out.append((f"proj1 shift {mm} mm ({axis})", ["--bump", f"proj1:{axis}={mm}mm", "--frames", "60"]))
    out.append(("proj1 shift 10 mm (x), 5 mm (y)", ["--bump", "proj1:x=10mm,y=5mm", "--frames", "60"]))
    out.append(("proj0 yaw 1° and proj2 pitch 1°", ["--bump", "proj0:yaw=1deg", "--bump", "proj2:pitch=1deg",
                                                     "--frames", "60"]))
    out.append(("proj0 and proj2 yaw 1° (alike: two thirds of the content moves as a camera yaw would)",
                ["--bump", "proj0:yaw=1deg", "--bump", "proj2:yaw=1deg", "--frames", "60"]))
    out.append(("camera yaw 1° with proj0 yaw 1° and proj2 pitch 1°",
                ["--bump", "camera:yaw=1deg", "--bump", "proj0:yaw=1deg", "--bump", "proj2:pitch=1deg",
                 "--frames", "60"]))
    out.append(("camera yaw 1°, pitch 0.5°, 10 mm", ["--bump", "camera:yaw=1deg,pitch=0.5deg,x=10mm", "--frames",
                                                     "30"]))
    out.append(("proj1 yaw 1°, visitors 10–40 %", ["--bump", "proj1:yaw=1deg", "--frames", "60",
                                                    "--occlusion", "0.1", "--occlusion-max", "0.4"]))
    out.append(("proj1 yaw 1°, repetitive content", ["--bump", "proj1:yaw=1deg", "--frames", "60",
                                                      "--content-kind", "repetitive"]))
    out.append(("proj1 yaw 1°, plain (textureless) content", ["--bump", "proj1:yaw=1deg", "--frames", "20",
                                                               "--content-kind", "plain"]))
    # A pattern pair takes a monitored frame of its own: these rows run as long as the textured ones.
    out.append(("proj1 yaw 1°, plain content, pattern fallback on", ["--bump", "proj1:yaw=1deg", "--frames", "60",
                                                                      "--content-kind", "plain", "--pattern"]))
    out.append(("proj1 yaw 1°, dark scene (4 % of the light)", ["--bump", "proj1:yaw=1deg", "--frames", "20",
                                                                "--content-kind", "dark"]))
    out.append(("proj1 yaw 1°, dark scene, pattern fallback on", ["--bump", "proj1:yaw=1deg", "--frames", "60",
                                                                  "--content-kind", "dark", "--pattern"]))
    out.append(("proj2 yaw −20° (image off the screen)", ["--bump", "proj2:yaw=-20deg", "--frames", "20"]))
    out.append((f"static, {static_frames / 2 / 60:.0f} min, visitors 10–40 %, exposure ±30 %",
                ["--frames", str(static_frames), "--occlusion", "0.1", "--occlusion-max", "0.4",
                 "--exposure-jitter", "0.3"]))
    return out


def autocal_scenarios(static_frames):
    """(rig stem, name, scale, extra): runs started from autocal's estimate at that scale (projectors and camera)."""
    half = [(f"proj1 {axis} {deg}°", ["--bump", f"proj1:{axis}={deg}deg", "--frames", "60"])
            for axis, deg in (("yaw", "0.2"), ("yaw", "1"), ("yaw", "3"), ("pitch", "1"), ("roll", "1"))]
    half += [("proj1 shift 10 mm (x)", ["--bump", "proj1:x=10mm", "--frames", "60"]),
             ("proj0 yaw 1° and proj2 pitch 1°", ["--bump", "proj0:yaw=1deg", "--bump", "proj2:pitch=1deg",
                                                  "--frames", "60"]),
             ("camera yaw 1°, pitch 0.5°, 10 mm", ["--bump", "camera:yaw=1deg,pitch=0.5deg,x=10mm", "--frames", "30"]),
             (f"static, {static_frames / 2 / 60:.0f} min, visitors 10–40 %, exposure ±30 %",
              ["--frames", str(static_frames), "--occlusion", "0.1", "--occlusion-max", "0.4", "--exposure-jitter",
               "0.3"])]
    # The shifts the half-resolution table never detects (under 1 of its pixels), where a pixel is
    # half as large.
    full = [("proj1 yaw 1°, full resolution", ["--bump", "proj1:yaw=1deg", "--frames", "40"])]
    full += [(f"proj1 shift {mm} mm ({axis}), full resolution", ["--bump", f"proj1:{axis}={mm}mm", "--frames", "40"])
             for axis, mm in (("x", "2"), ("y", "2"), ("z", "2"), ("z", "10"))]
    full += [
            ("static, 1 min, visitors 10–40 %, exposure ±30 %, full resolution",
             ["--frames", "120", "--occlusion", "0.1", "--occlusion-max", "0.4", "--exposure-jitter", "0.3"])]
    out = [("standard", n, "0.5", e) for n, e in half] + [("standard", n, "1", e) for n, e in full]
    # The rigs with a real installation's errors (their [prior]: camera intrinsics, screen, projector lenses):
    # the monitor starts from a calibration that estimated what the rig did not hand it, lens distortion kept.
    for stem in REALISTIC:
        out += [(stem, "proj1 yaw 1°", "0.5", ["--bump", "proj1:yaw=1deg", "--frames", "60"]),
                (stem, "proj1 shift 10 mm (x)", "0.5", ["--bump", "proj1:x=10mm", "--frames", "60"]),
                (stem, f"static, {static_frames / 2 / 60:.0f} min, visitors 10–40 %, exposure ±30 %", "0.5",
                 ["--frames", str(static_frames), "--occlusion", "0.1", "--occlusion-max", "0.4",
                  "--exposure-jitter", "0.3"])]
    out.append(("realistic-lens", "proj1 yaw 1°, full resolution", "1", ["--bump", "proj1:yaw=1deg", "--frames", "40"]))
    return out


def field(text, pattern, default="—"):
    m = re.search(pattern, text, re.M)
    return m.group(1) if m else default


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build-calib")
    ap.add_argument("--static-frames", type=int, default=240)
    ap.add_argument("--long-static-frames", "--hour-frames", dest="long_frames", type=int, default=1200,
                    help="the long static run's frames beside the others (1200: 10 minutes; 7200: the simulated hour; "
                         "0: none)")
    ap.add_argument("--only", choices=["scenarios", "autocal"], default=None,
                    help="regenerate one table only (default: both)")
    args = ap.parse_args()
    tool = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-calibrate-sim")
    if args.only != "scenarios":
        from_autocal_table(args, tool)
    if args.only != "autocal":
        scenarios_table(args, tool)


def row(name, t, start=False):
    """One table row from mogao-calibrate-sim selfcal-simulate's output."""
    cells = [name] + ([field(t, r"^error at the start: ([0-9.]+) px")] if start else []) + [
        field(t, r"^error right after the bump: ([0-9.]+) px"),
        field(t, r"^detected after: ([0-9.]+) s", "never"),
        field(t, r"^corrected \(< [0-9.]+ px\) after: ([0-9.]+) s", "never"),
        field(t, r"detections: (\d+)"),
        field(t, r"corrections: (\d+)"),
        str(len(re.findall(r"^journal: selfcal: t=[0-9.]+ s: camera moved", t, re.M))),
        field(t, r"^final state: ([^;]+);"),
        field(t, r"mean ([0-9.]+) px, p95") + " / " + field(t, r"p95 ([0-9.]+) px"),
        field(t, r"waiting frames: (\d+)"),
        field(t, r"^CPU per monitored frame: ([0-9.]+) ms"),
        field(t, r"^CPU per monitored frame: [0-9.]+ ms \(([0-9.]+ %)"),
    ]
    return "| " + " | ".join(cells) + " |"


def write_block(pattern, tag, lines):
    doc = os.path.join(ROOT, "docs", "calibration.md")
    text = open(doc).read()
    if not pattern.search(text):
        sys.exit(f"docs/calibration.md: no <!-- generated:{tag} --> block")
    text = pattern.sub(lambda m: f"<!-- generated:{tag} -->\n" + "\n".join(lines) + "\n<!-- /generated -->", text)
    open(doc, "w").write(text)


def from_autocal_table(args, tool):
    """The monitor started from autocal's estimate (the full calibration's residual included)."""
    autocal = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-calibrate-sim")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    lines = [f"Run {datetime.date.today()} at commit {commit} on {platform.node()} by "
             f"`tools/docs/regenerate_selfcal_doc.py --only autocal --static-frames {args.static_frames}`: "
             "rigs/standard.toml (rows without a rig name) and the rigs/realistic*.toml rigs (named; their "
             "errors in the prior, projector lens distortion kept by the calibration, `realistic-install` with "
             "`--fit-screen`) calibrated by `mogao-calibrate-sim rig --rig RIG --scale S` (S = 0.5: "
             "projectors and camera at half resolution; S = 1: three 1920x1080 projectors and the 1280x720 camera), "
             "the monitor started from its calibration.models.json "
             "(`mogao-calibrate-sim selfcal-simulate --models`), errors against "
             "the rig's ground truth in the projectors' pixels at that scale; otherwise as the table above.", "",
             "| scenario | error at the start (px) | error after the bump (px) | detected after (s) | < 1 px "
             "after (s) | "
             "detections | corrections | camera re-basings | final state | final error mean / p95 (px) | "
             "waiting frames | "
             "CPU per frame (ms) | share of one core |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as work:
        models = {}
        for stem, name, scale, extra in autocal_scenarios(args.static_frames):
            rig = os.path.join(ROOT, "rigs", stem + ".toml")
            if (stem, scale) not in models:
                out = os.path.join(work, f"{stem}-{scale}")
                os.makedirs(out)
                p = subprocess.run([autocal, "rig", "--rig", rig, "--out", out, "--scale", scale] +
                                   REALISTIC.get(stem, []), capture_output=True, text=True)
                if p.returncode != 0:
                    sys.exit(f"mogao-calibrate-sim rig --rig {rig} --scale {scale} failed: {p.stderr.strip()}")
                models[(stem, scale)] = os.path.join(out, "calibration.models.json")
            jitter = [] if "--exposure-jitter" in extra else ["--exposure-jitter", "0.1"]
            cmd = [tool, "selfcal-simulate", "--rig", rig, "--rate-hz", "2", "--bump-at-s", "2", "--projector-scale",
                   scale,
                   "--camera-scale", scale, "--models", models[(stem, scale)]] + jitter + extra
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit(f"{stem}: {name}: mogao-calibrate-sim selfcal-simulate failed: {p.stderr.strip()}")
            label = (f"{stem}: " if stem != "standard" else "") + name + (f" (x{scale})" if scale != "1" else "")
            lines.append(row(label, p.stdout, start=True))
            print(lines[-1], flush=True)
    write_block(AUTOCAL_BLOCK, "selfcal-from-autocal", lines)


def scenarios_table(args, tool):
    rig = os.path.join(ROOT, "rigs", "standard.toml")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    hour = f" --long-static-frames {args.long_frames}"
    lines = [f"Run {datetime.date.today()} at commit {commit} on {platform.node()} by "
             f"`tools/docs/regenerate_selfcal_doc.py --static-frames {args.static_frames}{hour}`: rigs/standard.toml, "
             "projectors and camera at half resolution (errors in those projector pixels, the worst projector's mean, "
             "against the rig's ground truth), monitor at 2 Hz, bumps at t = 2 s, hold 2 s, transition 3 s, "
             "camera gain ±10 % per frame unless stated.", "",
             "| scenario | error after the bump (px) | detected after (s) | < 1 px after (s) | detections | "
             "corrections | "
             "camera re-basings | final state | final error mean / p95 (px) | waiting frames | CPU per frame "
             "(ms) | share of one core |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    def command(extra):
        jitter = [] if "--exposure-jitter" in extra else ["--exposure-jitter", "0.1"]
        common = []  # COMMON less the flags a scenario sets itself
        for i in range(0, len(COMMON), 2):
            if COMMON[i] not in extra:
                common += COMMON[i:i + 2]
        return [tool, "selfcal-simulate", "--rig", rig] + common + jitter + extra

    # The long run goes on beside the short ones (its own process, a second core).
    long_run = None
    if args.long_frames > 0:
        long_name, long_extra = long_static_scenario(args.long_frames)
        long_run = subprocess.Popen(command(long_extra), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    outputs = []
    for name, extra in scenarios(args.static_frames):
        p = subprocess.run(command(extra), capture_output=True, text=True)
        outputs.append((name, p.returncode, p.stdout, p.stderr))
    if long_run is not None:
        out, err = long_run.communicate()
        outputs.append((long_name, long_run.returncode, out, err))
    for name, rc, t, err in outputs:
        if rc != 0:
            sys.exit(f"{name}: mogao-calibrate-sim selfcal-simulate failed: {err.strip()}")
        lines.append(row(name, t))
        print(lines[-1], flush=True)
    write_block(BLOCK, "selfcal-scenarios", lines)


if __name__ == "__main__":
    main()
