#!/usr/bin/env python3
# Speed against error: runs the gale benchmarks that were built (BUILD/bench/gale_bench_*),
# parses their tables and writes bench/REPORT.md with plots in bench/report/ (matplotlib).
# `make report` runs it; what a benchmark cannot provide yet is said in the report.
import argparse
import datetime
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Each benchmark: its arguments (small but meaningful sizes) and a time limit in seconds.
BENCHES = {
    "vm": (["300000", "5"], 600),
    "noise": (["300000", "5"], 600),
    "turbulence": ([], 900),
    "solver": (["--quick"], 900),
}


def run_bench(build, name):
    exe = os.path.join(build, "bench", "gale_bench_" + name)
    if not os.path.exists(exe):
        return None, "not built (%s missing)" % exe
    args, limit = BENCHES[name]
    try:
        p = subprocess.run([exe] + args, capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired:
        return None, "timed out after %d s" % limit
    if p.returncode != 0:
        return p.stdout, "exited with %d: %s" % (p.returncode, p.stderr.strip()[-400:])
    return p.stdout, None


def number(text):
    m = re.match(r"\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)", text.replace("**", ""))
    return float(m.group(1)) if m else None


def markdown_tables(text):
    """[(heading, header cells, rows of cells)] for every |-table, with the last ## heading."""
    tables, heading, lines = [], "", text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i].strip()
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if line.startswith("|") and i + 1 < len(lines) and re.match(r"^\|[\s:|-]+\|$", lines[i + 1].strip()):
            header = [c.strip() for c in line.strip("|").split("|")]
            rows, i = [], i + 2
            while i < len(lines) and lines[i].strip().startswith("|"):
                rows.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
                i += 1
            tables.append((heading, header, rows))
            continue
        i += 1
    return tables


def column(header, *words):
    for k, h in enumerate(header):
        if all(w.lower() in h.lower() for w in words):
            return k
    return None


def vm_precision(out, figdir, notes):
    """The VM table: ns per point in float and double, and the float-vs-double error."""
    rows = []
    for line in out.splitlines():
        # name, hand, f32, f64, ratio, 2-thread, speed-up, error: the numbers are the last 7 fields.
        parts = line.split()
        if len(parts) >= 8 and re.match(r"^[\d.]+x?$", parts[-4]) and "e" in parts[-1]:
            try:
                hand, f32, f64 = float(parts[-7]), float(parts[-6]), float(parts[-5])
                err = float(parts[-1])
            except ValueError:
                continue
            rows.append((" ".join(parts[:-7]), hand, f32, f64, err))
    if not rows:
        notes.append("VM precision: no rows recognised in gale_bench_vm's output.")
        return None
    fig, ax = plt.subplots(figsize=(7, 3.2))
    # '$' would start matplotlib mathtext ($P[0] …); show the expression as written.
    labels = [(r[0][:32] + ("…" if len(r[0]) > 32 else "")).replace("$", r"\$") for r in rows]
    xs = range(len(rows))
    ax.bar([x - 0.27 for x in xs], [r[1] for r in rows], 0.27, label="hand-written C++ (float)")
    ax.bar(list(xs), [r[2] for r in rows], 0.27, label="VM float")
    ax.bar([x + 0.27 for x in xs], [r[3] for r in rows], 0.27, label="VM double")
    for x, r in zip(xs, rows):
        ax.annotate("float err %.1e" % r[4], (x, max(r[1:4])), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(list(xs))
    ax.set_xticklabels(labels, fontsize=8)
    ax.set_ylabel("ns per point")
    ax.set_title("VM precision: float is faster; its error against double")
    ax.set_ylim(0, 1.2 * max(max(r[1:4]) for r in rows))
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    path = os.path.join(figdir, "vm_precision.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    table = ["| expression | hand ns | VM f32 ns | VM f64 ns | f32 vs f64 error |", "|---|---|---|---|---|"]
    table += ["| `%s` | %.2f | %.2f | %.2f | %.1e |" % r for r in rows]
    return path, "\n".join(table)


def noise_octaves(out, figdir, notes):
    lines = out.splitlines()
    start = next((i for i, l in enumerate(lines) if l.startswith("octaves vs time")), None)
    if start is None:
        notes.append("Noise octaves: gale_bench_noise printed no 'octaves vs time' table.")
        return None
    rows = []
    for line in lines[start + 2:]:
        parts = line.split()
        if not parts or not parts[0].isdigit():
            break
        vals = [number(p) for p in parts]
        rows.append(vals)
    if not rows:
        notes.append("Noise octaves: the table was empty.")
        return None
    fig, ax = plt.subplots(figsize=(6, 3.4))
    oct_ = [r[0] for r in rows]
    ax.plot(oct_, [r[1] for r in rows], "o-", label="hand-written")
    ax.plot(oct_, [r[2] for r in rows], "o-", label="VM float")
    ax.plot(oct_, [r[3] for r in rows], "o-", label="VM double")
    ax.set_xlabel("fbm octaves")
    ax.set_ylabel("ns per point")
    if len(rows[0]) >= 6:
        ax2 = ax.twinx()
        ax2.semilogy(oct_, [max(r[5], 1e-12) for r in rows], "k--", label="float error")
        ax2.set_ylabel("float vs double error")
    ax.set_title("Noise octaves: cost per octave")
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    path = os.path.join(figdir, "noise_octaves.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    table = ["| octaves | hand ns | VM f32 ns | VM f64 ns |", "|---|---|---|---|"]
    table += ["| %d | %.2f | %.2f | %.2f |" % (r[0], r[1], r[2], r[3]) for r in rows]
    return path, "\n".join(table)


def fft_resolution(out, figdir, notes):
    tables = markdown_tables(out)
    synth = next((t for t in tables if column(t[1], "synthesis ms") is not None and column(t[1], "variance") is not None), None)
    sampling = next((t for t in tables if column(t[1], "rms error") is not None), None)
    if not synth and not sampling:
        notes.append("FFT resolution: gale_bench_turbulence printed no synthesis or sampling table.")
        return None
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    if synth:
        h, rows = synth[1], synth[2]
        res = [number(r[0]) for r in rows]
        ms = [number(r[column(h, "synthesis ms")]) for r in rows]
        var = [number(r[column(h, "variance")]) for r in rows]
        axes[0].loglog(res, ms, "o-", label="synthesis ms")
        axes[0].set_xlabel("FFT resolution (per axis)")
        axes[0].set_ylabel("ms")
        ax2 = axes[0].twinx()
        ax2.plot(res, var, "s--", color="C1", label="resolved variance %")
        ax2.set_ylabel("resolved variance (%)")
        axes[0].set_title("synthesis cost and resolved variance")
    if sampling:
        h, rows = sampling[1], sampling[2]
        kns, kerr = column(h, "random ns"), column(h, "rms error")
        groups = {}
        for r in rows:
            groups.setdefault(r[1] if len(r) > 1 else "", []).append((number(r[kns]), number(r[kerr]), r[0]))
        for name, pts in groups.items():
            axes[1].loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
            for p in pts:
                axes[1].annotate(p[2], (p[0], p[1]), fontsize=7)
        axes[1].set_xlabel("ns per point (random points)")
        axes[1].set_ylabel("rms error / sigma")
        axes[1].set_title("sampling: speed against error")
        axes[1].legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(figdir, "fft_resolution.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path, None


def solver_tradeoff(out, figdir, notes):
    tables = [t for t in markdown_tables(out) if column(t[1], "integrator") is not None and column(t[1], "error") is not None]
    if not tables:
        notes.append("Solver substeps and tolerances: gale_bench_solver printed no integrator/error table.")
        return None
    fig, axes = plt.subplots(1, len(tables), figsize=(5.2 * len(tables), 3.8), squeeze=False)
    for ax, (heading, h, rows) in zip(axes[0], tables):
        ki, kt, ke, kw = column(h, "integrator"), column(h, "tol"), column(h, "error"), column(h, "wall")
        groups = {}
        for r in rows:
            err, wall = number(r[ke]), number(r[kw])
            if err is None or wall is None:
                continue
            key = r[ki] + (" tol " + r[kt] if kt is not None else "")
            groups.setdefault(key, []).append((wall, max(err, 1e-12)))
        for name, pts in sorted(groups.items()):
            pts.sort()
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
        ax.set_xlabel("wall time (ms)")
        ax.set_ylabel("error (m)")
        ax.set_title(heading[:60], fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    path = os.path.join(figdir, "solver_tradeoff.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path, None


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="bench")
    args = ap.parse_args()
    figdir = os.path.join(args.out, "report")
    os.makedirs(figdir, exist_ok=True)
    sections = [
        ("VM precision (float against double)", "vm", vm_precision),
        ("Noise octaves", "noise", noise_octaves),
        ("FFT turbulence resolution", "turbulence", fft_resolution),
        ("Solver substeps and tolerances", "solver", solver_tradeoff),
    ]
    md = ["# gale: speed against error", "",
          "Written by `make report` (bench/report.py) on %s. Every benchmark measures its baseline in "
          "the same run; absolute times depend on the machine and its load, ratios less so." %
          datetime.date.today().isoformat(), ""]
    for title, bench, fn in sections:
        md += ["## " + title, ""]
        print("report: running gale_bench_%s ..." % bench, file=sys.stderr)
        out, problem = run_bench(args.build, bench)
        notes = []
        if problem:
            notes.append("gale_bench_%s: %s." % (bench, problem))
        if out:
            try:
                result = fn(out, figdir, notes)
            except Exception as e:  # a changed table format must not lose the rest of the report
                notes.append("could not read gale_bench_%s's tables (%s: %s)." % (bench, type(e).__name__, e))
                result = None
            if result:
                path, table = result
                md += ["![%s](%s)" % (title, os.path.relpath(path, args.out)), ""]
                if table:
                    md += [table, ""]
            md += ["<details><summary>gale_bench_%s output</summary>" % bench, "", "```", out.rstrip(), "```", "",
                   "</details>", ""]
        for n in notes:
            md += ["*Not available:* " + n, ""]
    path = os.path.join(args.out, "REPORT.md")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(md))
    os.replace(path + ".tmp", path)
    print("report: wrote %s and %s/*.png" % (path, figdir), file=sys.stderr)


if __name__ == "__main__":
    main()
