#!/usr/bin/env python3
"""gale live's re-simulation latency: a slider edit (POST /api/param, what the page sends) while
Simulate runs, to the new run's first frame on the page's wire (its `frame` event and the
GET /api/frame the page then makes), and to its first stepped frame (frame first + 1, the first
one the edit can change). Baseline, measured in the same run: `gale sim` of the same scene
started cold, to its first and second frame files on disk (what any restart must pay).

    python3 bench/live_resim.py build/cli/gale [--runs 5]

Scenes: examples/05_ice_cape ($turbulenceScale) and tests/live/resim (a 24×24 flag, $speed).
Each run starts its own server on loopback and stops it (and everything it started) by pid.
"""
import argparse, http.client, json, os, shutil, socket, statistics, subprocess, sys, tempfile, threading, time

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.dirname(HERE)
SCENES = [
    ("ice cape (examples/05_ice_cape)", os.path.join(SRC, "examples/05_ice_cape"), "cape", "turbulenceScale", [0.7, 0.5]),
    ("24x24 flag (tests/live/resim)", os.path.join(SRC, "tests/live/resim"), "flag", "speed", [7, 4]),
]


class Live:
    def __init__(self, gale, scene):
        self.proc = subprocess.Popen([gale, "live", scene, "--no-open", "--port", "0"], stderr=subprocess.PIPE, text=True)
        line = ""
        while "token=" not in line:
            line = self.proc.stderr.readline()
            if not line:
                raise RuntimeError("gale live printed no URL")
        url = line.split("http://", 1)[1].strip()
        self.host, rest = url.split(":", 1)
        self.port = int(rest.split("/", 1)[0])
        self.token = url.split("token=", 1)[1]
        self.events = []  # (time, type, data)
        self.cv = threading.Condition()
        threading.Thread(target=self.listen, daemon=True).start()

    def listen(self):
        s = socket.create_connection((self.host, self.port))
        s.sendall(f"GET /api/events?token={self.token} HTTP/1.1\r\nHost: {self.host}:{self.port}\r\n\r\n".encode())
        buf = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                return
            now = time.perf_counter()
            buf += chunk
            while b"\n\n" in buf:
                block, buf = buf.split(b"\n\n", 1)
                fields = dict(l.split(": ", 1) for l in block.decode().split("\n") if ": " in l and not l.startswith(":"))
                if "event" in fields:
                    with self.cv:
                        self.events.append((now, fields["event"], json.loads(fields.get("data", "{}"))))
                        self.cv.notify_all()

    def request(self, method, path, body=None):
        c = http.client.HTTPConnection(self.host, self.port, timeout=30)
        sep = "&" if "?" in path else "?"
        c.request(method, f"{path}{sep}token={self.token}", body=None if body is None else json.dumps(body),
                  headers={"Content-Type": "application/json"})
        r = c.getresponse()
        data = r.read()
        c.close()
        return r.status, json.loads(data)

    def wait(self, pred, timeout=60):
        end = time.perf_counter() + timeout
        with self.cv:
            while True:
                for e in self.events:
                    if pred(e):
                        return e
                left = end - time.perf_counter()
                if left <= 0:
                    raise RuntimeError("timed out waiting for an event")
                self.cv.wait(left)

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=10)


def cold_start(gale, scene, obj):
    out = tempfile.mkdtemp(prefix="gale-bench-")
    t0 = time.perf_counter()
    p = subprocess.Popen([gale, "sim", scene, "-o", out, "--threads", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    first = second = None
    while second is None and time.perf_counter() - t0 < 60:
        if first is None and os.path.exists(os.path.join(out, f"{obj}.0001.obj")):
            first = time.perf_counter() - t0
        if os.path.exists(os.path.join(out, f"{obj}.0002.obj")):
            second = time.perf_counter() - t0
            first = first or second
        time.sleep(0.002)
    p.kill()
    p.wait()
    shutil.rmtree(out, ignore_errors=True)
    return first, second


def one(gale, folder, obj, param, values):
    tmp = tempfile.mkdtemp(prefix="gale-bench-live-")
    scene_dir = os.path.join(tmp, "scene")
    shutil.copytree(folder, scene_dir, ignore=shutil.ignore_patterns("*.png"))
    scene = os.path.join(scene_dir, "scene.toml")
    base = cold_start(gale, scene, obj)
    live = Live(gale, scene)
    try:
        live.request("POST", "/api/simulate", {"action": "start"})
        live.wait(lambda e: e[1] == "frame" and e[2].get("run") == 1 and e[2]["frame"] >= 3)
        t0 = time.perf_counter()
        status, _ = live.request("POST", "/api/param", {"name": param, "value": values[0]})
        assert status == 200, status
        restart = live.wait(lambda e: e[1] == "sim" and e[2].get("run") == 2 and e[2].get("running"))
        first = live.wait(lambda e: e[1] == "frame" and e[2].get("run") == 2)
        status, fr = live.request("GET", f"/api/frame?n={first[2]['frame']}")
        fetched = time.perf_counter()
        assert status == 200 and fr["run"] == 2, (status, fr.get("run"))
        second = live.wait(lambda e: e[1] == "frame" and e[2].get("run") == 2 and e[2]["frame"] == first[2]["frame"] + 1)
        return {"restart": restart[0] - t0, "first": first[0] - t0, "fetched": fetched - t0, "second": second[0] - t0,
                "cold_first": base[0], "cold_second": base[1]}
    finally:
        live.stop()
        shutil.rmtree(tmp, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("gale")
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    for name, folder, obj, param, values in SCENES:
        rows = [one(a.gale, folder, obj, param, values) for _ in range(a.runs)]
        med = {k: 1000 * statistics.median(r[k] for r in rows) for k in rows[0]}
        print(f"{name}: median of {a.runs} (ms)")
        print(f"  edit -> restart event          {med['restart']:7.1f}")
        print(f"  edit -> first frame event      {med['first']:7.1f}")
        print(f"  edit -> first frame fetched    {med['fetched']:7.1f}")
        print(f"  edit -> first stepped frame    {med['second']:7.1f}")
        print(f"  baseline: cold gale sim, frame 1 file {med['cold_first']:7.1f}, frame 2 file {med['cold_second']:7.1f}")
        print(f"  ratio: first frame fetched / cold frame 1 = {med['fetched'] / med['cold_first']:.2f}; "
              f"first stepped / cold frame 2 = {med['second'] / med['cold_second']:.2f}")


if __name__ == "__main__":
    main()
