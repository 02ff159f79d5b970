#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""One meaning per flag name, units in the names (docs/cli.md, "Flag names").

Runs every program's --help, and its subcommands' recursively, and fails when
  (a) one flag name is declared in two places with different help texts, unless docs/cli.md lists
      the name as generic (--out, --threads, ...): a flag shared by several programs or commands is
      declared once (or with the very same text), so it cannot mean two things;
  (b) the help text of an option that takes a number states a unit (seconds, ms, metres, degrees,
      pixels, Hz, ...) that the flag's name does not carry (--duration-s, --fov-deg, --snap-px),
      unless docs/cli.md lists the name as one whose unit is implied.

  cli_flag_names_test.py DOCS_CLI_MD NAME=PATH [NAME=PATH ...]

CLI11's help layout (2.1): an option line is two spaces, the names and the type; the description
starts at column 30, or on the next line indented 30 when the names are longer.
"""
import re
import subprocess
import sys

COLUMN = 30

# Unit stated in a help text -> the name components that carry it (the suffix table of docs/cli.md).
# Checked in this order; a match is blanked out before the next unit is looked for ("per second" is
# a rate, not seconds; "per pixel" is a density, not pixels).
UNITS = [
    ("Hz", r"\bhz\b|\bhertz\b|\bper (simulated )?second\b", {"hz", "fps"}),
    ("milliseconds", r"\bmilliseconds?\b|\bms\b", {"ms"}),
    ("microseconds", r"\bmicroseconds?\b|(?<=[\d ,(])us\b", {"us"}),
    ("seconds", r"\bseconds?\b|\b\d+(\.\d+)? ?s\b", {"s"}),
    ("millimetres", r"\bmillimet(re|er)s?\b|\bmm\b", {"mm"}),
    ("metres", r"\bmet(re|er)s?\b", {"m"}),
    ("degrees", r"\bdegrees?\b|°", {"deg"}),
    ("pixels", r"\bper pixel\b|\bpixels? per\b", None),  # a density: no unit of its own
    ("pixels", r"\bpixels?\b|\bpx\b", {"px"}),
]
NUMERIC = re.compile(r"^(INT|UINT|FLOAT|NUMBER)\b")


def doc_names(doc_text, label):
    """The `--names` of the docs/cli.md paragraph that starts with LABEL (up to its blank line)."""
    for paragraph in re.split(r"\n\s*\n", doc_text):
        if paragraph.startswith(label):
            return set(re.findall(r"`(--[\w-]+)`", paragraph.split(" -- ")[0]))
    sys.exit(f"FAIL: docs/cli.md has no paragraph starting with '{label}'")


def run_help(path, words):
    r = subprocess.run([path, *words, "--help"], capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    if r.returncode != 0:
        sys.exit(f"FAIL: {path} {' '.join(words)} --help exited {r.returncode}: {r.stderr[:300]}")
    return r.stdout


def parse_help(text):
    """(options, subcommands): options as (name, type, description) per flag name."""
    options, subcommands = [], []
    lines = text.splitlines()
    section = None
    for i, line in enumerate(lines):
        if re.match(r"^[A-Z][A-Za-z ]*:\s*$", line):
            section = line.strip().rstrip(":").lower()
            continue
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if nxt.startswith(" " * COLUMN) and nxt[COLUMN:COLUMN + 1].strip():
            head, desc = line.strip(), nxt.strip()  # names too long: the description on the next line
        elif len(line) > COLUMN and line[COLUMN - 1] == " ":
            head, desc = line[:COLUMN].strip(), line[COLUMN:].strip()
        else:
            head, desc = line.strip(), ""
        if section == "options" and re.match(r"^  -", line):
            names, _, kind = head.partition(" ")
            for n in names.split(","):
                m = re.match(r"^(--[\w-]+)", n)
                if m:
                    options.append((m.group(1), kind.strip(), desc))
        elif section == "subcommands" and re.match(r"^  [a-z]", line):
            subcommands.append(head.split()[0])
    return options, subcommands


def walk(program, path, words, seen):
    options, subcommands = parse_help(run_help(path, words))
    where = " ".join([program, *words])
    for name, kind, desc in options:
        seen.append((name, kind, desc, where))
    for sub in subcommands:
        walk(program, path, [*words, sub], seen)


def stated_units(desc):
    text = desc
    found = []
    for unit, pattern, tokens in UNITS:
        rx = re.compile(pattern, re.IGNORECASE if unit != "microseconds" else 0)
        if rx.search(text) and tokens is not None:
            found.append((unit, tokens))
        text = rx.sub(" ", text)
    return found


def main():
    doc = open(sys.argv[1], encoding="utf-8").read()
    generic = doc_names(doc, "Generic names:")
    implied = doc_names(doc, "Implied units:")
    seen = []
    for entry in sys.argv[2:]:
        program, _, path = entry.partition("=")
        walk(program, path, [], seen)
    if not seen:
        sys.exit("FAIL: no options found (is the help layout still CLI11's?)")
    fails = []
    by_name = {}
    for name, kind, desc, where in seen:
        by_name.setdefault(name, []).append((desc, where))
    for name, uses in sorted(by_name.items()):
        texts = {d for d, _ in uses}
        if name not in generic and len(texts) > 1:
            listing = "; ".join(f"{w}: '{d}'" for d, w in uses)
            fails.append(f"{name} has {len(texts)} help texts (one meaning per name; declare it once): {listing}")
    for name, kind, desc, where in seen:
        if not NUMERIC.match(kind) or name in implied:
            continue
        parts = set(name.lstrip("-").lower().split("-"))
        for unit, tokens in stated_units(desc):
            if not parts & tokens:
                suffix = "/".join(f"-{t}" for t in sorted(tokens))
                fails.append(f"{where} {name}: its help states {unit} but the name has no {suffix}: '{desc}'")
    for f in dict.fromkeys(fails):
        print("FAIL:", f)
    programs = len(sys.argv) - 2
    if fails:
        print(f"{len(dict.fromkeys(fails))} problem(s) in {len(seen)} options of {programs} programs")
        return 1
    print(f"PASS: {len(seen)} options ({len(by_name)} names) of {programs} programs: one text per name, units named")
    return 0


if __name__ == "__main__":
    sys.exit(main())
