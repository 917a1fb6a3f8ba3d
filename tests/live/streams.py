# Load test of gale live's event streams on loopback (run by streams.sh): N open /api/events
# streams must leave /api/state answering fast (median and worst under LIMIT_MS over REQUESTS
# requests), every stream must get the event of an edit, and streams closed by their client
# must be freed (the server's own count, /api/state's eventStreams, drops back).
# Environment: BASE (http://127.0.0.1:PORT), TOKEN, SE (a watched file to touch), STREAMS,
# REQUESTS, LIMIT_MS.
import http.client, os, socket, statistics, sys, time

base, token, se = os.environ["BASE"], os.environ["TOKEN"], os.environ["SE"]
streams_n, requests_n = int(os.environ.get("STREAMS", 64)), int(os.environ.get("REQUESTS", 40))
limit_ms = float(os.environ.get("LIMIT_MS", 50))
host, port = base.split("//")[1].split(":")
port = int(port)
failures = 0
deadline = time.monotonic() + 90  # the whole test is bounded in time


def check(ok, what):
    global failures
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    failures += 0 if ok else 1


def state():
    c = http.client.HTTPConnection(host, port, timeout=10)
    t0 = time.perf_counter()
    c.request("GET", "/api/state?token=" + token)
    r = c.getresponse()
    body = r.read()
    ms = 1000 * (time.perf_counter() - t0)
    c.close()
    import json
    return r.status, json.loads(body), ms


def until(fn, seconds):
    end = min(deadline, time.monotonic() + seconds)
    while time.monotonic() < end:
        v = fn()
        if v:
            return v
        time.sleep(0.02)
    return fn()


def open_stream():
    s = socket.create_connection((host, port), timeout=10)
    s.sendall(f"GET /api/events?token={token} HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n".encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(4096)
        if not chunk:
            break
        head += chunk
    return s, head


socks = []
for i in range(streams_n):
    try:
        s, head = open_stream()
    except OSError as e:
        check(False, f"stream {i}: no reply ({e})")
        break
    if not head.startswith(b"HTTP/1.1 200") or b"text/event-stream" not in head:
        check(False, f"stream {i}: a 200 text/event-stream reply, got {head[:80]!r}")
        break
    socks.append([s, head])
check(len(socks) == streams_n, f"{streams_n} event streams open")
count = until(lambda: state()[1].get("eventStreams") == streams_n, 5)
check(count, f"the server counts {streams_n} open streams: {state()[1].get('eventStreams')}")

times = []
for _ in range(requests_n):
    code, _, ms = state()
    if code != 200:
        check(False, f"/api/state: HTTP {code}")
        break
    times.append(ms)
med, worst = statistics.median(times), max(times)
print(f"     /api/state with {streams_n} streams open: median {med:.2f} ms, worst {worst:.2f} ms over {len(times)} requests")
check(med < limit_ms and worst < limit_ms, f"/api/state median {med:.2f} ms and worst {worst:.2f} ms < {limit_ms:g} ms")

# An edit: every stream hears of it.
text = open(se).read()
open(se, "w").write(text + "\n")
for entry in socks:
    entry[0].settimeout(0.05)
def all_heard():
    for entry in socks:
        if b"event: field" in entry[1]:
            continue
        try:
            chunk = entry[0].recv(65536)
            entry[1] += chunk
        except socket.timeout:
            pass
    return all(b"event: field" in e[1] for e in socks)
heard = until(all_heard, 10)
check(heard, f"every stream gets the edit's field event ({sum(b'event: field' in e[1] for e in socks)} of {len(socks)})")
open(se, "w").write(text)

# Clients that go away: half closed, then the other half.
half = len(socks) // 2
for s, _ in socks[:half]:
    s.close()
freed = until(lambda: state()[1].get("eventStreams") == len(socks) - half, 2)
check(freed, f"{half} closed streams freed within 2 s: {state()[1].get('eventStreams')} open")
for s, _ in socks[half:]:
    s.shutdown(socket.SHUT_RDWR)
    s.close()
freed = until(lambda: state()[1].get("eventStreams") == 0, 2)
check(freed, f"all freed: {state()[1].get('eventStreams')} open")
code, _, ms = state()
check(code == 200, f"the server still answers ({ms:.2f} ms)")
sys.exit(1 if failures else 0)
