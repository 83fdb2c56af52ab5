#!/usr/bin/python3
"""Test of scripts/plot_mission.py on a fabricated `auvrl run` directory.

Usage: /usr/bin/python3 test_plot_mission.py [path/to/plot_mission.py]   (CTest passes the path)

The run directory is synthetic (written here, not by auvrl run): two way-points, two thrusters,
one injected event. The test checks that the script exits 0 and writes both figures; that
without matplotlib (a stand-in module that fails to import, first on PYTHONPATH) it exits 3
with a note naming the Debian packages; and that a missing run directory exits 2.
Exits 77 (CTest: skipped) when Debian's python3-matplotlib or python3-numpy is missing.
"""
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else \
    os.path.join(HERE, "..", "..", "scripts", "plot_mission.py")
PYTHON = "/usr/bin/python3"


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def fabricate(run):
    """A straight run north through [2, 0, 5] to [4, 0, 5] in 6 s, T1 faulted at 3 s."""
    header = ("t,x,y,z,phi,theta,psi,u,v,w,p,q,r,cmd_1,cmd_2,thrust_1,thrust_2,distance_m,"
              "waypoint\n")
    rows = []
    for k in range(61):
        t = 0.1 * k
        x = min(4.0, 0.8 * t)
        thrust_1 = 20.0 if t < 3.0 else 2.0
        rows.append(f"{t:.1f},{x},0,5,0,0,0,0.8,0,0,0,0,0,20,10,{thrust_1},10,"
                    f"{abs((2.0 if t < 2.5 else 4.0) - x)},{0 if t < 2.5 else 1}\n")
    write(os.path.join(run, "trajectory.csv"), header + "".join(rows))
    write(os.path.join(run, "waypoints.csv"),
          "index,x,y,z,reached,time_to_reach_s,time_from_previous_s,completed_s,hold_error_m,"
          "energy\n0,2,0,5,1,1.9,1.9,2.5,0.2,3.1\n1,4,0,5,1,4.4,1.9,5.0,0.1,2.9\n")
    write(os.path.join(run, "vehicle.csv"),
          "vehicle,file,thruster,name,max_thrust_n\nboat,boat.yaml,1,T1_port,40\n"
          "boat,boat.yaml,2,T2_starboard,40\n")
    write(os.path.join(run, "events.csv"),
          'time_s,event\n3,"t=3.0 s (due at 3 s): thruster 0 (T1_port) at 10 % efficiency"\n')


class PlotMission(unittest.TestCase):
    def run_script(self, run, env=None):
        return subprocess.run([PYTHON, SCRIPT, run], capture_output=True, text=True, env=env,
                              timeout=120)

    def test_draws_both_figures(self):
        with tempfile.TemporaryDirectory() as run:
            fabricate(run)
            result = self.run_script(run)
            self.assertEqual(result.returncode, 0, result.stderr)
            for name in ("mission_3d.png", "mission_thrusters.png"):
                path = os.path.join(run, "plots", name)
                self.assertTrue(os.path.getsize(path) > 10000, name)

    def test_without_matplotlib_it_says_what_to_install(self):
        with tempfile.TemporaryDirectory() as run, tempfile.TemporaryDirectory() as fake:
            fabricate(run)
            write(os.path.join(fake, "matplotlib", "__init__.py"),
                  'raise ImportError("not installed", name="matplotlib")\n')
            env = dict(os.environ, PYTHONPATH=fake)
            result = self.run_script(run, env)
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertIn("apt install python3-matplotlib python3-numpy", result.stderr)
            self.assertFalse(os.path.exists(os.path.join(run, "plots")))

    def test_a_missing_run_directory(self):
        with tempfile.TemporaryDirectory() as parent:
            result = self.run_script(os.path.join(parent, "none"))
            self.assertEqual(result.returncode, 2, result.stderr)
            self.assertIn("trajectory.csv is missing", result.stderr)


if __name__ == "__main__":
    try:
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError:
        print("test_plot_mission: python3-matplotlib or python3-numpy missing: skipped")
        sys.exit(77)
    unittest.main()
