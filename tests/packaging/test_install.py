"""`cmake --install` of the build tree into a fresh prefix, used from there as a machine
uses /usr: the layout (bin/, lib/tilth/plugins/, share/tilth/, the SDK, the systemd unit),
no installed file naming the source or build tree, the demo graph measuring with nothing
but the installed tree, command-line paths relative to the working directory, a machine
graph copied to an /etc/tilth of its own still finding its includes, and the unit passing
`systemd-analyze verify`."""
import os
import re
import shutil
import subprocess
import tempfile
import unittest

BUILD = os.environ["TILTH_BUILD_DIR"]
SOURCE = os.environ["TILTH_SOURCE_DIR"]


def run(*args, cwd=None, timeout=300):
    env = {k: v for k, v in os.environ.items() if not k.startswith("TILTH_")}
    return subprocess.run(list(args), capture_output=True, text=True, timeout=timeout, cwd=cwd,
                          env=env)


class InstalledTree(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scratch = tempfile.mkdtemp(prefix="tilth-install-")
        cls.prefix = os.path.join(cls.scratch, "usr")
        for component in ["runtime", "sdk"]:
            result = run("cmake", "--install", BUILD, "--prefix", cls.prefix, "--strip",
                         "--component", component)
            assert result.returncode == 0, result.stdout + result.stderr
        cls.tilth = os.path.join(cls.prefix, "bin", "tilth")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.scratch)

    def installed(self, *parts):
        return os.path.join(self.prefix, *parts)

    def test_the_layout_of_an_installed_tree(self):
        for program in ["tilth", "tilth-ab", "tilth-calibrate", "tilth-cameras", "tilth-doctor",
                        "tilth-recording", "tilth-simulate", "tilth-train-segmenter"]:
            self.assertTrue(os.access(self.installed("bin", program), os.X_OK), program)
        plugins = sorted(os.listdir(self.installed("lib", "tilth", "plugins")))
        self.assertEqual(plugins, sorted(
            f"tilth_{family}.so" for family in
            ["aravis", "depth", "estimation", "mcap", "modbus", "pairing", "recording",
             "registration", "segmentation", "sinks", "synthetic", "view"]))
        self.assertEqual(sorted(os.listdir(self.installed("share", "tilth", "graphs"))),
                         sorted(os.listdir(os.path.join(SOURCE, "graphs"))))
        self.assertEqual(sorted(os.listdir(self.installed("share", "tilth", "calib"))),
                         sorted(os.listdir(os.path.join(SOURCE, "calib"))))
        self.assertTrue(os.path.isfile(self.installed("include", "tilth", "stage.h")))
        self.assertTrue(os.path.isfile(self.installed("lib", "cmake", "Tilth", "TilthConfig.cmake")))
        self.assertTrue(os.path.islink(self.installed("lib", "libtilth_sdk.so")))
        with open(self.installed("lib", "systemd", "system", "tilth@.service")) as unit:
            self.assertIn(f"ExecStart={self.tilth} run /etc/tilth/%i.json", unit.read())

    def test_no_installed_file_names_the_source_or_build_tree(self):
        # A path, not the same letters inside a longer name ("/project" in
        # "chain/project.raw" when the tree is /project).
        wrong = [re.compile(rb"(?<![\w.-])" + re.escape(os.path.realpath(tree).encode()) +
                            rb"(?![\w.-])") for tree in (SOURCE, BUILD)]
        naming = []
        for folder, _, files in os.walk(self.prefix):
            for name in files:
                path = os.path.join(folder, name)
                if os.path.islink(path):
                    continue
                with open(path, "rb") as f:
                    content = f.read()
                naming += [(path, w.pattern) for w in wrong if w.search(content)]
        self.assertEqual(naming, [])

    def test_the_demo_measures_from_the_installed_tree_alone(self):
        elsewhere = os.path.join(self.scratch, "elsewhere")
        os.makedirs(elsewhere, exist_ok=True)
        result = run(self.tilth, "run", self.installed("share", "tilth", "graphs", "demo.json"),
                     "--frames", "12", cwd=elsewhere)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("12 frames completed", result.stderr)
        first = result.stdout.splitlines()[0]
        # The simulator's case C at 518 mm, which the chain measures to 0.04 mm.
        measured = float(first.split(":")[1].split("mm")[0])
        self.assertAlmostEqual(measured, 518.0, delta=0.5, msg=first)

    def test_command_line_paths_are_relative_to_the_working_directory(self):
        work = os.path.join(self.scratch, "work")
        os.makedirs(work, exist_ok=True)
        shutil.copy(self.installed("share", "tilth", "graphs", "demo.json"), work)
        # The copy includes measurement-chain.json, found among the shipped graphs, and
        # names ../calib/paper_rig.calib.json, which is not beside it.
        result = run(self.tilth, "run", "demo.json", "--frames", "3", cwd=work)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertIn("paper_rig.calib.json: cannot read calibration file", result.stderr)
        result = run(self.tilth, "run", "demo.json", "--frames", "3", "--set",
                     f"camera.calibration={self.installed('share', 'tilth', 'calib', 'paper_rig.calib.json')}",
                     cwd=work)
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_a_machine_graph_copied_to_etc_finds_its_includes(self):
        etc = os.path.join(self.scratch, "etc", "tilth")
        os.makedirs(etc, exist_ok=True)
        for machine in ["seeder", "tillage", "transplanter"]:
            shutil.copy(self.installed("share", "tilth", "graphs", f"{machine}.json"), etc)
            result = run(self.tilth, "validate", os.path.join(etc, f"{machine}.json"))
            self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
            self.assertIn("valid", result.stdout)

    def test_the_unit_passes_systemd_analyze_verify(self):
        units = os.path.join(self.scratch, "units")
        os.makedirs(units, exist_ok=True)
        instance = os.path.join(units, "tilth@seeder.service")
        shutil.copy(self.installed("lib", "systemd", "system", "tilth@.service"), instance)
        result = run("systemd-analyze", "verify", instance)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout + result.stderr, "")
        # It does complain: a unit naming a program that is not there.
        with open(instance) as f:
            text = f.read()
        with open(instance, "w") as f:
            f.write(text.replace(self.tilth, self.tilth + "-missing"))
        result = run("systemd-analyze", "verify", instance)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("tilth-missing", result.stderr)


if __name__ == "__main__":
    unittest.main()
