#!/usr/bin/env python3
"""What watching a render costs it: the same render without the preview, with the preview serving
nobody, with a client polling it as the page does, with the real page open in headless Chromium
(on the same cores, as when a user watches on the machine that renders), and under a slowloris attack
of --slow-clients connections on loopback (each sends a header byte a second and never ends its
request; closed, it comes back half a second later).

  bench/preview_overhead.py [--candela build/candela] [--resolution 256x256] [--spp 256] [--threads 2]
                            [--repeats 3] [--no-browser] [--slow-clients 200] [--screenshot docs/images/preview.png]

Runs alternate between the modes, `--repeats` times, and prints per mode the median render time (the
time candela reports for its samples, not the process start) and its ratio to the plain render.
--screenshot saves the page of a longer render of the same scene (for docs/preview.md).
"""
import argparse
import json
import pathlib
import re
import statistics
import subprocess
import sys
import threading
import time
import urllib.request

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "browser"))
from slowloris import SlowClients  # noqa: E402
SCENE = ROOT / "scenes" / "cornell-box.json"


def start(args, extra, spp=None):
    cmd = [args.candela, "render", str(SCENE), "--resolution", args.resolution, "--spp", str(spp or args.spp), "--threads",
           str(args.threads), "-q", "-o", "/tmp/preview-overhead.exr", *extra]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    url = None
    if "--preview" in extra:
        for line in proc.stderr:
            m = re.search(r"preview at (http://\S+)", line)
            if m:
                url = m.group(1)
                break
    return proc, url


def render_seconds(proc):
    out, err = proc.communicate()
    if proc.returncode != 0:
        sys.exit(f"candela failed: {err}")
    return float(re.search(r" in ([\d.]+) s:", out).group(1))


def endpoint(url, path):
    """The printed address (http://HOST:PORT/?token=T) made into one of an endpoint, with the token."""
    base, token = url.split("?token=")
    return f"{base}{path}{'&' if '?' in path else '?'}token={token}"


def poll_like_the_page(url, stop):
    """Status twice a second, the image whenever its version changed (what preview_page.html does)."""
    shown = None
    while not stop.is_set():
        try:
            status = json.load(urllib.request.urlopen(endpoint(url, "status"), timeout=5))
            if status["version"] != shown:
                with urllib.request.urlopen(endpoint(url, "image?max=1280"), timeout=5) as r:
                    r.read()
                    shown = int(r.headers["X-Version"])
        except OSError:
            return
        stop.wait(0.5)


def slow_clients(url, count, stop):
    """`count` slowloris connections (tests/browser/slowloris.py) until `stop`."""
    clients = SlowClients(int(re.search(r":(\d+)/", url).group(1)), count)
    while not stop.is_set():
        clients.refill()
        clients.drip()
        stop.wait(0.5)
    clients.close()


def browser(headless_size="1100,760"):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu", f"--window-size={headless_size}"):
        options.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--candela", default=str(ROOT / "build" / "candela"))
    p.add_argument("--resolution", default="256x256")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--no-browser", action="store_true")
    p.add_argument("--slow-clients", type=int, default=0, help="add a mode under this many slowloris clients")
    p.add_argument("--screenshot")
    args = p.parse_args()

    modes = ["plain", "preview, nobody watching", "preview, polled as the page does"]
    if not args.no_browser:
        modes.append("preview, page open in Chromium")
    if args.slow_clients:
        modes.append(f"preview, {args.slow_clients} slow clients")
    driver = None if args.no_browser else browser()
    times = {m: [] for m in modes}
    for _ in range(args.repeats):
        for mode in modes:
            if mode == "plain":
                times[mode].append(render_seconds(start(args, [])[0]))
                continue
            proc, url = start(args, ["--preview", "127.0.0.1:0"])
            stop = threading.Event()
            if mode.startswith("preview, polled"):
                threading.Thread(target=poll_like_the_page, args=(url, stop), daemon=True).start()
            elif mode.startswith("preview, page"):
                driver.get(url)
            elif mode.endswith("slow clients"):
                threading.Thread(target=slow_clients, args=(url, args.slow_clients, stop), daemon=True).start()
            times[mode].append(render_seconds(proc))
            stop.set()
    base = statistics.median(times["plain"])
    print(f"{args.resolution}, {args.spp} spp, {args.threads} threads, {args.repeats} runs each (median render time):")
    for mode in modes:
        t = statistics.median(times[mode])
        runs = " ".join(f"{x:.2f}" for x in times[mode])
        print(f"  {mode:36s} {t:7.2f} s  {t / base:6.3f}x   ({runs})")

    if args.screenshot:
        # A longer render of the same scene, watched for a few seconds.
        proc, url = start(args, ["--preview", "127.0.0.1:0", "--time-limit", "12"], spp=65536)
        shot = driver or browser()
        shot.get(url)
        time.sleep(8)
        shot.save_screenshot(args.screenshot)
        proc.communicate()
        print(f"screenshot -> {args.screenshot}")
    if driver:
        driver.quit()


if __name__ == "__main__":
    main()
