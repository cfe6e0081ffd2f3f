"""The HTML report of make_fixture.py opened in headless Chromium (Debian's `chromium`):
its script draws every plot without an error, the page asks for nothing over the
network, and a report whose data is broken is caught by the same check."""
import os
import re
import shutil
import subprocess
import tempfile
import unittest

FIXTURE = os.environ["AB_FIXTURE"]
REPORT = os.path.join(FIXTURE, "report", "report.html")
RECORDINGS = 3  # distance plots, one per recording, plus one error histogram
VARIANTS = 3


def chromium():
    for name in ("chromium", "chromium-browser"):
        if shutil.which(name):
            return shutil.which(name)
    raise AssertionError("chromium is not installed (bash tools/setup.sh installs it)")


def render(html_file):
    """The DOM after the page's scripts ran (and the images they load, within a virtual
    2 s), and Chromium's log (console messages)."""
    with tempfile.TemporaryDirectory() as profile:
        result = subprocess.run(
            [chromium(), "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
             "--user-data-dir=" + profile, "--enable-logging=stderr", "--v=0",
             "--virtual-time-budget=2000", "--dump-dom", "file://" + os.path.abspath(html_file)],
            capture_output=True, text=True, timeout=90)
    if result.returncode != 0:
        raise AssertionError("chromium failed (%d): %s" % (result.returncode, result.stderr[-2000:]))
    return result.stdout, result.stderr


def render_status(dom):
    """The body's data-rendered marker and the status line the script writes."""
    body = re.search(r"<body[^>]*>", dom).group(0)
    marker = re.search(r'data-rendered="([^"]*)"', body).group(1)
    status = re.search(r'<p id="render-status"[^>]*>(.*?)</p>', dom, re.S).group(1)
    return marker, status


def console_messages(log):
    """The page's console output: uncaught errors and console.* calls. The report's script
    writes none, so any is a problem."""
    return [line for line in log.splitlines() if ":CONSOLE" in line]


class ReportRendersTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dom, cls.log = render(REPORT)
        with open(REPORT) as f:
            cls.html = f.read()

    def test_every_plot_is_drawn(self):
        self.assertEqual(render_status(self.dom),
                         (str(RECORDINGS + 1), "rendered %d plots" % (RECORDINGS + 1)))
        self.assertEqual(self.dom.count("<svg"), RECORDINGS + 1)

    def test_plots_hold_the_data(self):
        figures = re.findall(r'<figure class="plot" data-plot="distance".*?</figure>', self.dom, re.S)
        self.assertEqual(len(figures), RECORDINGS)
        for figure in figures:
            # each variant's series and the truth, as lines or single points
            self.assertGreaterEqual(figure.count('class="series"'), VARIANTS)
            self.assertEqual(figure.count('class="truth"'), 1)
            self.assertRegex(figure, r"<(polyline|circle) ")
        histogram = re.search(r'<figure class="plot" data-plot="histogram".*?</figure>', self.dom,
                              re.S).group(0)
        self.assertGreater(histogram.count("<rect "), VARIANTS)  # bars, plus the border

    def test_no_script_errors(self):
        self.assertNotEqual(render_status(self.dom)[0], "error")
        self.assertEqual(console_messages(self.log), [])

    def test_self_contained(self):
        self.assertNotRegex(self.html, r"<(link|iframe)\b")
        self.assertNotRegex(self.html, r"""(src|href)=["']?(https?:)?//""")
        self.assertNotRegex(self.html, r"\b(fetch|XMLHttpRequest|import)\s*\(")
        images = re.findall(r'<img [^>]*src="([^"]*)"', self.html)
        self.assertTrue(images)
        for source in images:
            self.assertTrue(source.startswith("data:image/jpeg;base64,"), source[:40])

    def test_an_overlay_zooms_at_its_own_resolution(self):
        """A click on the first overlay opens the viewer at twice the image's own width;
        + doubles it again, Esc closes it."""
        probe = """<script>
window.addEventListener("load", function () {
  var thumbnail = document.querySelector(".overlays img");
  var viewer = document.querySelector(".zoom"), image = viewer.querySelector("img");
  var seen = [];
  function note() { seen.push(viewer.hidden + ":" + image.style.width); }
  thumbnail.click();
  setTimeout(function () {
    note();
    document.dispatchEvent(new KeyboardEvent("keydown", {key: "+"}));
    note();
    document.dispatchEvent(new KeyboardEvent("keydown", {key: "Escape"}));
    note();
    document.body.setAttribute("data-zoom", thumbnail.naturalWidth + "|" + seen.join("|"));
  }, 200);
});
</script>
</body>"""
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "zoom.html")
            with open(path, "w") as f:
                f.write(self.html.replace("</body>", probe, 1))
            dom, log = render(path)
        self.assertEqual(console_messages(log), [])
        zoom = re.search(r'data-zoom="([^"]*)"', dom).group(1).split("|")
        width = int(zoom[0])
        self.assertEqual(width, 320)  # the depth grid of the fixture's half-size rig
        self.assertEqual(zoom[1:], ["false:%dpx" % (2 * width), "false:%dpx" % (4 * width),
                                    "true:%dpx" % (4 * width)])

    def test_uncaught_error_is_seen(self):
        """An error outside the drawing code reaches both the marker and the console log."""
        broken = self.html.replace("</body>", "<script>noSuchFunction();</script>\n</body>", 1)
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "uncaught.html")
            with open(path, "w") as f:
                f.write(broken)
            dom, log = render(path)
        marker, status = render_status(dom)
        self.assertEqual(marker, "error")
        self.assertIn("noSuchFunction", status)
        self.assertTrue(any("noSuchFunction" in line for line in console_messages(log)), log[-2000:])

    def test_broken_data_is_reported(self):
        """The check above would see a script error: a report with bad data says so."""
        broken = self.html.replace('"recordings":[{', '"recordings":[null,{', 1)
        self.assertNotEqual(broken, self.html)
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "broken.html")
            with open(path, "w") as f:
                f.write(broken)
            dom, log = render(path)
        marker, status = render_status(dom)
        self.assertEqual(marker, "error")
        self.assertRegex(status, r"^render error: .*null")


if __name__ == "__main__":
    unittest.main()
