"""The browser preview (`candela render --preview`) in a real browser: headless Chromium driven by
Selenium opens the page of a running render, sees the image change and the samples-per-pixel counter
grow, uses the tone-map controls and the heat map, presses stop, and the output file is written as
after SIGINT. A screenshot of the page is kept in $CANDELA_ARTIFACTS (docs/preview.md)."""
import hashlib
import os
import re
import shutil
import socket
import subprocess
import threading
import time
import urllib.parse
import urllib.request
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By

CLI = os.environ.get("CANDELA_CLI", "candela")
CORNELL_BOX = str(Path(os.environ.get("CANDELA_SOURCE_DIR", Path(__file__).parents[2])) / "scenes" / "cornell-box.json")
ARTIFACTS = Path(os.environ.get("CANDELA_ARTIFACTS", "test-artifacts"))
CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"


class Render:
    """A `candela render ... --preview 127.0.0.1:0` process and the page's address it prints."""

    def __init__(self, args):
        self.proc = subprocess.Popen([CLI, "render", *args, "--preview", "127.0.0.1:0", "-q"],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.stderr, self.url = [], None
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
        with urllib.request.urlopen(render.url + "status", timeout=10) as r:
            assert b'"state":"rendering"' in r.read()
        port = urllib.parse.urlparse(render.url).port
        with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
            s.sendall(b"GET /image HTTP/1.1\r\nHost: x\r\n\r\n")
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
    assert r.returncode == 1
    assert "--preview-public" in r.stderr and "no authentication" in r.stderr
    r = subprocess.run([CLI, "render", CORNELL_BOX, "--preview", "localhost:99999", "--spp", "1", "-o", "/tmp/never.exr"],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "PORT" in r.stderr
