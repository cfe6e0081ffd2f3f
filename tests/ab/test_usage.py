"""`tilth ab` on bad input: each mistake gives a message saying what, where and what was
expected, and nothing runs. Also: `tilth` finds the tilth-ab program, the progress bar
appears only on a terminal, a graph that fails is shown in the report and fails the
run, and a node given another stage type keeps the chain's region."""
import json
import os
import pty
import shutil
import subprocess
import tempfile
import unittest

TILTH = os.environ["TILTH_BIN"]
FIXTURE = os.environ["AB_FIXTURE"]
RECORDINGS = os.path.join(FIXTURE, "recordings")
CASE_C = os.path.join(RECORDINGS, "case_c")
# The fixture's recordings are of a half-resolution rig.
CALIBRATION = "calibration=" + os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                            "half_rig.calib.json")


def ab(*arguments):
    return subprocess.run([TILTH, "ab", *arguments], capture_output=True, text=True, timeout=60)


class UsageTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp()
        self.out = os.path.join(self.folder, "out")

    def tearDown(self):
        shutil.rmtree(self.folder)

    def assert_refused(self, result, *messages, code=2):
        self.assertEqual(result.returncode, code, result.stdout + result.stderr)
        for message in messages:
            self.assertIn(message, result.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.out, "summary.json")))

    def test_tilth_lists_and_runs_ab(self):
        usage = subprocess.run([TILTH, "--help"], capture_output=True, text=True, timeout=10)
        self.assertRegex(usage.stdout, r"other commands found:.* ab\b")
        self.assertIn("--variant NAME:SETTING", ab("--help").stdout)

    def test_no_variant(self):
        self.assert_refused(ab(CASE_C, "--out", self.out),
                            "no variant given: use --variant or --variants")

    def test_no_recording(self):
        self.assert_refused(ab("--variant", "a", "--out", self.out), "no recording given")
        self.assert_refused(ab(os.path.join(self.folder, "nothing"), "--variant", "a"),
                            "nothing: no such file or folder")
        self.assert_refused(ab(self.folder, "--variant", "a", "--out", self.out),
                            self.folder + ": no recording.json, and no image-folder recording "
                            "or .mcap file directly inside")

    def test_bad_variant_name(self):
        self.assert_refused(ab(CASE_C, "--variant", "a b:segment.dilation_px=3"),
                            "variant name 'a b': expected 1-64 letters, digits, '-' or '_'")

    def test_setting_without_value(self):
        self.assert_refused(ab(CASE_C, "--variant", "a:segment.dilation_px"),
                            "--variant a:segment.dilation_px: expected NAME:chain=FILE, "
                            "NAME:NODE.type=STAGE_TYPE, NAME:NODE.PARAM=VALUE or NAME:recorded")

    def test_unknown_node(self):
        self.assert_refused(ab(CASE_C, "--variant", "a:segmnt.dilation_px=3", "--out", self.out),
                            "command line:--variant a:segmnt.dilation_px=3: no node 'segmnt' in "
                            "the chain", "did you mean 'segment'?")

    def test_unknown_parameter_and_bad_value(self):
        result = ab(CASE_C, "--variant", "a:segment.dilaton_px=3",
                    "--variant", "b:segment.dilation_px=-1", "--out", self.out)
        self.assert_refused(result,
                            "command line:--variant a:segment.dilaton_px=3: unknown parameter "
                            "'dilaton_px' of segmentation.fusion; did you mean "
                            "'dilation_px'?",
                            "command line:--variant b:segment.dilation_px=-1: parameter "
                            "'dilation_px': expected an integer")
        self.assertIn("2 problem(s); nothing was run", result.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.out, "runs")))

    def test_unknown_stage_type(self):
        result = ab(CASE_C, "--variant", "a:segment.type=segmentation.colour_threshold",
                    "--out", self.out)
        self.assert_refused(result,
                            "command line:--variant a:segment.type=segmentation.colour_threshold: "
                            "unknown stage type 'segmentation.colour_threshold'; did you mean "
                            "'segmentation.color_threshold'")
        self.assertIn("1 problem(s); nothing was run", result.stderr)

    def test_variants_file_problems(self):
        variants = os.path.join(self.folder, "variants.json")
        with open(variants, "w") as f:
            json.dump({"variants": [{"name": "a", "sett": {}},
                                    {"name": "b", "set": {"segment": 3}},
                                    {"name": "c", "chain": "missing.json"},
                                    {"name": "a"}]}, f)
        result = ab(CASE_C, "--variants", variants, "--out", self.out)
        self.assert_refused(result,
                            variants + ":/variants/0/sett: unknown key 'sett' in variant; did you "
                            "mean 'set'?",
                            variants + ":/variants/1/set/segment: expected a key \"NODE.PARAM\" "
                            "or \"NODE.type\"",
                            variants + ":/variants/2/chain: no such file: " +
                            os.path.join(self.folder, "missing.json"),
                            variants + ":/variants/3/name: variant 'a' is defined twice")
        with open(variants, "w") as f:
            f.write('{"variants": [}')
        self.assert_refused(ab(CASE_C, "--variants", variants), variants + ":1:15: malformed JSON")
        # The second "set" silently replaced the first.
        with open(variants, "w") as f:
            f.write('{"variants": [{"name": "a", "set": {"segment.dilation_px": 4}, "set": {}}]}')
        self.assert_refused(ab(CASE_C, "--variants", variants),
                            variants + ":/variants/0/set: expected each key once in an object, "
                            "got \"set\" again")

    def test_unknown_baseline(self):
        self.assert_refused(ab(CASE_C, "--variant", "a", "--variant", "b:segment.dilation_px=2",
                               "--baseline", "c", "--out", self.out),
                            "--baseline c: no such variant; the variants are a, b")

    def test_tags_file_problems(self):
        tags = os.path.join(self.folder, "tags.csv")
        for text, message in [
                ("site\ncase_c,north\n", tags + ":1: expected the header recording,KEY..."),
                ("recording,\ncase_c,north\n", tags + ":1: column 2 has no tag name"),
                ("recording,site\ncase_c,north,x\n", tags + ":2: 3 fields, expected 2"),
                ("recording,site\n\ncase_d,north\n",
                 tags + ":3: no recording named 'case_d' among the 1 given"),
                ('recording,site\ncase_c,"north, upper"\n', tags + ":2: quotes are not read"),
                ("", tags + ": empty")]:
            with open(tags, "w") as f:
                f.write(text)
            self.assert_refused(ab(CASE_C, "--variant", "a", "--tags", tags, "--out", self.out),
                                message)
        self.assert_refused(ab(CASE_C, "--variant", "a", "--tags", tags + ".missing", "--out",
                               self.out), tags + ".missing: cannot read the tags file")

    def test_numbers_are_read_whole(self):
        for option, text, expected in [
                ("--jobs", "2x", "--jobs: expected a whole number in [1, 256], got '2x'"),
                ("--jobs", "0", "--jobs: expected a whole number in [1, 256], got '0'"),
                ("--overlays", "-1", "--overlays: expected a whole number in [0, 100], got '-1'"),
                ("--no-soil-below", "0.1x",
                 "--no-soil-below: expected a number in [0, 1], got '0.1x'")]:
            self.assert_refused(ab(CASE_C, "--variant", "a", option, text, "--out", self.out),
                                "tilth ab: " + expected)

    def test_output_folder_is_protected(self):
        os.makedirs(self.out)
        with open(os.path.join(self.out, "notes.txt"), "w") as f:
            f.write("mine")
        self.assert_refused(ab(CASE_C, "--variant", "a", "--out", self.out),
                            "folder exists and is not empty; give --overwrite")
        self.assert_refused(ab(CASE_C, "--variant", "a", "--out", self.out, "--overwrite"),
                            "folder holds no summary.json; not overwriting a folder that is not "
                            "a report")
        self.assertTrue(os.path.exists(os.path.join(self.out, "notes.txt")))

    def test_progress_bar_only_on_a_terminal(self):
        plain = ab(CASE_C, "--variant", "a", "--var", CALIBRATION, "--out", self.out)
        self.assertEqual(plain.returncode, 0, plain.stderr)
        self.assertNotIn("\r", plain.stdout)
        self.assertIn("report: " + os.path.join(self.out, "report.html"), plain.stdout)
        # On a pseudo-terminal: the bar, redrawn in place, then cleared.
        leader, follower = pty.openpty()
        process = subprocess.Popen([TILTH, "ab", CASE_C, "--variant", "a", "--var", CALIBRATION,
                                    "--out", self.out, "--overwrite"],
                                   stdout=follower, stderr=subprocess.DEVNULL)
        os.close(follower)
        output = bytearray()
        while True:
            try:
                data = os.read(leader, 4096)
            except OSError:  # the terminal closed with the process
                break
            if not data:
                break
            output.extend(data)
        os.close(leader)
        self.assertEqual(process.wait(timeout=60), 0)
        text = output.decode()
        self.assertRegex(text, r"\r\[[#-]{24}\] +\d+%  \d/1 graphs  \d+ frames")
        self.assertIn("\r\x1b[K", text)

    def test_failed_graph_is_reported(self):
        broken = os.path.join(self.folder, "broken")
        shutil.copytree(CASE_C, broken)
        with open(os.path.join(broken, "recording.json"), "w") as f:
            f.write('{"format": "tilth-image-folder/9"}')
        result = ab(CASE_C, broken, "--variant", "a", "--var", CALIBRATION, "--out", self.out)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("tilth ab: a graph failed: node 'recording' (recording.image_folder) failed "
                      "to start: " + broken, result.stderr)
        with open(os.path.join(self.out, "summary.json")) as f:
            rows = {row["recording"]: row for row in json.load(f)["recording_figures"]}
        self.assertFalse(rows["case_c"]["failed"])
        self.assertEqual(rows["case_c"]["figures"]["frames"], 3)
        self.assertTrue(rows["broken"]["failed"])
        self.assertIn("tilth-image-folder/9", rows["broken"]["failure"])
        self.assertEqual(rows["broken"]["figures"]["frames"], 0)
        with open(os.path.join(self.out, "report.html")) as f:
            self.assertIn("Some graphs failed", f.read())

    def test_a_replaced_stage_keeps_the_chains_region(self):
        """segment.type replaces the fusion node and drops its parameters, but not the
        chain's "roi": "${roi}": the new stage segments the region the registration colours
        and the estimation reads, and only that is judged."""
        result = ab(CASE_C, "--variant", "index:segment.type=segmentation.color_index",
                    "--var", CALIBRATION, "--out", self.out)
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(os.path.join(self.out, "runs", "index", "case_c", "frames.jsonl")) as f:
            frames = [json.loads(line) for line in f]
        # The half rig's 320x240 image: its middle half (160x120) and the 8 px around it.
        segmented = (160 + 16) * (120 + 16)
        for frame in frames:
            mask = frame["mask"]
            judged = mask["tp"] + mask["fp"] + mask["fn"] + mask["tn"]
            self.assertEqual(judged + mask["ignored"], 320 * 240)
            # Less the pixels of mixed truth.
            self.assertLessEqual(judged, segmented)
            self.assertGreater(judged, 0.85 * segmented)


if __name__ == "__main__":
    unittest.main()
