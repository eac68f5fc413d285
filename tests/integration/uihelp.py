# What the browser tests share (ui_test.py, studio_test.py): the rcb4 tool run, a virtual board
# served on a pty, `rcb4 ui` running, a headless Chromium (Debian's, through selenium), waiting.
# SPDX-License-Identifier: BSL-1.0
import contextlib
import json
import re
import signal
import subprocess
import time


def tools(RCB4):
    """run(*args), serve() (a pty's path), Ui(*args) (.url, .port, .stop()), browser(), wait_until(pred),
    joints_on(device) (the tool's joint list by name)."""

    def run(*args, timeout=60):
        p = subprocess.run([RCB4, *args], capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr

    @contextlib.contextmanager
    def serve():
        srv = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
        try:
            yield srv.stdout.readline().strip()
        finally:
            srv.terminate()
            srv.wait(timeout=10)

    class Ui:
        """`rcb4 ui ARGS` running; .url, .port; stop() ends it with SIGINT and returns its exit code."""

        def __init__(self, *args):
            self.p = subprocess.Popen([RCB4, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self.url = self.p.stdout.readline().strip()
            m = re.match(r"http://[^/]*:(\d+)/", self.url)
            self.port = int(m.group(1)) if m else 0

        def stop(self):
            if self.p.poll() is None:
                self.p.send_signal(signal.SIGINT)
            try:
                rc = self.p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.p.kill()
                rc = "hung"
            self.err = self.p.stderr.read()
            return rc

    def joints_on(dev):
        rc, out, err = run("--json", "--device", dev, "joint", "list")
        assert rc == 0, err
        return {j["name"]: j for j in json.loads(out)}

    def browser():
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        o = webdriver.ChromeOptions()
        o.binary_location = "/usr/bin/chromium"
        # WebGL (the studio's 3D view) drawn by SwiftShader: no GPU needed.
        for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,1080",
                  "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-background-networking",
                  "--no-first-run"):
            o.add_argument(a)
        return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)


    def wait_until(pred, timeout=10, step=0.05):
        end = time.time() + timeout
        while time.time() < end:
            v = pred()
            if v:
                return v
            time.sleep(step)
        return pred()

    return run, serve, Ui, browser, wait_until, joints_on
