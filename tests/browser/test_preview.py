"""The browser preview (`candela render --preview`) in a real browser: headless Chromium driven by
Selenium opens the page of a running render (with the token candela prints), sees the image change and
the samples-per-pixel counter grow, uses the tone-map controls and the heat map, presses stop, and the
output file is written as after SIGINT. Requests without the token, with a foreign Host, or from a page
of another origin are refused while the render goes on, and 200 slow clients neither stop the render nor
take a measurable share of it. A screenshot of the page is kept in $CANDELA_ARTIFACTS (docs/preview.md)."""
import hashlib
import http.server
import json
import os
import re
import shutil
import socket
import subprocess
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from slowloris import SlowClients

CLI = os.environ.get("CANDELA_CLI", "candela")
CORNELL_BOX = str(Path(os.environ.get("CANDELA_SOURCE_DIR", Path(__file__).parents[2])) / "scenes" / "cornell-box.json")
ARTIFACTS = Path(os.environ.get("CANDELA_ARTIFACTS", "test-artifacts"))
CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"


class Render:
    """A `candela render ... --preview 127.0.0.1:0` process and the page's address it prints."""

    def __init__(self, args):
        self.proc = subprocess.Popen([CLI, "render", *args, "--preview", "127.0.0.1:0", "-q"],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.stderr, self.url = [], None  # url: http://127.0.0.1:PORT/?token=...
        found = threading.Event()

        def read():
            for line in self.proc.stderr:
                self.stderr.append(line)
                m = re.search(r"preview at (http://\S+)", line)
                if m:
                    self.url = m.group(1)
                    found.set()
            found.set()

        self.reader = threading.Thread(target=read, daemon=True)
        self.reader.start()
        assert found.wait(60) and self.url, f"no preview address printed: {''.join(self.stderr)}"
        parts = urllib.parse.urlparse(self.url)
        self.port, self.token = parts.port, urllib.parse.parse_qs(parts.query)["token"][0]
        self.base = f"http://127.0.0.1:{self.port}/"

    def get(self, path, headers=None, method="GET"):
        """(status, body) of a request to the preview, with exactly the headers given."""
        req = urllib.request.Request(self.base + path, headers=headers or {}, method=method,
                                     data=b"" if method == "POST" else None)
        try:
            with urllib.request.urlopen(req, timeout=10) as r:
                return r.status, r.read()
        except urllib.error.HTTPError as e:
            return e.code, e.read()

    def state(self):
        status, body = self.get(f"status?token={self.token}")
        assert status == 200, body
        return json.loads(body)["state"]

    def finish(self, timeout=60):
        # Not communicate(): it would read stderr too, racing the reader thread for the last lines.
        self.proc.wait(timeout=timeout)
        self.reader.join(10)  # the last lines of stderr, up to its end
        return self.proc.returncode, "".join(self.stderr)

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


@pytest.fixture
def browser():
    for tool in (CHROMIUM, CHROMEDRIVER):
        assert shutil.which(tool), f"{tool} is missing: apt-get install chromium chromium-driver python3-selenium"
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu", "--window-size=1100,760"):
        options.add_argument(arg)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(30)
    yield driver
    driver.quit()


def wait_for(condition, timeout, what):
    end = time.time() + timeout
    while time.time() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def canvas_digest(driver):
    data = driver.execute_script("return document.getElementById('image').toDataURL('image/png');")
    return hashlib.sha256(data.encode()).hexdigest()


def text(driver, element_id):
    return driver.find_element(By.ID, element_id).text


def mean_spp(driver):
    m = re.match(r"([\d.]+)", text(driver, "spp"))
    return float(m.group(1)) if m else -1.0


def test_page_shows_the_render_converging_and_stops_it(browser, tmp_path):
    out = tmp_path / "preview.exr"
    # The built-in Cornell box, small and on one thread: a pass of 16 spp every fraction of a second,
    # far from done when stopped (the time limit only guards against a hang).
    render = Render([CORNELL_BOX, "--resolution", "96x72", "--spp", "65536", "--threads", "1", "--time-limit", "90", "-o", str(out)])
    try:
        browser.get(render.url)
        wait_for(lambda: text(browser, "state") == "rendering" and int(text(browser, "frames")) >= 1, 30,
                 "the first frame")
        spp1, frames1, digest1 = mean_spp(browser), int(text(browser, "frames")), canvas_digest(browser)
        # The image changes and the counter grows as passes land.
        wait_for(lambda: int(text(browser, "frames")) >= frames1 + 2 and mean_spp(browser) > spp1, 30,
                 "more frames and samples")
        assert canvas_digest(browser) != digest1
        assert re.search(r"\d", text(browser, "eta")), text(browser, "eta")
        assert "/ 65536" in text(browser, "spp")
        # A second viewer, and one that drops its connection mid-request, change nothing for the first.
        assert render.state() == "rendering"
        with socket.create_connection(("127.0.0.1", render.port), timeout=5) as s:
            s.sendall(f"GET /image?token={render.token} HTTP/1.1\r\nHost: 127.0.0.1:{render.port}\r\n\r\n".encode())
        # The exposure slider and the tone map redraw the image.
        before = canvas_digest(browser)
        browser.execute_script("const e = document.getElementById('exposure'); e.value = '-3';"
                               "e.dispatchEvent(new Event('input'));")
        assert text(browser, "exposure-value") == "-3.0 EV"
        assert canvas_digest(browser) != before
        browser.execute_script("const t = document.getElementById('tonemap'); t.value = 'aces';"
                               "t.dispatchEvent(new Event('change'));")
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        browser.save_screenshot(str(ARTIFACTS / "preview.png"))
        # Stop: the render ends as after SIGINT (exit status 3) with the image so far written.
        spp_at_stop = mean_spp(browser)
        browser.find_element(By.ID, "stop").click()
        code, stderr = render.finish(60)
        assert code == 3, stderr
        assert "stopped from the preview page" in stderr
        assert out.exists() and out.stat().st_size > 0
        assert spp_at_stop < 65536
        # The page saw the end (the server lingers until a watching page has polled the final state).
        wait_for(lambda: text(browser, "state") in ("stopped", "disconnected"), 10, "the stopped state")
    finally:
        render.kill()


def test_adaptive_render_shows_a_samples_per_pixel_heat_map(browser, tmp_path):
    out = tmp_path / "adaptive.exr"
    # Long enough (several seconds) that the page loads well before the render ends.
    render = Render([CORNELL_BOX, "--resolution", "96x72", "--adaptive-spp", "512", "--adaptive-batch", "16", "--threads", "1",
                     "-o", str(out)])
    try:
        browser.get(render.url)
        wait_for(lambda: not browser.find_element(By.CSS_SELECTOR, "#view option[value=spp]").get_property("disabled"),
                 30, "the heat map option")
        # After the first adaptive rounds the pixels' sample counts differ (a whole pass, not one still running).
        wait_for(lambda: re.search(r"\((\d+)-(\d+)\)", text(browser, "spp")), 60, "differing sample counts")
        image = canvas_digest(browser)
        browser.execute_script("const v = document.getElementById('view'); v.value = 'spp';"
                               "v.dispatchEvent(new Event('change'));")
        assert canvas_digest(browser) != image
        assert text(browser, "legend-high").endswith("spp")
        colours = browser.execute_script(
            "const c = document.getElementById('image'), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
            "const s = new Set(); for (let i = 0; i < d.length; i += 4) s.add(d[i] * 65536 + d[i + 1] * 256 + d[i + 2]);"
            "return s.size;")
        assert colours >= 3, colours
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        browser.save_screenshot(str(ARTIFACTS / "preview-heat-map.png"))
        code, stderr = render.finish(120)
        assert code == 0, stderr
        assert out.exists()
    finally:
        render.kill()


def test_preview_address_is_loopback_unless_asked():
    r = subprocess.run([CLI, "render", CORNELL_BOX, "--preview", "0.0.0.0:0", "--spp", "1", "-o", "/tmp/never.exr"],
                       capture_output=True, text=True)
    assert r.returncode == 2  # a usage error (docs/cli.md, "Exit status")
    assert "--preview-public" in r.stderr and "this machine only" in r.stderr
    r = subprocess.run([CLI, "render", CORNELL_BOX, "--preview", "localhost:99999", "--spp", "1", "-o", "/tmp/never.exr"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "PORT" in r.stderr


def test_requests_without_the_token_from_a_foreign_host_or_another_origin_are_refused(browser, tmp_path):
    render = Render([CORNELL_BOX, "--resolution", "64x48", "--spp", "65536", "--threads", "1", "--time-limit", "60",
                     "-o", str(tmp_path / "never-stopped.exr")])
    here = f"127.0.0.1:{render.port}"
    try:
        assert render.get("")[0] == 403, "the page without the token"
        assert render.get("status")[0] == 403
        assert render.get("stop", method="POST")[0] == 403
        assert render.get(f"status?token={'0' * 48}")[0] == 403
        # DNS rebinding: a site whose name now resolves to 127.0.0.1 sends its own name as Host.
        assert render.get(f"image?token={render.token}", {"Host": f"evil.example:{render.port}"})[0] == 403
        # A cross-site POST, even one that somehow knows the token.
        assert render.get(f"stop?token={render.token}", {"Origin": "http://evil.example"}, "POST")[0] == 403
        assert render.get(f"stop?token={render.token}", {"Referer": "http://evil.example/"}, "POST")[0] == 403
        assert render.get(f"stop?token={render.token}")[0] in (404, 405), "stop is POST only"
        # A page of another origin, open in the user's browser, tries to stop the render: with a form (a
        # simple request, sent without CORS) and with fetch, with and without the token.
        attack = ("<form id=f method=POST action='http://%s/stop?token=%s'></form><script>"
                  "fetch('http://%s/stop', {method: 'POST', mode: 'no-cors'});"
                  "fetch('http://%s/stop?token=%s', {method: 'POST', mode: 'no-cors'});"
                  "setTimeout(() => document.getElementById('f').submit(), 300);</script>") % (
                      here, render.token, here, here, render.token)

        class AttackPage(http.server.BaseHTTPRequestHandler):
            def do_GET(self):
                self.send_response(200)
                self.send_header("Content-Type", "text/html")
                self.end_headers()
                self.wfile.write(attack.encode())

            def log_message(self, *args):
                pass

        site = http.server.HTTPServer(("127.0.0.1", 0), AttackPage)
        threading.Thread(target=site.handle_request, daemon=True).start()
        browser.get(f"http://127.0.0.1:{site.server_address[1]}/")
        time.sleep(2)
        site.server_close()
        assert render.state() == "rendering", "".join(render.stderr)
        assert render.proc.poll() is None
        # The page itself, with the token, still works and can stop the render.
        browser.get(render.url)
        wait_for(lambda: text(browser, "state") == "rendering", 30, "the page with the token")
        browser.find_element(By.ID, "stop").click()
        code, stderr = render.finish(60)
        assert code == 3 and "stopped from the preview page" in stderr, stderr
    finally:
        render.kill()


def proc_status(pid):
    """VmHWM (peak resident KiB) of a running process, or None once it has gone."""
    try:
        fields = dict(line.split(":", 1) for line in Path(f"/proc/{pid}/status").read_text().splitlines())
        return (int(fields["VmHWM"].split()[0]),)
    except (OSError, KeyError, ValueError):
        return None


def cpu_ticks(pid):
    """(server threads' CPU ticks, whole process's CPU ticks, server threads): utime + stime from /proc."""
    server = total = threads = 0
    try:
        for task in Path(f"/proc/{pid}/task").iterdir():
            stat = (task / "stat").read_text()
            fields = stat[stat.rindex(")") + 2:].split()
            ticks = int(fields[11]) + int(fields[12])
            total += ticks
            if stat[stat.index("(") + 1:stat.rindex(")")].startswith("http-"):
                server += ticks
                threads += 1
    except (OSError, ValueError):
        return None
    return server, total, threads


def test_slow_clients_neither_stop_the_render_nor_take_its_time(tmp_path):
    """200 slowloris clients on loopback for the whole render (each sends a header byte a second and
    never ends its request; closed, it comes back half a second later): the render finishes as planned,
    the page still answers promptly, the server's threads take under 5% of the process's CPU time, and
    memory and the server's threads stay bounded. The render's wall-time ratio is measured in bench/preview_overhead.py."""
    args = [CORNELL_BOX, "--resolution", "96x72", "--spp", "512", "--threads", "1"]
    render = Render(args + ["-o", str(tmp_path / "attacked.exr")])
    clients, peak = SlowClients(render.port, 200), 0
    answered, slowest, ticks, server_threads = 0, 0.0, None, 0
    try:
        end = time.time() + 60
        while render.proc.poll() is None and time.time() < end:
            clients.refill()
            if clients.drip():
                # Meanwhile a viewer with the token is answered at once.
                asked = time.time()
                try:
                    render.state()
                    answered += 1
                    slowest = max(slowest, time.time() - asked)
                except (AssertionError, OSError):
                    pass
            status = proc_status(render.proc.pid)
            peak = max(peak, status[0] if status else 0)
            ticks = cpu_ticks(render.proc.pid) or ticks
            server_threads = max(server_threads, ticks[2] if ticks else 0)
            time.sleep(0.05)
        code, stderr = render.finish(60)
    finally:
        clients.close()
        render.kill()
    assert code == 0, stderr
    assert "stopped" not in stderr and "interrupted" not in stderr
    assert answered >= 2 and slowest < 1.0, (answered, slowest)
    server, total, _ = ticks
    assert total > 0 and server / total < 0.05, f"the server's threads took {server} of {total} ticks"
    assert server_threads == 6, f"{server_threads} server threads (accept, gate and 4 workers)"
    # The same render without clients: memory.
    quiet = Render(args + ["-o", str(tmp_path / "quiet.exr")])
    quiet_peak = 0
    while quiet.proc.poll() is None:
        status = proc_status(quiet.proc.pid)
        quiet_peak = max(quiet_peak, status[0] if status else 0)
        time.sleep(0.05)
    assert quiet.finish(60)[0] == 0
    print(f"server threads {server} of {total} ticks; slowest answer {slowest:.3f} s of {answered}; "
          f"peak RSS {peak} KiB, {quiet_peak} KiB unattacked")
    assert peak < quiet_peak + 32 * 1024, f"peak RSS {peak} KiB against {quiet_peak} KiB unattacked"
