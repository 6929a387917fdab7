#!/usr/bin/env python3
"""Mutation testing of the OpenCL kernels in kernels/.

Each mutant changes one token of one kernel line: an arithmetic or
comparison operator (+ and -, * and /, < and >, <= and >=, && and ||),
fmin and fmax, or one digit of a numeric constant. Every mutation keeps the
line's length, so instead of rebuilding the crate per mutant the script
builds the judging test binaries once and rewrites the line inside them:
the kernels reach the binaries as text (`include_str!`) and are compiled
by OpenCL at run time, so a binary with the line rewritten runs exactly
the mutated kernel.

A mutant is caught when a judging binary fails or runs past the timeout.
For survivors the golden test's PSNR lines say whether any gallery image
changed (a finite PSNR) or none did (every image identical: equivalent for
what users see at that quality). Text snapshots are not judges: they
would catch every mutant of the text without saying whether it matters.

Usage: scripts/mutate_kernels.py [--sample N | --all | --only FILE:LINE[:COLUMN] ...]
                                 [--out DIR]
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# The judges: every device test that checks what the kernels compute, not
# their text. render_quality and render_sizes cover supersampling (jitter,
# the AOVs' centre ray) and sizes that tiles do not divide; inside, the
# brute-force march of shapes with only a membership test.
JUDGES = [
    "conformance",
    "render_effects",
    "render_agreement",
    "render_quality",
    "render_sizes",
    "smooth_oracle",
    "golden",
    "inside",
]
TIMEOUT_S = 300

SWAPS = [
    (" + ", " - "),
    (" - ", " + "),
    (" * ", " / "),
    (" / ", " * "),
    (" < ", " > "),
    (" > ", " < "),
    (" <= ", " >= "),
    (" >= ", " <= "),
    ("&&", "||"),
    ("||", "&&"),
    ("fmin(", "fmax("),
    ("fmax(", "fmin("),
]
NUMBER = re.compile(r"(?<![\w.])(\d+\.\d*|\d+)(?:[eE][-+]?\d+)?[uf]?(?![\w.])")


def code_part(line):
    """The columns of `line` that are code: before a // or /* comment."""
    cut = len(line)
    for marker in ("//", "/*"):
        i = line.find(marker)
        if i != -1:
            cut = min(cut, i)
    return line[:cut]


def mutants():
    """Every single-token, same-length mutant, in a fixed order."""
    found = []
    for path in sorted(ROOT.glob("kernels/**/*.cl")):
        rel = path.relative_to(ROOT).as_posix()
        in_comment = False
        for number, line in enumerate(path.read_text().splitlines(), 1):
            stripped = line.strip()
            if in_comment:
                in_comment = "*/" not in stripped
                continue
            if stripped.startswith("/*") and "*/" not in stripped:
                in_comment = True
                continue
            code = code_part(line)
            if not code.strip() or stripped.startswith("#if") or stripped.startswith("#endif"):
                continue
            for old, new in SWAPS:
                start = 0
                while (i := code.find(old, start)) != -1:
                    found.append((rel, number, line, i, old, new))
                    start = i + 1
            for m in NUMBER.finditer(code):
                digits = [j for j in range(m.start(1), m.end(1)) if code[j].isdigit()]
                j = digits[0]
                d = code[j]
                found.append((rel, number, line, j, d, str((int(d) + 1) % 10)))
    return found


def build():
    """Builds the judging test binaries once; returns {name: path}."""
    args = ["cargo", "test", "--no-run", "--all-features", "--message-format=json"]
    for judge in JUDGES:
        args += ["--test", judge]
    out = subprocess.run(args, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    found = {}
    for line in out.splitlines():
        msg = json.loads(line)
        if msg.get("reason") == "compiler-artifact" and msg.get("executable"):
            if msg["target"]["name"] in JUDGES:
                found[msg["target"]["name"]] = msg["executable"]
    missing = set(JUDGES) - set(found)
    if missing:
        sys.exit(f"no test binary for {sorted(missing)}")
    return found


def run_judges(binaries, workdir):
    """Runs every judge; returns (caught by, golden's PSNR lines)."""
    env = dict(os.environ, FRACTAL_SDF_REQUIRE_DEVICE="1", PROPTEST_RNG_SEED="20261201")
    psnr = []
    caught = None
    for judge in JUDGES:
        binary = workdir / judge
        try:
            r = subprocess.run(
                [str(binary), "--nocapture"] if judge == "golden" else [str(binary)],
                cwd=ROOT, env=env, capture_output=True, text=True, timeout=TIMEOUT_S,
            )
        except subprocess.TimeoutExpired:
            caught = caught or f"{judge} (timeout)"
            continue
        if judge == "golden":
            psnr = re.findall(r"^(\w+): (inf|[\d.]+) dB", r.stdout + r.stderr, re.M)
        if r.returncode != 0:
            caught = caught or judge
    return caught, psnr


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", type=int, default=60, help="mutants to run, spread evenly")
    parser.add_argument("--all", action="store_true", help="run every mutant")
    parser.add_argument("--only", nargs="+", metavar="FILE:LINE[:COLUMN]",
                        help="run the mutants of these lines (or columns) only")
    parser.add_argument("--out", default=str(ROOT / "target/mutants-kernels"))
    args = parser.parse_args()

    every = mutants()
    if args.only:
        lines = set(args.only)
        chosen = [m for m in every
                  if f"{m[0]}:{m[1]}" in lines or f"{m[0]}:{m[1]}:{m[3] + 1}" in lines]
    elif args.all or args.sample >= len(every):
        chosen = every
    else:
        chosen = [every[i * len(every) // args.sample] for i in range(args.sample)]
    print(f"==> {len(every)} kernel mutants; running {len(chosen)}", flush=True)
    binaries = build()
    out = Path(args.out)
    shutil.rmtree(out, ignore_errors=True)
    work = out / "bin"
    work.mkdir(parents=True)
    originals = {name: Path(path).read_bytes() for name, path in binaries.items()}

    # The unmutated kernels must pass, or no outcome means anything.
    for name, data in originals.items():
        (work / name).write_bytes(data)
        (work / name).chmod(0o755)
    caught, _ = run_judges(binaries, work)
    if caught:
        sys.exit(f"the unmutated kernels fail {caught}: fix that first")

    results = []
    for k, (rel, number, line, col, old, new) in enumerate(chosen, 1):
        mutated = line[:col] + new + line[col + len(old):]
        before, after = line.encode(), mutated.encode()
        sites = 0
        for name, data in originals.items():
            sites = max(sites, data.count(before))
            (work / name).write_bytes(data.replace(before, after))
        if sites == 0:
            sys.exit(f"{rel}:{number}: the line is not in the test binaries")
        start = time.time()
        caught, psnr = run_judges(binaries, work)
        changed = [f"{n} {db} dB" for n, db in psnr if db != "inf"]
        outcome = "caught" if caught else ("survived" if changed else "survived, no image changed")
        results.append({
            "file": rel, "line": number, "column": col + 1, "from": old.strip(),
            "to": new.strip(), "text": line.strip(), "outcome": outcome,
            "caught_by": caught, "images_changed": changed,
            "seconds": round(time.time() - start, 1),
        })
        print(f"[{k}/{len(chosen)}] {rel}:{number}:{col + 1} {old.strip()!r} -> {new.strip()!r}: "
              f"{outcome}{' by ' + caught if caught else ''}"
              f"{' (' + ', '.join(changed) + ')' if changed and not caught else ''}", flush=True)

    (out / "results.json").write_text(json.dumps(results, indent=1))
    counts = {}
    for r in results:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    print(f"==> kernel mutants: {len(results)} run of {len(every)}: "
          + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())))
    print(f"==> details: {out / 'results.json'}")


if __name__ == "__main__":
    main()
