"""Headless Chromium (Debian's `chromium`) driven over its DevTools protocol
(python3-websocket): open a page, evaluate script in it, collect its uncaught errors and
console messages, take a screenshot. The browser is stopped by its pid, its output bounded."""
import base64
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request

import websocket


def chromium():
    for name in ("chromium", "chromium-browser"):
        if shutil.which(name):
            return shutil.which(name)
    raise AssertionError("chromium is not installed (bash tools/setup.sh installs it)")


class Browser:
    """One headless Chromium showing `url` in a window of `width` x `height`."""

    def __init__(self, url, width=1280, height=900):
        self.profile = tempfile.mkdtemp(prefix="tilth-chromium-")
        self.log = open(os.path.join(self.profile, "chromium.log"), "w+")
        self.process = subprocess.Popen(
            [chromium(), "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
             "--user-data-dir=" + self.profile, "--remote-debugging-port=0",
             "--remote-allow-origins=*", "--window-size=%d,%d" % (width, height), url],
            stdout=subprocess.DEVNULL, stderr=self.log, start_new_session=True)
        self.next_id = 0
        self.events = []
        try:
            self.socket = websocket.create_connection(self._page_socket(url), timeout=30)
            self.call("Runtime.enable")
        except BaseException:
            self.close()
            raise

    def _page_socket(self, url):
        deadline = time.monotonic() + 60
        port = None
        while port is None:
            assert self.process.poll() is None, "chromium exited: " + self._log_tail()
            assert time.monotonic() < deadline, "chromium did not open DevTools: " + self._log_tail()
            port = (re.search(r"DevTools listening on ws://[^:]+:(\d+)/", self._log_tail()) or
                    [None, None])[1]
            time.sleep(0.1)
        while True:
            with urllib.request.urlopen("http://127.0.0.1:%s/json/list" % port, timeout=10) as r:
                pages = [t for t in json.load(r) if t["type"] == "page" and t["url"].startswith(url)]
            if pages:
                return pages[0]["webSocketDebuggerUrl"]
            assert time.monotonic() < deadline, "chromium opened no page for " + url
            time.sleep(0.1)

    def _log_tail(self):
        self.log.flush()
        self.log.seek(0)
        return self.log.read()[-4000:]

    def call(self, method, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise AssertionError("%s failed: %s" % (method, message["error"]))
                return message["result"]
            self.events.append(message)

    def evaluate(self, expression):
        """The value of `expression` in the page (JSON-serialisable, promises awaited)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise AssertionError("%s threw: %s" % (expression, result["exceptionDetails"]))
        return result["result"].get("value")

    def emulate(self, width, height, mobile):
        """Lays the page out as a device of that size (a tablet: 768 x 1024, mobile)."""
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                  deviceScaleFactor=1, mobile=mobile)

    def problems(self):
        """Uncaught exceptions and console messages of the page so far."""
        return [event for event in self.events
                if event.get("method") in ("Runtime.exceptionThrown", "Runtime.consoleAPICalled")]

    def screenshot(self, path):
        """PNG, or JPEG when `path` ends in .jpg."""
        jpeg = path.endswith(".jpg")
        data = self.call("Page.captureScreenshot", format="jpeg" if jpeg else "png",
                         **({"quality": 85} if jpeg else {}))["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        if getattr(self, "socket", None) is not None:
            self.socket.close()
        # The browser and its renderer processes: the group it leads.
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        self.log.close()
        shutil.rmtree(self.profile, ignore_errors=True)
