#!/usr/bin/python3
"""Test of scripts/plot_robustness.py on fabricated robustness.csv files.

Usage: /usr/bin/python3 test_plot_robustness.py [path/to/plot_robustness.py]   (CTest passes it)

The two files are synthetic (written here, not by auvrl eval): three groups, one of which the
policy never reached (empty time and hold cells) and one only the PID has. The test checks that
the script exits 0 and writes a PNG given the files or their directories; that a missing input
exits 2 naming it; and that without matplotlib it exits 3 naming the Debian packages.
Exits 77 (CTest: skipped) when Debian's python3-matplotlib or python3-numpy is missing.
"""
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else \
    os.path.join(HERE, "..", "..", "scripts", "plot_robustness.py")
PYTHON = "/usr/bin/python3"
HEADER = ("group,controller,episodes,reached,held,flips,blow_ups,left_region,"
          "mean_time_to_reach_s,mean_hold_error_m,mean_thrust_energy,mean_smoothness,"
          "description\n")


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def fabricate(directory):
    write(os.path.join(directory, "policy", "robustness.csv"), HEADER +
          "rest_start,policy,20,20,20,0,0,0,8.7,0.105,123.3,0.262,\"at rest, in the region\"\n"
          "t1_0pct,policy,20,0,0,2,0,0,,,226.3,0.075,T1 at 0 % efficiency\n")
    write(os.path.join(directory, "pid", "robustness.csv"), HEADER +
          "rest_start,pid,20,20,20,0,0,0,11.9,0.047,58.2,0.008,\"at rest, in the region\"\n"
          "t1_0pct,pid,20,20,20,0,0,0,12.2,0.046,58.3,0.008,T1 at 0 % efficiency\n"
          "current,pid,20,20,19,0,0,0,12.2,0.071,77.8,0.011,constant current\n")


class PlotRobustness(unittest.TestCase):
    def run_script(self, *args, env=None):
        return subprocess.run([PYTHON, SCRIPT, *args], capture_output=True, text=True, env=env,
                              timeout=120)

    def test_draws_the_figure_from_files_or_directories(self):
        with tempfile.TemporaryDirectory() as d:
            fabricate(d)
            for policy, pid in ((os.path.join(d, "policy", "robustness.csv"),
                                 os.path.join(d, "pid", "robustness.csv")),
                                (os.path.join(d, "policy"), os.path.join(d, "pid"))):
                out = os.path.join(d, "robustness.png")
                if os.path.exists(out):
                    os.remove(out)
                result = self.run_script(policy, pid, out)
                self.assertEqual(result.returncode, 0, result.stderr)
                with open(out, "rb") as f:
                    self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
                self.assertGreater(os.path.getsize(out), 10000)

    def test_a_missing_input(self):
        with tempfile.TemporaryDirectory() as d:
            fabricate(d)
            missing = os.path.join(d, "none", "robustness.csv")
            result = self.run_script(os.path.join(d, "policy"), missing,
                                     os.path.join(d, "out.png"))
            self.assertEqual(result.returncode, 2, result.stderr)
            self.assertIn(missing, result.stderr)
            self.assertFalse(os.path.exists(os.path.join(d, "out.png")))

    def test_without_matplotlib_it_says_what_to_install(self):
        with tempfile.TemporaryDirectory() as d, tempfile.TemporaryDirectory() as fake:
            fabricate(d)
            write(os.path.join(fake, "matplotlib", "__init__.py"),
                  'raise ImportError("not installed", name="matplotlib")\n')
            result = self.run_script(os.path.join(d, "policy"), os.path.join(d, "pid"),
                                     os.path.join(d, "out.png"),
                                     env=dict(os.environ, PYTHONPATH=fake))
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertIn("apt install python3-matplotlib python3-numpy", result.stderr)


if __name__ == "__main__":
    try:
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError:
        print("test_plot_robustness: python3-matplotlib or python3-numpy missing: skipped")
        sys.exit(77)
    unittest.main()
