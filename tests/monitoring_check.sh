#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The operator views against Prometheus' own checker (promtool, Debian package prometheus):
#   1. the metrics the farm and the kiosk really write -- the text their writers produce in their unit
#      tests (FarmMetrics.*, KioskMetrics.*, left in WORK by MOGAO_METRICS_SAMPLE_DIR) -- pass
#      `promtool check metrics` (format and naming conventions) without a single complaint;
#   2. the alert rules pass `promtool check rules` and their unit tests (`promtool test rules`);
#   3. every query of the Grafana dashboard parses as PromQL (promtool checks them as recording rules);
#   4. every mogao_* metric name the rules and the dashboard use is one the farm or the kiosk writes.
# Exit 77 (skipped) without promtool; .ci/deps installs it, so CI never skips this.
#   monitoring_check.sh FARM_TEST_BINARY KIOSK_TEST_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
farm_test=$1 kiosk_test=$2 src=$3 work=$4
if ! command -v promtool >/dev/null; then
  echo "SKIP: promtool is not installed (Debian package prometheus; .ci/deps installs it)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
MOGAO_METRICS_SAMPLE_DIR=$work "$farm_test" \
    --gtest_filter='FarmMetrics.ExpositionTextHasEveryFamilyWithItsTypeAndValue' >"$work/farm-test.log"
MOGAO_METRICS_SAMPLE_DIR=$work "$kiosk_test" \
    --gtest_filter='KioskMetrics.EveryFamilyWithItsValueFromTheStatusAndTheCounters' >"$work/kiosk-test.log"
for side in farm kiosk; do
  file=$work/mogao-$side.prom
  [ -s "$file" ] || { echo "FAIL: the $side metrics test left no $file"; exit 1; }
  # promtool exits 3 on a lint problem; any output at all is one.
  if ! out=$(promtool check metrics <"$file" 2>&1) || [ -n "$out" ]; then
    echo "FAIL: promtool check metrics on the $side's metrics:"; echo "$out"; exit 1
  fi
  echo "promtool check metrics: mogao-$side.prom OK ($(grep -c '^# TYPE' "$file") families)"
done
monitoring=$src/docs/monitoring
promtool check rules "$monitoring/mogao-alerts.yml"
(cd "$monitoring" && promtool test rules mogao-alerts.test.yml)
python3 - "$monitoring" "$work" <<'PY'
import json, pathlib, re, subprocess, sys
monitoring, work = map(pathlib.Path, sys.argv[1:])
dashboard = json.loads((monitoring / "mogao-grafana.json").read_text())
exprs = []
def walk(node):
    if isinstance(node, dict):
        if isinstance(node.get("expr"), str): exprs.append(node["expr"])
        for v in node.values(): walk(v)
    elif isinstance(node, list):
        for v in node: walk(v)
walk(dashboard["panels"])
# Grafana's variables replaced by what they stand for, then each query checked as a recording rule
# (a JSON string is a valid YAML double-quoted scalar).
rules = ["groups:", "  - name: dashboard", "    rules:"]
for i, e in enumerate(exprs):
    e = e.replace("$__rate_interval", "5m").replace("$farm", ".*").replace("$kiosk", ".*")
    rules += [f"      - record: dashboard:query_{i}", f"        expr: {json.dumps(e)}"]
(work / "dashboard-rules.yml").write_text("\n".join(rules) + "\n")
subprocess.run(["promtool", "check", "rules", str(work / "dashboard-rules.yml")], check=True)
emitted = set()
for side in ("farm", "kiosk"):
    for line in (work / f"mogao-{side}.prom").read_text().splitlines():
        if line and not line.startswith("#"):
            emitted.add(re.match(r"[a-zA-Z_:][a-zA-Z0-9_:]*", line).group(0))
used = {}
for name, text in (("mogao-alerts.yml", (monitoring / "mogao-alerts.yml").read_text()),
                   ("mogao-grafana.json", "\n".join(exprs))):
    for metric in re.findall(r"\bmogao_(?:farm|kiosk)_[a-z0-9_]+", text):
        used.setdefault(metric, set()).add(name)
unknown = {m: sorted(w) for m, w in used.items() if m not in emitted}
for m, where in sorted(unknown.items()):
    print(f"FAIL: {m} (used in {', '.join(where)}) is not written by the farm or the kiosk")
print(f"dashboard: {len(exprs)} queries parse; rules and dashboard use {len(used)} metric names, "
      f"{len(used) - len(unknown)} of them written by the farm or the kiosk ({len(emitted)} series names written)")
sys.exit(1 if unknown else 0)
PY
echo "monitoring check: OK"
