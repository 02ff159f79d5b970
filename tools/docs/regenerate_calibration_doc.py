#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Fills the <!-- generated:calibration-rigs --> and <!-- generated:calibration-colour --> tables of
docs/calibration.md: runs `mogao-calibrate-sim rig` on every rigs/*.toml and writes, per rig, the
accuracy against the rig's ground truth from its report.json (geometry; the seam luminance's maximum
at white; the blend's predicted seam, which its gate holds; seams before and after the colour and
black-level step) beside the self-check's figure (from the camera images alone), or the refusal message;
a run the self-check refuses is run again with its gate off (--max-self-check-px 1e9) to show the ground
truth of what it refused. Figures there are never pasted.

  tools/docs/regenerate_calibration_doc.py [--build build-calib] [--scale 0.5]
Python 3 standard library only.
"""
import argparse, datetime, glob, json, os, platform, subprocess, tempfile

from calibration_cells import heights_cell, seams_grid_phrase
from generated_block import replace_block

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# Rigs also run with these options (a row each): the options they exist to show.
EXTRA_RUNS = {"roughscreen": [["--fit-screen"], ["--fit-heights"]], "falloff": [["--no-falloff"]],
              "bulge": [["--no-bow"]], "realistic": [["--fixed-camera-intrinsics"]],
              "focal": [["--fixed-camera-intrinsics"]], "grazing": [["--intrinsics-min-gain", "0"]],
              "standard": [["--intrinsics-min-gain", "0"]], "realistic-lens": [["--pinhole-projectors"]],
              "realistic-install": [["--fit-screen"], ["--fit-heights"]],
              "realistic-screen": [["--no-indirect-light"]]}
# Rigs also run at full resolution (x1), a row for each list of options they need there.
X1_RUNS = {"standard": [[]], "focal": [[]], "realistic": [[]], "realistic-lens": [[]], "realistic-optics": [[]],
           "realistic-screen": [[]],
           "realistic-install": [["--fit-screen"], ["--fit-heights"]]}
# The gates after which the table still shows a refused run's figures (the run again with them lifted), by the
# refusal's first words: what these two gates judge is the error the truth measures.
GATES = [("self-check:", "--max-self-check-px"), ("screen heights:", "--max-heights-shift-px")]
# Rigs already at small resolutions, run at their own (x1): the QEMU test's rig (rigs/qemu.toml).
OWN_SCALE = {"qemu"}


def seam_cell(before, after, key, scale, fmt):
    return f"{fmt.format(scale * before[key])} → {fmt.format(scale * after[key])}"


def colour_rows(name, r):
    """One row per content level: seam luminance (p95, max, max of the pixel means) and Delta E (p95 and max),
    before -> after."""
    rows = []
    g = r["ground_truth"]
    for b, a in zip(g["seams_before_colour"], g["seams"]):
        rows.append(f"| {name} | {a['level']:.2f} | {seam_cell(b, a, 'seam_luminance_p95', 100, '{:.2f}')} % | "
                    f"{seam_cell(b, a, 'seam_luminance_deviation', 100, '{:.2f}')} % | "
                    f"{seam_cell(b, a, 'seam_luminance_pixel_max', 100, '{:.2f}')} % | "
                    f"{seam_cell(b, a, 'seam_delta_e76_p95', 1, '{:.2f}')} | "
                    f"{seam_cell(b, a, 'seam_delta_e76', 1, '{:.2f}')} |")
    return rows


def distortion_cell(projectors):
    """The projector distortion trial per projector: which kept it (with the fitted k1), each relative cost."""
    trials = [p.get("distortion_trial", {}) for p in projectors]
    if not any(t.get("tried") for t in trials):
        return "pinholes, not tried"
    costs = ", ".join(f"{t['relative_cost']:.3f}" for t in trials)
    kept = [f"{p['id']} k1 {p['distortion']['k1']:+.4f}" for p, t in zip(projectors, trials) if t["kept"]]
    return f"{'kept: ' + '; '.join(kept) if kept else 'pinholes'} ({costs})"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build-calib")
    ap.add_argument("--scale", default="0.5")
    args = ap.parse_args()
    tool = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-calibrate-sim")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    lines = [f"Run {datetime.date.today()} at commit {commit} on {platform.node()} by "
             f"`tools/docs/regenerate_calibration_doc.py --scale {args.scale}` (projector and camera "
             f"resolution x{args.scale}, "
             "but x1 for rigs marked so; errors in that rig's projector pixels, against the rig's ground "
             "truth; compute = "
             "the calibration's wall time without the rig's camera simulation, colour step included, 2 cores).", "",
             "| rig | result | geometry mean / p95 / max (px) | self-check mean / p95 (px) | heights check (px) | "
             "camera intrinsics (trial's "
             "relative cost) | projector distortion (trial's relative cost per projector) | seam luminance max | "
             "predicted seam | camera position error | lit edges rms | reprojection rms (px) | compute s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|--:|"]
    colour = ["Same run. Flat content at each level, the rig's ground-truth light {grid} "
              "(each projector pixel's light spread by the rig's defocus where it has one, as the screen shows it); "
              "seam = points two projectors light; luminance deviation |Y / Y_ref - 1| with Y_ref the median of the "
              "points one projector lights; pixel mean = the light averaged over the footprint of the output pixel "
              "that shows the point (the projector with the largest blend weight there; 8 x 8 points of it); CIE76 "
              "Delta E against that reference colour (CIELAB relative to the screen's own white). Before = the "
              "geometric calibration alone (gamma 2.2 assumed, no beta); after = with the colour and black-level "
              "step.", "",
              "| rig | content | seam luminance p95 | seam luminance max | seam luminance max, pixel mean | "
              "seam ΔE76 p95 | seam ΔE76 max |",
              "|---|---|---|---|---|---|---|"]
    runs, reports = [], []
    for rig in sorted(glob.glob(os.path.join(ROOT, "rigs", "*.toml"))):
        stem = os.path.splitext(os.path.basename(rig))[0]
        runs.append((f"{stem} (x1)" if stem in OWN_SCALE else stem, rig, []))
        # The goals hold at full resolution, and the compute goal is for three 1920x1080 projectors: x1 too,
        # for every rig with a real installation's errors (those whose camera integrates 4 x 4 points per
        # pixel take two to three minutes of simulation each at x1).
        for x1 in X1_RUNS.get(stem, []):
            runs.append((f"{stem} (x1)" + (f" `{' '.join(x1)}`" if x1 else ""), rig, x1))
        for extra in EXTRA_RUNS.get(stem, []):
            runs.append((f"{stem} `{' '.join(extra)}`", rig, extra))
    for name, rig, extra in runs:
        with tempfile.TemporaryDirectory() as out:
            scale = "1" if name.split()[0] in OWN_SCALE or "(x1)" in name else args.scale
            command = [tool, "rig", "--rig", rig, "--out", out, "--scale", scale] + extra
            p = subprocess.run(command, capture_output=True, text=True)
            result = "calibrated"
            if p.returncode != 0:
                why = p.stderr.strip().replace("mogao-calibrate-sim rig: ", "").replace("|", "/")
                gate = next((flag for prefix, flag in GATES if why.startswith(prefix)), None)
                if gate is None:
                    lines.append(f"| {name} | refused: {why} | — | — | — | — | — | — | — | — | — | — | — |")
                    continue
                # What the self-check or the heights' check refused, against the truth: the same run with every
                # such gate off (which another gate may still refuse: then the row has no figures).
                lifted = [a for _, flag in GATES for a in (flag, "1e9")]
                q = subprocess.run(command + lifted, capture_output=True, text=True)
                if q.returncode != 0:
                    then = q.stderr.strip().replace("mogao-calibrate-sim rig: ", "").replace("|", "/")
                    lines.append(f"| {name} | refused: {why} (with its gate off: {then}) | — | — | — | — | — | — | — | "
                                 "— | — | — | — |")
                    continue
                result = f"refused: {why} (figures: the same run with the gate off)"
            r = json.load(open(os.path.join(out, "report.json")))
        reports.append(r)
        g = r["ground_truth"]
        if "seams_before_colour" in g:
            colour += colour_rows(name, r)
        rms = ", ".join(f"{p['reprojection_rms_px']:.2f}" for p in r["projectors"])
        c = r["self_check"]
        trial = r["camera"].get("intrinsics_trial", {})
        intrinsics = ("prior's, taken as exact" if not trial.get("tried") else
                      f"{'refined' if trial['kept'] else 'prior' + chr(39) + 's'} ({trial['relative_cost']:.4f})")
        lines.append(f"| {name} | {result} | {g['geometry_mean_px']:.3f} / {g['geometry_p95_px']:.3f} / "
                     f"{g['geometry_max_px']:.3f} | {c['mean_px']:.3f} / {c['p95_px']:.3f} | "
                     f"{heights_cell(r['screen'])} | {intrinsics} | "
                     f"{distortion_cell(r['projectors'])} | "
                     f"{100 * g['seam_luminance_max_deviation']:.2f} % | "
                     f"{100 * r['predicted']['seam_weight_sum_max_deviation']:.2f} % | "
                     f"{g['camera_position_error_mm']:.2f} mm | {r['camera']['edge_rms_mm']:.2f} mm | {rms} | "
                     f"{r['timing']['compute_s']:.1f} |")
    doc = os.path.join(ROOT, "docs", "calibration.md")
    replace_block(doc, "calibration-rigs", lines)
    colour[0] = colour[0].format(grid=seams_grid_phrase(reports))
    replace_block(doc, "calibration-colour", colour)

if __name__ == "__main__":
    main()
