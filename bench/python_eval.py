#!/usr/bin/python3
# Python eval overhead: gale.Expression.eval on 10^6 points against `gale bench` (the VM alone,
# points already in memory) in the same run, same expressions, points, precision and threads;
# then 8 Python threads evaluating one compiled program at once against one thread (the GIL
# released during eval). Usage: PYTHONPATH=build/python bench/python_eval.py build/cli/gale [N]
import json
import subprocess
import sys
import threading
import time

import numpy as np

import gale

EXPRS = [
    "$P[0]*2.0 + sin($P[1]) * 0.5",
    "d = $P - [1,2,3]; r = length(d); n = d/(r+1); w = cross(n,[0,1,0])*2.5 + n*0.5; "
    "clamp(w*exp(-r*0.01) + [0.1,0,0], -10, 10) + $t*0.1",
    "fbm($P * 0.1, 4) * [1, 0.5, 0.25]",
]


def best_ns(fn, n, min_total=0.5, min_runs=3):
    times = []
    start = time.perf_counter()
    while len(times) < min_runs or time.perf_counter() - start < min_total:
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times) / n * 1e9


def main():
    gale_bin = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    rng = np.random.default_rng(1)
    P = rng.uniform(-50, 50, size=(n, 3))
    print(f"{n} points, float, best of >= 0.5 s")
    print("| expression | threads | gale bench ns/pt | Python eval ns/pt | Python / bench | with out= | out= / bench |")
    print("|---|---|---|---|---|---|---|")
    for expr in EXPRS:
        e = gale.compile(source=expr)
        for threads in (1, 0):
            cli = json.loads(subprocess.run([gale_bin, "bench", "-e", expr, "--points", str(n), "--threads",
                                             str(threads), "--json"], capture_output=True, text=True,
                                            check=True).stdout)["ns_per_point"]
            py = best_ns(lambda: e.eval(P, threads=threads), n)
            out = np.empty((n,) if e.width == 1 else (n, e.width), np.float32)
            inplace = best_ns(lambda: e.eval(P, threads=threads, out=out), n)
            short = expr if len(expr) < 40 else expr[:37] + "..."
            print(f"| `{short}` | {threads or 'all'} | {cli:.2f} | {py:.2f} | {py / cli:.3f}× | {inplace:.2f} | "
                  f"{inplace / cli:.3f}× |")

    # 8 Python threads on one program (1 VM thread each) against the same 8 calls in one thread.
    e = gale.compile(source=EXPRS[2])
    chunks = [P[i::8] for i in range(8)]
    chunks = [np.ascontiguousarray(c) for c in chunks]
    one = best_ns(lambda: [e.eval(c, threads=1) for c in chunks], n)

    def eight():
        ts = [threading.Thread(target=e.eval, args=(c,), kwargs={"threads": 1}) for c in chunks]
        for t in ts:
            t.start()
        for t in ts:
            t.join()

    many = best_ns(eight, n)
    print(f"\n8 calls of {n // 8} points, `{EXPRS[2]}`: one Python thread {one:.2f} ns/pt, "
          f"8 Python threads {many:.2f} ns/pt: {one / many:.2f}× (cores: {len(__import__('os').sched_getaffinity(0))})")


if __name__ == "__main__":
    main()
