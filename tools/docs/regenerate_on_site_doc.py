#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Fills the <!-- generated:on-site-budget -->, <!-- generated:on-site-path -->,
<!-- generated:on-site-pattern-set --> and <!-- generated:on-site-images --> blocks of
docs/on-site-calibration.md: the image count and capture time `mogao-calibrate --budget` prints for
rigs/standard.toml at several camera frame rates and settle times, one run of the whole on-site
path without hardware (headless outputs filmed by the standard rig's camera, 1/4 scale) next to
`mogao-calibrate-sim rig` at the same scale, the pattern set `mogao-calibrate patterns` writes for the
standard rig at full resolution (count, files, size), and one run of the captured-images route at
1/4 scale (patterns written, filmed by the rig with mogao-rig-film, calibrated with --images, measured
against the rig's ground truth). Figures there are never pasted.

  tools/docs/regenerate_on_site_doc.py [--build build-calhw]
Python 3 standard library only.
"""
import argparse, json, os, re, subprocess, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOC = os.path.join(ROOT, "docs", "on-site-calibration.md")


def replace(text, name, body):
    block = re.compile(rf"^<!-- generated:{name} -->\n.*?^<!-- /generated -->$", re.S | re.M)
    new = f"<!-- generated:{name} -->\n{body}\n<!-- /generated -->"
    if not block.search(text):
        raise SystemExit(f"{DOC}: no generated:{name} block")
    return block.sub(lambda _: new, text)


def budget_rows(tool, site):
    rows = ["| colour step | camera fps | settle | frames dropped | images | s per image | capture |",
            "|---|---|---|---|---|---|---|"]
    for colour in (True, False):
        for fps, settle, drop in ((30, 150, 2), (30, 300, 2), (60, 100, 2), (15, 150, 1)):
            cmd = [tool, "--site", site, "--budget", "--budget-fps", str(fps), "--settle-ms", str(settle),
                   "--drop-frames", str(drop)] + ([] if colour else ["--no-colour"])
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            m = re.search(r": (\d+) images .*: ([0-9.]+) s per image, (\d+) s \(([0-9.]+) min\)", out)
            rows.append(f"| {'yes' if colour else 'no'} | {fps} | {settle} ms | {drop} | {m.group(1)} | "
                        f"{m.group(2)} | {m.group(3)} s ({m.group(4)} min) |")
    return "\n".join(rows)


def path_rows(tool, site):
    with tempfile.TemporaryDirectory() as d:
        t0 = time.time()
        out = subprocess.run([tool, "--site", site, "--outputs", "headless", "--camera", "rig:" + site, "--scale",
                              "0.25", "--content", "480x270", "--settle-ms", "0", "--drop-frames", "0", "--no-colour",
                              "--out", os.path.join(d, "site")], capture_output=True, text=True, check=True).stdout
        truth = re.search(r"geometry mean ([0-9.]+) p95 ([0-9.]+) px", out)
        t_site = time.time() - t0
        site_report = json.load(open(os.path.join(d, "site", "report.json")))
        t0 = time.time()
        subprocess.run([tool, "rig", "--rig", site, "--scale", "0.25", "--content", "480x270", "--no-colour",
                        "--out", os.path.join(d, "rig")], capture_output=True, text=True, check=True)
        t_rig = time.time() - t0
        rig_report = json.load(open(os.path.join(d, "rig", "report.json")))
    conn = ", ".join(f"{c['projector']}={c['connector']}" for c in site_report["connectors"])
    rms = ", ".join(f"{p['reprojection_rms_px']:.3f}" for p in site_report["projectors"])
    g = rig_report["ground_truth"]
    rig_rms = ", ".join(f"{p['reprojection_rms_px']:.3f}" for p in rig_report["projectors"])
    return "\n".join([
        "| path | images | reprojection rms per projector (px) | self-check (no ground truth) | "
        "geometry vs ground truth | wall time |",
        "|---|---|---|---|---|---|",
        f"| `--outputs headless --camera rig:` ({conn}) | {site_report['captures']} | {rms} | "
        f"mean {site_report['self_check']['mean_px']:.3f}, p95 {site_report['self_check']['p95_px']:.3f} px | "
        f"mean {truth.group(1)}, p95 {truth.group(2)} px | {t_site:.1f} s |",
        f"| `rig` | {rig_report['captures']} | "
        f"{rig_rms} | "
        f"mean {rig_report['self_check']['mean_px']:.3f}, p95 {rig_report['self_check']['p95_px']:.3f} px | "
        f"mean {g['geometry_mean_px']:.3f}, p95 {g['geometry_p95_px']:.3f} px | {t_rig:.1f} s |"])


def pattern_set_rows(tool, site):
    with tempfile.TemporaryDirectory() as d:
        t0 = time.time()
        subprocess.run([tool, "patterns", "--site", site, "--out", d], capture_output=True, text=True, check=True)
        seconds = time.time() - t0
        manifest = json.load(open(os.path.join(d, "patterns.json")))
        files = [os.path.join(r, f) for r, _, fs in os.walk(d) for f in fs if f.endswith(".png")]
        size = sum(os.path.getsize(f) for f in files)
    kinds = {}
    for p in manifest["patterns"]:
        kinds[p["kind"]] = kinds.get(p["kind"], 0) + 1
    per_kind = ", ".join(f"{k} {n}" for k, n in kinds.items())
    return "\n".join([
        "| site | patterns (captures to take) | of which | PNG files | size | written in |",
        "|---|---|---|---|---|---|",
        f"| `{site}` ({len(manifest['projectors'])} projectors, "
        f"{manifest['projectors'][0]['width']}x{manifest['projectors'][0]['height']}) | {len(manifest['patterns'])} | "
        f"{per_kind} | {len(files)} | {size / 1e6:.1f} MB | {seconds:.1f} s |"])


def images_rows(tool, film, site):
    scale = ["--scale", "0.25"]
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([tool, "patterns", "--site", site, "--out", d] + scale, capture_output=True, text=True,
                       check=True)
        subprocess.run([film, "--rig", site] + scale + ["film", "--patterns", d], capture_output=True, text=True,
                       check=True)
        t0 = time.time()
        subprocess.run([tool, "--site", site] + scale + ["--content", "480x270", "--camera-transfer", "linear",
                       "--images", d, "--out", os.path.join(d, "out")], capture_output=True, text=True, check=True)
        seconds = time.time() - t0
        truth = subprocess.run([film, "--rig", site] + scale + ["measure", "--mpcdi",
                               os.path.join(d, "out", "calibration.mpcdi")], capture_output=True, text=True,
                               check=True).stdout
        m = re.search(r"geometry mean ([0-9.]+) p95 ([0-9.]+) px", truth)
        report = json.load(open(os.path.join(d, "out", "report.json")))
    rms = ", ".join(f"{p['reprojection_rms_px']:.3f}" for p in report["projectors"])
    return "\n".join([
        "| path | patterns filmed | images read | reprojection rms per projector (px) | geometry vs ground truth | "
        "calibration wall time |",
        "|---|---|---|---|---|---|",
        f"| `patterns`, `mogao-rig-film film`, `--images` | {report['images']['patterns']} | {report['captures']} | "
        f"{rms} | mean {m.group(1)}, p95 {m.group(2)} px | {seconds:.1f} s |"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build-calhw")
    args = ap.parse_args()
    tool = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-calibrate")
    site = os.path.join("rigs", "standard.toml")
    os.chdir(ROOT)
    text = open(DOC).read()
    text = replace(text, "on-site-budget", budget_rows(tool, site))
    sim = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-calibrate-sim")  # the rig camera and `rig`
    text = replace(text, "on-site-path", path_rows(sim, site))
    text = replace(text, "on-site-pattern-set", pattern_set_rows(tool, site))
    film = os.path.join(ROOT, args.build, "kiosk", "calibrate", "mogao-rig-film")
    text = replace(text, "on-site-images", images_rows(tool, film, site))
    open(DOC, "w").write(text)


if __name__ == "__main__":
    main()
