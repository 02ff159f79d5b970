#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The soak benchmark's sampler and report (bench/soak/run drives both).

  soak.py sample --out DIR --kiosk-pid PID --farm-sid SID [--period-s 60]
      Every period, until the kiosk exits: RSS, open fds and threads of the kiosk and of every
      process in the farm's session (mpirun and its ranks, named by OMPI_COMM_WORLD_RANK), the load
      average, the kiosk's and the farm's metrics files (frames, frame-time sum and count). One JSON
      line per sample in DIR/samples.jsonl, flushed, so a stopped run keeps what it measured.
  soak.py report --out DIR [--write-docs docs/reliability.md]
      Reads DIR/samples.jsonl, the kiosk's DIR/kiosk-stats.json and its frame log
      DIR/kiosk-frames.jsonl (motion-to-photon of every frame) and prints the table; writes
      DIR/soak.json and DIR/soak.png; with --write-docs, the doc's `soak` generated block and
      docs/reliability/soak.png beside it.
  soak.py heap --out DIR [--window-min 10]
      After a run with --heaptrack: the heap the kiosk and the admin rank hold (live malloc
      allocations, heaptrack's record DIR/kiosk-heap.zst and DIR/admin-heap.zst) per window after
      the first 10 minutes, floor and peak, and their slopes per hour. Flat here while RSS grows: the growth is
      not memory the program holds (the allocator keeps or fragments what was freed).

Goals read (docs/reliability.md, "Soak"): after the first 10 minutes, RSS growth of every process
<= 1 MiB per hour (least-squares slope of the samples), open fds and threads constant; the
motion-to-photon p95 of the last 10 minutes within 10 % of the first 10 minutes'.
"""
import argparse
import importlib.machinery
import json
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
WARMUP_MIN = 10.0
GROWTH_LIMIT_MIB_H = 1.0
P95_TOLERANCE = 0.10
WINDOW_MIN = 10.0


def summarize_module():
    return importlib.machinery.SourceFileLoader("summarize", os.path.join(ROOT, "bench", "summarize")).load_module()


# ---- sampling ------------------------------------------------------------------------------------

def proc_status(pid):
    """VmRSS (KiB) and Threads of /proc/PID/status; None when the process is gone."""
    try:
        with open(f"/proc/{pid}/status") as f:
            text = f.read()
    except OSError:
        return None
    rss = re.search(r"^VmRSS:\s+(\d+)", text, re.M)
    threads = re.search(r"^Threads:\s+(\d+)", text, re.M)
    return {"rss_kib": int(rss.group(1)) if rss else 0, "threads": int(threads.group(1)) if threads else 0}


def rss_by_mapping(pid):
    """RSS (KiB) of /proc/PID/smaps by kind of mapping: "heap" (malloc's main arena, [heap]), "anon"
    (other anonymous memory: thread arenas, large malloc blocks, GL buffers), "file" and "other"
    ([stack], [vvar]...): where a growth lives. None when the process is gone."""
    out = {"heap": 0, "anon": 0, "file": 0, "other": 0}
    kind = "other"
    try:
        with open(f"/proc/{pid}/smaps") as f:
            for line in f:
                head = line.split(None, 1)[0]
                if not head.endswith(":"):  # a mapping's line: address perms offset dev inode [path]
                    fields = line.split(None, 5)
                    path = fields[5].strip() if len(fields) > 5 else ""
                    kind = ("heap" if path == "[heap]" else "anon" if not path else
                            "other" if path.startswith("[") else "file")
                elif head == "Rss:":
                    out[kind] += int(line.split()[1])
    except OSError:
        return None
    return out


def fd_count(pid):
    try:
        return len(os.listdir(f"/proc/{pid}/fd"))
    except OSError:
        return None


def session_pids(sid):
    """Every process whose session id is `sid` (the farm: mpirun started by setsid, and its ranks)."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rfind(")") + 2:].split()
        if len(fields) > 3 and int(fields[3]) == sid:
            pids.append(int(entry))
    return sorted(pids)


def process_name(pid):
    """'kiosk', 'mpirun' or 'farm rank N' (the rank from the process's environment)."""
    try:
        with open(f"/proc/{pid}/comm") as f:
            comm = f.read().strip()
        with open(f"/proc/{pid}/environ", "rb") as f:
            env = dict(kv.split(b"=", 1) for kv in f.read().split(b"\0") if b"=" in kv)
    except OSError:
        return None
    rank = env.get(b"OMPI_COMM_WORLD_RANK")
    if comm.startswith("mogao-farm") and rank is not None:
        return f"farm rank {rank.decode()}"
    return comm


def metrics(path):
    """name{labels} -> value of a Prometheus text file; {} when it is missing."""
    values = {}
    try:
        with open(path) as f:
            for line in f:
                if line.startswith("#") or not line.strip():
                    continue
                key, _, value = line.rpartition(" ")
                try:
                    values[key] = float(value)
                except ValueError:
                    pass
    except OSError:
        pass
    return values


def sample_once(out, kiosk_pid, farm_sid, start):
    procs = {}
    for pid, name in [(kiosk_pid, "kiosk")] + [(p, None) for p in session_pids(farm_sid)]:
        name = name or process_name(pid)
        status = proc_status(pid)
        fds = fd_count(pid)
        if name is None or status is None or fds is None:
            continue
        procs[name] = dict(status, fds=fds, pid=pid, rss_by_mapping_kib=rss_by_mapping(pid))
    kiosk = metrics(os.path.join(out, "kiosk.prom"))
    farm = metrics(os.path.join(out, "farm.prom"))
    return {
        "t_s": time.time() - start,
        "unix_s": time.time(),
        "loadavg_1min": os.getloadavg()[0],
        "processes": procs,
        "kiosk_frames_shown": kiosk.get("mogao_kiosk_frames_shown_total"),
        "farm_frames": farm.get("mogao_farm_frames_total"),
        "farm_frame_seconds_sum": farm.get("mogao_farm_frame_seconds_sum"),
        "farm_frame_seconds_count": farm.get("mogao_farm_frame_seconds_count"),
        "farm_log_bytes": os.path.getsize(os.path.join(out, "farm.log")),
        "kiosk_log_bytes": os.path.getsize(os.path.join(out, "kiosk.log")),
    }


def sample(args):
    start = time.time()
    with open(os.path.join(args.out, "samples.jsonl"), "w") as f:
        while os.path.exists(f"/proc/{args.kiosk_pid}"):
            f.write(json.dumps(sample_once(args.out, args.kiosk_pid, args.farm_sid, start)) + "\n")
            f.flush()
            deadline = time.time() + args.period_s
            while time.time() < deadline and os.path.exists(f"/proc/{args.kiosk_pid}"):
                time.sleep(1.0)
    return 0


# ---- report --------------------------------------------------------------------------------------

def slope_per_hour(points):
    """Least-squares slope of (minutes, value) points, per hour; None with fewer than 3 points."""
    if len(points) < 3:
        return None
    n = len(points)
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    if sxx == 0:
        return None
    return 60.0 * sum((p[0] - mx) * (p[1] - my) for p in points) / sxx


def slope_error_per_hour(points):
    """Standard error of slope_per_hour's slope (residuals' spread); None with fewer than 3 points."""
    slope = slope_per_hour(points)
    if slope is None:
        return None
    n = len(points)
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    b = slope / 60.0
    residual = sum((p[1] - my - b * (p[0] - mx)) ** 2 for p in points) / (n - 2)
    return 60.0 * (residual / sxx) ** 0.5


def window_points(points, pick, window_min=WINDOW_MIN):
    """pick (min or max) of the values of each window of (minutes, value) points after the warm-up
    (windows with at least 3 points), at the window's mean time."""
    windows = {}
    for t, v in points:
        windows.setdefault(int((t - WARMUP_MIN) // window_min), []).append((t, v))
    return [(sum(t for t, _ in w) / len(w), pick(v for _, v in w)) for _, w in sorted(windows.items()) if len(w) >= 3]


def percentile(values, q):
    if not values:
        return None
    v = sorted(values)
    i = min(len(v) - 1, max(0, int(round(q * (len(v) - 1)))))
    return v[i]


def process_rows(samples):
    names = sorted({n for s in samples for n in s["processes"]}, key=lambda n: (n != "kiosk", n))
    rows = []
    for name in names:
        series = [(s["t_s"] / 60.0, s["processes"][name]) for s in samples if name in s["processes"]]
        after = [(t, p) for t, p in series if t >= WARMUP_MIN]
        if not series:
            continue
        rss = [(t, p["rss_kib"] / 1024.0) for t, p in after]
        growth = slope_per_hour(rss)
        floors = window_points(rss, min)
        peaks = window_points(rss, max)
        peak_growth = slope_per_hour(peaks)
        fds = [p["fds"] for _, p in after] or [series[-1][1]["fds"]]
        threads = [p["threads"] for _, p in after] or [series[-1][1]["threads"]]
        third = max(1, len(after) // 3)
        rows.append({
            "process": name,
            "rss_mib_at_warmup": after[0][1]["rss_kib"] / 1024.0 if after else None,
            "rss_mib_at_end": series[-1][1]["rss_kib"] / 1024.0,
            "rss_growth_mib_per_h": growth,
            "rss_growth_error_mib_per_h": slope_error_per_hour(rss),
            "rss_floors_mib": [round(v, 2) for _, v in floors],
            "rss_floor_growth_mib_per_h": slope_per_hour(floors),
            "rss_peaks_mib": [round(v, 2) for _, v in peaks],
            "rss_peak_growth_mib_per_h": peak_growth,
            "fds": [min(fds), max(fds)],
            "threads": [min(threads), max(threads)],
            # Transient workers (a render pass's tile threads, the denoiser's row bands) make the
            # count at a sample vary by their number: constant means no growth, i.e. the last third
            # of the run never above the first third's most.
            "fds_grow": max(fds[-third:]) > max(fds[:third]),
            "threads_grow": max(threads[-third:]) > max(threads[:third]),
        })
        kinds = [(t, p["rss_by_mapping_kib"]) for t, p in after if p.get("rss_by_mapping_kib")]
        rows[-1]["rss_growth_by_mapping_mib_per_h"] = {
            k: slope_per_hour([(t, m[k] / 1024.0) for t, m in kinds]) for k in ("heap", "anon", "file", "other")
        } if len(kinds) >= 2 else None
        # Judged on the peaks where there are enough windows: a process that hands freed memory back
        # follows its working set, which differs from window to window (the farm's admin holds a
        # full-resolution still view's buffers only in the minutes it renders one), while every window
        # reaches the whole working set at its peak; a leak or a ratcheting allocator raises the peaks.
        judged = peak_growth if peak_growth is not None else growth
        rows[-1]["ok"] = ((judged is None or judged <= GROWTH_LIMIT_MIB_H) and not rows[-1]["fds_grow"]
                          and not rows[-1]["threads_grow"])
    return rows


def read_frames(out, stats):
    """Every presented frame: the kiosk's frame log, else the statistics file's (first) frames."""
    path = os.path.join(out, "kiosk-frames.jsonl")
    if not os.path.exists(path):
        return stats.get("frames", [])
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def latency_minutes(frames, start_unix_s):
    """Per minute of the run: frames presented, motion-to-photon p50/p95 (ms)."""
    buckets = {}
    for fr in frames:
        minute = int((fr["presented_ns"] / 1e9 - start_unix_s) // 60)
        buckets.setdefault(minute, []).append(fr["motion_to_photon_ms"])
    return [{"minute": m, "frames": len(v), "p50_ms": percentile(v, 0.5), "p95_ms": percentile(v, 0.95)}
            for m, v in sorted(buckets.items()) if m >= 0]


def window_latency(frames, start_unix_s, lo_min, hi_min):
    v = [fr["motion_to_photon_ms"] for fr in frames
         if lo_min * 60 <= fr["presented_ns"] / 1e9 - start_unix_s < hi_min * 60]
    span = (hi_min - lo_min) * 60.0
    return {"frames": len(v), "fps": len(v) / span, "p50_ms": percentile(v, 0.5), "p95_ms": percentile(v, 0.95)}


def farm_frame_ms(samples, lo_min, hi_min):
    inside = [s for s in samples if lo_min <= s["t_s"] / 60.0 <= hi_min and s.get("farm_frame_seconds_count")]
    if len(inside) < 2:
        return None
    a, b = inside[0], inside[-1]
    n = b["farm_frame_seconds_count"] - a["farm_frame_seconds_count"]
    return 1000.0 * (b["farm_frame_seconds_sum"] - a["farm_frame_seconds_sum"]) / n if n > 0 else None


def analyse(out):
    with open(os.path.join(out, "samples.jsonl")) as f:
        samples = [json.loads(line) for line in f if line.strip()]
    if len(samples) < 2:
        raise SystemExit(f"soak.py: {out}/samples.jsonl has {len(samples)} sample(s); a report needs 2")
    with open(os.path.join(out, "kiosk-stats.json")) as f:
        stats = json.load(f)
    frames = read_frames(out, stats)
    start = samples[0]["unix_s"] - samples[0]["t_s"]
    minutes = samples[-1]["t_s"] / 60.0
    first = window_latency(frames, start, 0, min(10, minutes))
    last = window_latency(frames, start, max(0, minutes - 10), minutes)
    for w, lo, hi in ((first, 0, min(10, minutes)), (last, max(0, minutes - 10), minutes)):
        w["farm_frame_ms"] = farm_frame_ms(samples, lo, hi)
        loads = [x["loadavg_1min"] for x in samples if lo <= x["t_s"] / 60.0 <= hi]
        w["loadavg_1min"] = sum(loads) / len(loads) if loads else None
    p95_change = (last["p95_ms"] / first["p95_ms"] - 1.0) if first["p95_ms"] and last["p95_ms"] else None
    loads = [s["loadavg_1min"] for s in samples]
    return {
        "minutes": minutes,
        "samples": len(samples),
        "processes": process_rows(samples),
        "first_10_min": first,
        "last_10_min": last,
        "p95_change": p95_change,
        "p95_ok": p95_change is not None and abs(p95_change) <= P95_TOLERANCE,
        "kiosk_frames": stats.get("total", {}).get("frames"),
        "link_sessions": stats.get("link", {}).get("sessions_opened"),
        "frames_rejected": stats.get("frames_rejected"),
        "loadavg_1min": {"min": min(loads), "mean": sum(loads) / len(loads), "max": max(loads)},
        "log_bytes_per_h": {
            k: 60.0 * (samples[-1][k] - samples[0][k]) / max(minutes, 1e-9) for k in ("farm_log_bytes",
                                                                                      "kiosk_log_bytes")},
        "per_minute": latency_minutes(frames, start),
    }, samples


def fmt(x, spec):
    return "–" if x is None else format(x, spec)


def markdown(result, meta, command):
    s = summarize_module()
    lines = [s.header(meta, "bench/soak/run", command), ""]
    rows = [[p["process"], fmt(p["rss_mib_at_warmup"], ".1f"), fmt(p["rss_mib_at_end"], ".1f"),
             fmt(p["rss_growth_mib_per_h"], "+.2f") + " ± " + fmt(p.get("rss_growth_error_mib_per_h"), ".2f"),
             fmt(p.get("rss_floor_growth_mib_per_h"), "+.2f"), fmt(p.get("rss_peak_growth_mib_per_h"), "+.2f"),
             "–".join(str(x) for x in sorted(set(p["fds"]))),
             "–".join(str(x) for x in sorted(set(p["threads"]))), "yes" if p["ok"] else "**no**"]
            for p in result["processes"]]
    lines.append(s.table(["process", "RSS at 10 min (MiB)", "RSS at end (MiB)",
                          "RSS growth after 10 min, every sample (MiB/h ± s.e.)",
                          "RSS growth of the 10-min floors (MiB/h)", "RSS growth of the 10-min peaks (MiB/h)",
                          "open fds after 10 min (min–max)",
                          "threads after 10 min (min–max)", "within the goal"],
                         rows))
    by_kind = ["{}: {}".format(p["process"], ", ".join(f"{k} {v:+.2f}" for k, v in
                                                    p["rss_growth_by_mapping_mib_per_h"].items() if v is not None))
               for p in result["processes"] if p.get("rss_growth_by_mapping_mib_per_h")]
    if by_kind:
        lines += ["", "Where RSS grew after 10 minutes (MiB/h; `heap`: malloc's main arena, `anon`: other anonymous "
                  "memory such as thread arenas and large blocks, `file`: mapped files): " + "; ".join(by_kind) + "."]
    lines.append("")
    f, l = result["first_10_min"], result["last_10_min"]
    rows = [[name, w["frames"], fmt(w["fps"], ".2f"), fmt(w["p50_ms"], ".0f"), fmt(w["p95_ms"], ".0f"),
             fmt(w["farm_frame_ms"], ".0f"), fmt(w["loadavg_1min"], ".1f")]
            for name, w in (("first 10 min", f), ("last 10 min", l))]
    lines.append(s.table(["window", "frames shown", "frames/s", "motion-to-photon p50 (ms)",
                          "motion-to-photon p95 (ms)", "farm frame time mean (ms)", "load average (1 min, mean)"],
                         rows))
    lines.append("")
    ch = result["p95_change"]
    load = result["loadavg_1min"]
    lines.append(
        f"{result['minutes']:.0f} minutes, {result['samples']} samples, {result['kiosk_frames']} frames on the wall, "
        f"{result['link_sessions']} link session(s), {result['frames_rejected']} frame(s) rejected; motion-to-photon "
        f"p95 of the last 10 minutes {fmt(None if ch is None else 100 * ch, '+.1f')} % against the first 10 "
        f"({'within' if result['p95_ok'] else '**outside**'} the 10 % goal); load average (1 min) "
        f"{load['min']:.1f}–{load['max']:.1f}, mean {load['mean']:.1f}; logs grew "
        f"{result['log_bytes_per_h']['farm_log_bytes'] / 1024:.0f} KiB/h (farm) and "
        f"{result['log_bytes_per_h']['kiosk_log_bytes'] / 1024:.0f} KiB/h (kiosk).")
    lines.append("")
    lines.append("![RSS, motion-to-photon and farm frame time against time](reliability/soak.png)")
    return "\n".join(lines)


def plot(result, samples, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("soak.py: no matplotlib (apt-get install python3-matplotlib): no plot", file=sys.stderr)
        return False
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), dpi=72, sharex=True)
    for p in result["processes"]:
        pts = [(s["t_s"] / 60.0, s["processes"][p["process"]]["rss_kib"] / 1024.0)
               for s in samples if p["process"] in s["processes"]]
        axes[0].plot([t for t, _ in pts], [v for _, v in pts], label=p["process"])
    axes[0].set_ylabel("RSS (MiB)")
    axes[0].legend(fontsize=8, ncol=3)
    pm = result["per_minute"]
    axes[1].plot([m["minute"] + 0.5 for m in pm], [m["p95_ms"] for m in pm], label="p95")
    axes[1].plot([m["minute"] + 0.5 for m in pm], [m["p50_ms"] for m in pm], label="p50")
    axes[1].set_ylabel("motion-to-photon (ms)")
    axes[1].legend(fontsize=8)
    t = [s["t_s"] / 60.0 for s in samples]
    axes[2].plot(t, [s["loadavg_1min"] for s in samples], label="load average (1 min)")
    ft = [(b["t_s"] / 60.0, 1000.0 * (b["farm_frame_seconds_sum"] - a["farm_frame_seconds_sum"])
           / (b["farm_frame_seconds_count"] - a["farm_frame_seconds_count"]))
          for a, b in zip(samples, samples[1:]) if a.get("farm_frame_seconds_count")
          and b.get("farm_frame_seconds_count")
          and b["farm_frame_seconds_count"] > a["farm_frame_seconds_count"]]
    ax2 = axes[2].twinx()
    ax2.plot([x for x, _ in ft], [y for _, y in ft], color="tab:red", label="farm frame time (ms)")
    ax2.set_ylabel("farm frame time (ms)", color="tab:red")
    axes[2].set_ylabel("load average")
    axes[2].set_xlabel("minutes since start")
    axes[0].set_title("Soak: farm (3 ranks) and headless kiosk, looping tracked tour")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return True



def ended_early(samples):
    """{process: minute of its last sample} for every process missing from the run's last sample."""
    last_seen = {}
    for s in samples:
        for name in s["processes"]:
            last_seen[name] = s["t_s"] / 60.0
    final = samples[-1]["processes"] if samples else {}
    return {name: minute for name, minute in sorted(last_seen.items()) if name not in final}


def report(args):
    result, samples = analyse(args.out)
    ended = ended_early(samples)
    if ended:
        # A process that died (the farm aborting, the kiosk crashing) leaves windows without its frames
        # or memory: the run's figures do not describe a soak, so they must not reach the docs.
        print("soak: the run is incomplete: " + ", ".join(f"{name} ended at minute {minute:.1f}"
                                                            for name, minute in ended.items())
              + f" (see {args.out}/farm.log and kiosk.log)", file=sys.stderr)
        if args.write_docs:
            print(f"soak: not writing {args.write_docs}", file=sys.stderr)
            return 1
    try:
        with open(os.path.join(args.out, "meta.json")) as f:
            meta = json.load(f)
    except OSError:
        meta = {}
    command = f"bench/soak/run --minutes {round(result['minutes'])} --write-docs docs/reliability.md"
    block = markdown(result, meta, command)
    with open(os.path.join(args.out, "soak.json"), "w") as f:
        json.dump(result, f, indent=1)
    print(block)
    png = os.path.join(args.out, "soak.png")
    have_plot = plot(result, samples, png)
    if args.write_docs:
        summarize_module().write_block(args.write_docs, "soak", block)
        if have_plot:
            target = os.path.join(os.path.dirname(args.write_docs), "reliability", "soak.png")
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copyfile(png, target)
    ok = all(p["ok"] for p in result["processes"]) and result["p95_ok"]
    print(f"soak: {'all goals met' if ok else 'goals not met (see the table)'}")
    return 0


# ---- heap (a --heaptrack run) -------------------------------------------------------------------

def heap_points(record):
    """(minutes, MiB in use) of every snapshot of a heaptrack record (heaptrack_print's massif export)."""
    massif = record + ".massif"
    subprocess.run(["heaptrack_print", "-f", record, "--print-massif", massif, "--massif-threshold", "100",
                    "--massif-detailed-freq", "1000000000", "--print-peaks", "0", "--print-allocators", "0",
                    "--print-temporary", "0", "--print-leaks", "0"], check=True, stdout=subprocess.DEVNULL)
    points, t = [], 0.0
    with open(massif) as f:
        for line in f:
            if line.startswith("time="):
                t = float(line[5:]) / 60.0
            elif line.startswith("mem_heap_B="):
                points.append((t, int(line[11:]) / 2**20))
    return points


def heap(args):
    print("| process | windows | heap floor first / last window (MiB) | heap peak first / last window (MiB) "
          "| floors' growth (MiB/h) | peaks' growth (MiB/h) |")
    print("|---|--:|--:|--:|--:|--:|")
    for name in ("kiosk", "admin"):
        record = os.path.join(args.out, f"{name}-heap.zst")
        if not os.path.exists(record):
            print(f"| {name} | no record ({record}) | | | | |")
            continue
        points = heap_points(record)
        # Whole windows after the warm-up only: the last, partial one holds the exit's frees.
        last = WARMUP_MIN + args.window_min * ((points[-1][0] - WARMUP_MIN) // args.window_min) if points else 0
        points = [p for p in points if WARMUP_MIN <= p[0] < last]
        floors, peaks = window_points(points, min, args.window_min), window_points(points, max, args.window_min)
        if len(floors) < 2:
            too_short = f"too short: run past {WARMUP_MIN + 2 * args.window_min:.0f} min"
            print(f"| {name} | {len(floors)} ({too_short}) | | | | |")
            continue
        print(f"| {name} | {len(floors)} | {floors[0][1]:.2f} / {floors[-1][1]:.2f} | {peaks[0][1]:.2f} / "
              f"{peaks[-1][1]:.2f} | {fmt(slope_per_hour(floors), '+.2f')} | {fmt(slope_per_hour(peaks), '+.2f')} |")
    return 0


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("sample")
    s.add_argument("--out", required=True)
    s.add_argument("--kiosk-pid", type=int, required=True)
    s.add_argument("--farm-sid", type=int, required=True)
    s.add_argument("--period-s", type=float, default=60.0)
    r = sub.add_parser("report")
    r.add_argument("--out", required=True)
    r.add_argument("--write-docs")
    h = sub.add_parser("heap")
    h.add_argument("--out", required=True)
    h.add_argument("--window-min", type=float, default=WINDOW_MIN)
    args = ap.parse_args(argv)
    return {"sample": sample, "report": report, "heap": heap}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
