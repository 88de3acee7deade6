#!/usr/bin/env bash
# Opens a report page in headless Chromium and fails if any image is broken,
# a script throws, the console logs an error, a resource fails to load, or the
# page reaches outside file:/data: (a report must be self-contained).
# Also saves a full-page screenshot to look at.
#
# usage: scripts/check-report-in-browser.sh REPORT.html [SCREENSHOT.png]
#   SCREENSHOT defaults to REPORT.screenshot.png beside the report.
# exit:  0 page fine, 1 page has problems, 2 could not run the check.
#
# How: Chromium is driven over the DevTools protocol through
# --remote-debugging-pipe (fds 3/4, NUL-separated JSON) by a stdlib-only
# Python client, so no port is opened and nothing is injected into the page.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 2 ]]; then
    sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
report=$1
[[ -f $report ]] || { echo "no such file: $report" >&2; exit 2; }
shot=${2:-${report%.html}.screenshot.png}

if ! command -v chromium >/dev/null 2>&1; then
    echo "installing chromium (Debian package)..." >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq && apt-get install -y -qq chromium >/dev/null
fi
command -v python3 >/dev/null 2>&1 || { echo "python3 is required" >&2; exit 2; }

profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT

python3 - "$report" "$shot" "$profile" <<'PY'
import base64, fcntl, json, os, pathlib, select, subprocess, sys, time

report = pathlib.Path(sys.argv[1]).resolve()
shot = pathlib.Path(sys.argv[2])
profile = sys.argv[3]
DEADLINE = time.monotonic() + 90

cmd_r, cmd_w = os.pipe()   # we write commands, chromium reads fd 3
evt_r, evt_w = os.pipe()   # chromium writes fd 4, we read
# Park the child's ends above the low fds so dup2 to 3/4 cannot clobber them.
child_in = fcntl.fcntl(cmd_r, fcntl.F_DUPFD, 10)
child_out = fcntl.fcntl(evt_w, fcntl.F_DUPFD, 10)
os.close(cmd_r)
os.close(evt_w)

def in_child():
    os.dup2(child_in, 3)
    os.dup2(child_out, 4)

flags = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", "--hide-scrollbars", "--remote-debugging-pipe",
    f"--user-data-dir={profile}", "about:blank",
]
log = open(os.path.join(profile, "chromium.log"), "wb")
proc = subprocess.Popen(["chromium", *flags], preexec_fn=in_child, pass_fds=(3, 4),
                        stdin=subprocess.DEVNULL, stdout=log, stderr=log)
os.close(child_in)
os.close(child_out)

buf = b""
events = []
next_id = 0

def fail_infra(msg):
    print(f"check-report-in-browser: {msg}", file=sys.stderr)
    try:
        print(open(os.path.join(profile, "chromium.log"), errors="replace").read()[-2000:],
              file=sys.stderr)
    except OSError:
        pass
    proc.kill()
    sys.exit(2)

def read_message():
    global buf
    while b"\0" not in buf:
        left = DEADLINE - time.monotonic()
        if left <= 0:
            fail_infra("timed out waiting for chromium")
        ready, _, _ = select.select([evt_r], [], [], min(left, 1.0))
        if ready:
            chunk = os.read(evt_r, 1 << 20)
            if not chunk:
                fail_infra("chromium closed the DevTools pipe")
            buf += chunk
        elif proc.poll() is not None:
            fail_infra(f"chromium exited with {proc.returncode}")
    msg, buf = buf.split(b"\0", 1)
    return json.loads(msg)

def send(method, params=None, session=None):
    global next_id
    next_id += 1
    msg = {"id": next_id, "method": method, "params": params or {}}
    if session:
        msg["sessionId"] = session
    os.write(cmd_w, json.dumps(msg).encode() + b"\0")
    while True:
        m = read_message()
        if m.get("id") == next_id:
            if "error" in m:
                fail_infra(f"{method}: {m['error']}")
            return m.get("result", {})
        events.append(m)

def wait_for(method):
    for i, m in enumerate(events):
        if m.get("method") == method:
            return
    while True:
        m = read_message()
        events.append(m)
        if m.get("method") == method:
            return

target = send("Target.createTarget", {"url": "about:blank"})["targetId"]
session = send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
for domain in ("Page", "Runtime", "Log", "Network"):
    send(f"{domain}.enable", session=session)
send("Emulation.setDeviceMetricsOverride",
     {"width": 1200, "height": 900, "deviceScaleFactor": 1, "mobile": False}, session=session)
events.clear()
nav = send("Page.navigate", {"url": report.as_uri()}, session=session)
if nav.get("errorText"):
    fail_infra(f"navigation failed: {nav['errorText']}")
wait_for("Page.loadEventFired")
time.sleep(0.3)  # let late console messages and image decodes arrive

probe = """(() => {
  const imgs = [...document.images];
  return {
    title: document.title,
    images: imgs.length,
    broken: imgs.filter(i => !i.complete || i.naturalWidth === 0)
                .map(i => (i.getAttribute('src') || '(no src)').slice(0, 60)),
    scripts: document.scripts.length,
  };
})()"""
res = send("Runtime.evaluate", {"expression": probe, "returnByValue": True}, session=session)
page = res["result"]["value"]

metrics = send("Page.getLayoutMetrics", session=session)
size = metrics.get("cssContentSize") or metrics["contentSize"]
clip = {"x": 0, "y": 0, "width": min(size["width"], 4000),
        "height": min(size["height"], 16000), "scale": 1}
png = send("Page.captureScreenshot",
           {"format": "png", "captureBeyondViewport": True, "clip": clip}, session=session)
shot.write_bytes(base64.b64decode(png["data"]))

# Drain anything already queued, then shut down.
while True:
    ready, _, _ = select.select([evt_r], [], [], 0.2)
    if not ready:
        break
    chunk = os.read(evt_r, 1 << 20)
    if not chunk:
        break
    buf += chunk
    while b"\0" in buf:
        msg, buf = buf.split(b"\0", 1)
        events.append(json.loads(msg))
try:
    send("Browser.close")
except SystemExit:
    pass
try:
    proc.wait(timeout=10)
except subprocess.TimeoutExpired:
    proc.kill()

problems = []
for img in page["broken"]:
    problems.append(f"broken image: {img}")
for m in events:
    method, p = m.get("method"), m.get("params", {})
    if method == "Runtime.exceptionThrown":
        d = p["exceptionDetails"]
        text = d.get("exception", {}).get("description") or d.get("text", "")
        problems.append(f"script error: {text.splitlines()[0] if text else d}")
    elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
        args = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
        problems.append(f"console.{p['type']}: {args}")
    elif method == "Log.entryAdded" and p["entry"].get("level") == "error":
        e = p["entry"]
        problems.append(f"console error ({e.get('source')}): {e.get('text')} {e.get('url', '')}".rstrip())
    elif method == "Network.loadingFailed":
        problems.append(f"load failed: {p.get('errorText')} (request {p.get('requestId')})")
    elif method == "Network.requestWillBeSent":
        url = p["request"]["url"]
        if not url.startswith(("file:", "data:", "about:")):
            problems.append(f"external resource (report must be self-contained): {url[:100]}")

# One failure often shows up as several events; report each text once.
problems = list(dict.fromkeys(problems))
print(f"{report}: title {page['title']!r}, {page['images']} images, "
      f"{len(page['broken'])} broken, {page['scripts']} scripts; screenshot {shot}")
for p in problems:
    print(f"  FAIL {p}")
sys.exit(1 if problems else 0)
PY
