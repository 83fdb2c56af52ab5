#!/usr/bin/python3
"""Test of scripts/plot_run.py on a fabricated run directory.

Usage: /usr/bin/python3 test_plot_run.py [path/to/plot_run.py]   (CTest passes the path)

The run directory is synthetic (written here, not by auvrl): a learned-policy and a PID
evaluation with made-up numbers (and their robustness suites with auvrl's comparison table),
training logs with a rising success rate. It contains damaged rows (a short row and an
unreadable number in eval/policy/summary.csv, a bad number in episodes.csv and in a trajectory)
and missing files (progress.csv, the PID's current-scenario trajectory). The test checks that
the script exits 0, writes the expected figures, that report.md holds the table values
computed from the fabricated rows and the robustness table, names the damaged rows by file and
line and the missing files, and that its figure links resolve; and that a run directory with
nothing in it, one of binary junk and non-finite numbers, and a path that is not a directory,
are handled.
Exits 77 (CTest: skipped) when Debian's python3-matplotlib or python3-numpy is missing.
"""
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else \
    os.path.join(HERE, "..", "..", "scripts", "plot_run.py")
PYTHON = "/usr/bin/python3"

SUMMARY_HEADER = ("scenario,controller,episode,goal_x,goal_y,goal_z,reached,time_to_reach_s,"
                  "mean_error_after_reach_m,final_error_m,thrust_energy,end_reason")
START = (0.0, 0.0, 5.0)
GOAL = (7.0, 6.0, 10.0)


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def trajectory(reach_s, fault=False, facing_away=False, miss_by=0.0, bad_row=None):
    """A smooth approach to the goal (distance 0.5 m at reach_s), or to a point miss_by metres
    off it; 701 rows of 0.1 s in the evaluation's columns."""
    d0 = math.dist(START, GOAL)
    tau = reach_s / math.log(d0 / 0.5) if reach_s else 12.0
    end = [g + (miss_by if i == 0 else 0.0) for i, g in enumerate(GOAL)]
    cols = ["t", "x", "y", "z", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r"]
    cols += [f"cmd_{i}" for i in range(1, 7)] + [f"thrust_{i}" for i in range(1, 7)]
    cols += ["distance_m"]
    lines = [",".join(cols)]
    bearing = math.atan2(GOAL[1], GOAL[0])
    for k in range(701):
        t = 0.1 * k
        a = math.exp(-t / tau)
        pos = [e + (s - e) * a for s, e in zip(START, end)]
        psi = bearing + (math.pi * math.exp(-t / 2.0) if facing_away else 0.0)
        cmd = [39.24 * a * s for s in (1, 0.9, 0.3, -0.3, 0.6, 0.7)]
        real = [c * (1 - math.exp(-t / 0.3)) for c in cmd]
        if fault:
            real[0] *= 0.1
        dist = math.dist(pos, GOAL)
        row = [t] + pos + [0, 0, psi] + [0] * 6 + cmd + real + [dist]
        lines.append(",".join(f"{v:.6g}" for v in row))
        if bad_row is not None and k == bad_row:
            lines.append("oops," + ",".join(["1"] * (len(cols) - 1)))
    return "\n".join(lines) + "\n"


def summary_row(scenario, ctrl, ep, goal, reached, t, hold, final, energy, reason):
    f = (lambda v: "" if v is None else f"{v}")
    return (f"{scenario},{ctrl},{ep},{goal[0]},{goal[1]},{goal[2]},{int(reached)},{f(t)},"
            f"{f(hold)},{final},{energy},{reason}")


def fabricate(run):
    # ---- The learned policy: reaches test1, test2, current; misses the fault. ----
    pol = [SUMMARY_HEADER,
           summary_row("test1", "policy", 0, GOAL, 1, 21.4, 0.041, 0.012, 123.4, "reached"),
           summary_row("test2", "policy", 0, GOAL, 1, 16.9, 0.052, 0.02, 140.2, "reached"),
           summary_row("fault", "policy", 0, GOAL, 0, None, None, 2.345, 300.5, "time_limit"),
           summary_row("current", "policy", 0, GOAL, 1, 30.2, 0.11, 0.09, 88.8, "reached")]
    suite_goals = [(3, 4, 6), (-5, 2, 9), (8, -8, 2), (1, 1, 12), (-9, -9, 14), (0, 6, 3)]
    suite_pol = [(1, 10.0), (1, 12.0), (1, 14.0), (1, 20.0), (0, None), (0, None)]
    for ep, (g, (r, t)) in enumerate(zip(suite_goals, suite_pol)):
        pol.append(summary_row("suite", "policy", ep, g, r, t, 0.05 if r else None,
                               0.03 if r else 1.5, 100 + ep, "reached" if r else "left_region"))
    pol.append("suite,policy,7,1,2")  # line 12: too few fields
    pol.append(summary_row("suite", "policy", 8, (1, "x", 3), 1, 9.0, 0.1, 0.1, 1, "reached"))
    write(os.path.join(run, "eval/policy/summary.csv"), "\n".join(pol) + "\n")
    tdir = os.path.join(run, "eval/policy/trajectories")
    write(os.path.join(tdir, "test1_0.csv"), trajectory(21.4))
    write(os.path.join(tdir, "test2_0.csv"), trajectory(16.9, facing_away=True, bad_row=100))
    write(os.path.join(tdir, "fault_0.csv"), trajectory(None, fault=True, miss_by=2.345))
    write(os.path.join(tdir, "current_0.csv"), trajectory(30.2))
    # ---- The PID baseline: everything reached; its current trajectory is missing. ----
    pid = [SUMMARY_HEADER,
           summary_row("test1", "pid", 0, GOAL, 1, 8.3, 0.029, 5e-05, 46.8, "reached"),
           summary_row("test2", "pid", 0, GOAL, 1, 11.6, 0.023, 3e-05, 48.6, "reached"),
           summary_row("fault", "pid", 0, GOAL, 1, 11.1, 0.035, 2e-05, 59.8, "reached"),
           summary_row("current", "pid", 0, GOAL, 1, 8.5, 0.027, 3e-05, 56.7, "reached")]
    for ep, g in enumerate(suite_goals):
        pid.append(summary_row("suite", "pid", ep, g, 1, 8.0 + ep, 0.04, 0.0004, 50 + ep,
                               "reached"))
    write(os.path.join(run, "eval/pid/summary.csv"), "\n".join(pid) + "\n")
    tdir = os.path.join(run, "eval/pid/trajectories")
    write(os.path.join(tdir, "test1_0.csv"), trajectory(8.3))
    write(os.path.join(tdir, "test2_0.csv"), trajectory(11.6, facing_away=True))
    write(os.path.join(tdir, "fault_0.csv"), trajectory(11.1, fault=True))
    write(os.path.join(tdir, "suite_0.csv"), trajectory(8.0))

    # ---- Training: 300 episodes (one damaged line among them), learner stats at 1 Hz. ----
    ep_lines = ["wall_s,actor_id,episode_id,policy_version,return,length_steps,success,"
                "final_distance_m,min_distance_m,beta_m,end_reason,thrust_energy"]
    for i in range(300):
        success = int((i * 7) % 10 < i / 30)
        final = 10 * math.exp(-i / 100) + 0.05
        beta = 1.5 - i / 300
        ep_lines.append(f"{2.0 * i:.3f},{i % 4},{i // 4 + 1},{i // 10},{-700 + 3 * i + (i % 7)},"
                        f"700,{success},{final:.4f},{0.8 * final:.4f},{beta:.4f},"
                        f"{0 if success else 1},{100 + i % 13}")
        if i == 54:
            ep_lines.append("110.0,1,14,5,not-a-number,700,0,3.0,2.0,1.3,1,100")  # line 57
    write(os.path.join(run, "episodes.csv"), "\n".join(ep_lines) + "\n")
    le = ["wall_s,updates,updates_per_s,transitions_received,transitions_per_s,buffer_size,"
          "critic_loss,actor_loss,mean_q,episodes,beta_m,weights_published"]
    for s in range(1, 601):
        le.append(f"{s:.3f},{50 * s},50.0,{350 * s},350.0,{min(350 * s, 100000)},"
                  f"{1.0 / s:.6f},{-0.01 * s:.6f},{0.01 * s:.6f},{s // 2},{1.5 - s / 600:.4f},"
                  f"{s // 5}")
    write(os.path.join(run, "learner.csv"), "\n".join(le) + "\n")
    # progress.csv is left out on purpose.
    # ---- Fine-tuning: 20 iterations, validation every 10. ----
    ft = ["iteration,objective_s,elapsed_s,validation_reached,validation_mean_time_s,"
          "validation_hold_m,validation_worst_time_ratio"]
    for i in range(1, 21):
        tail = f",{60 - (i == 10)},{9.5 - i / 100:.2f},0.08,1.1" if i % 10 == 0 else ",,,,"
        ft.append(f"{i},{10.0 - i / 20:.3f},{0.3 * i:.1f}" + tail)
    write(os.path.join(run, "finetune.csv"), "\n".join(ft) + "\n")
    # ---- The robustness suite: two groups per controller and auvrl's comparison table. ----
    rb = ("group,controller,episodes,reached,held,flips,blow_ups,left_region,"
          "mean_time_to_reach_s,mean_hold_error_m,mean_thrust_energy,mean_smoothness,"
          "description\n")
    write(os.path.join(run, "eval/policy/robustness.csv"), rb +
          "rest_start,policy,20,20,20,0,0,0,8.7,0.105,123.3,0.262,at rest\n"
          "t1_0pct,policy,20,0,0,2,0,0,,,226.3,0.075,T1 dead\n")
    write(os.path.join(run, "eval/pid/robustness.csv"), rb +
          "rest_start,pid,20,20,20,0,0,0,11.9,0.047,58.2,0.008,at rest\n"
          "t1_0pct,pid,20,20,20,0,0,0,12.2,0.046,58.3,0.008,T1 dead\n")
    write(os.path.join(run, "eval/robustness_comparison.md"),
          "| group | held (policy vs PID) |\n|---|---|\n| rest_start | 20/20 vs 20/20 pass |\n")


class PlotRunTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="auvrl_plot_run_")
        cls.rundir = os.path.join(cls.tmp.name, "run")
        fabricate(cls.rundir)
        cls.proc = subprocess.run([PYTHON, SCRIPT, cls.rundir], capture_output=True, text=True,
                                  timeout=300)
        report = os.path.join(cls.rundir, "report.md")
        cls.report = ""
        if os.path.isfile(report):
            with open(report) as f:
                cls.report = f.read()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_exit_status(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stderr)

    def test_figures_written(self):
        expected = [f"eval_{s}_{k}.png" for s in ("test1", "test2", "fault", "current")
                    for k in ("3d", "position", "thrusters")]
        expected += ["eval_distance.png", "suite_overview.png", "suite_3d.png", "robustness.png",
                     "training_vs_episodes.png", "training_vs_time.png"]
        for name in expected:
            path = os.path.join(self.rundir, "plots", name)
            self.assertTrue(os.path.isfile(path), name)
            with open(path, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", name)
            self.assertGreater(os.path.getsize(path), 10000, name)

    def test_report_links_resolve(self):
        links = re.findall(r"\]\((plots/[^)]+\.png)\)", self.report)
        self.assertGreaterEqual(len(links), 17)
        for link in links:
            self.assertTrue(os.path.isfile(os.path.join(self.rundir, link)), link)

    def test_robustness_section(self):
        self.assertIn("### Robustness\n", self.report)
        self.assertIn("| rest_start | 20/20 vs 20/20 pass |", self.report)
        self.assertIn("![robustness](plots/robustness.png)", self.report)

    def test_scenario_table(self):
        for row in (
                "| test1 | learned policy | 1/1 | 21.4 s | 0.041 m | 0.012 m | 123.4 | reached |",
                "| test2 | learned policy | 1/1 | 16.9 s | 0.052 m | 0.020 m | 140.2 | reached |",
                "| fault | learned policy | 0/1 | - | - | 2.345 m | 300.5 | time_limit |",
                "| current | learned policy | 1/1 | 30.2 s | 0.110 m | 0.090 m | 88.8 | reached |",
                "| test1 | PID baseline | 1/1 | 8.3 s | 0.029 m | 5.0e-05 m | 46.8 | reached |",
                "| fault | PID baseline | 1/1 | 11.1 s | 0.035 m | 2.0e-05 m | 59.8 | reached |"):
            self.assertIn(row, self.report)

    def test_paper_comparison(self):
        self.assertIn("| test1 | Fig. 3, 4 | ~25 s (Fig. 4) | 21.4 s | 8.3 s |", self.report)
        self.assertIn("| test2 | Fig. 5, 6 | ~17 s (Fig. 5) | 16.9 s | 11.6 s |", self.report)
        self.assertIn("| fault | Fig. 7, 8 | ~30 s (Fig. 8) | not reached | 11.1 s |",
                      self.report)

    def test_suite_table(self):
        # Policy: 4 of the 6 readable rows reached in 10, 12, 14, 20 s (the two damaged rows
        # are skipped); PID: 6 of 6 in 8..13 s.
        self.assertIn("| learned policy | 4/6 (67 %) | 14.0 s | 13.0 s | 10.0-20.0 s |",
                      self.report)
        self.assertIn("| PID baseline | 6/6 (100 %) | 10.5 s | 10.5 s | 8.0-13.0 s |",
                      self.report)
        self.assertIn("left_region 2, reached 4", self.report)

    def test_training_summary(self):
        self.assertIn("| episodes (episodes.csv) | 300 |", self.report)
        self.assertIn("| actors | 4 |", self.report)
        self.assertIn("| learner updates | 30000 (mean 50 updates/s while updating) |",
                      self.report)
        self.assertIn("| transitions received / replay buffer | 210000 / 100000 |",
                      self.report)
        self.assertIn("| wall-clock time | 10.0 min (600 s) |", self.report)

    def test_finetuning_summary(self):
        self.assertIn("## Fine-tuning", self.report)
        self.assertIn("20 iterations of evolution strategies in 6 s", self.report)
        self.assertIn("9.950 s after the first iteration, 9.000 s after the last", self.report)
        self.assertIn("| 10 | 9.500 s | 59 | 9.40 s | 0.080 m | 1.10 |", self.report)
        self.assertIn("| 20 | 9.000 s | 60 | 9.30 s | 0.080 m | 1.10 |", self.report)

    def test_damage_reported_with_file_and_line(self):
        self.assertIn("eval/policy/summary.csv:12: 5 fields, expected 12; row skipped",
                      self.report)
        self.assertIn("eval/policy/summary.csv:13: column goal_y: cannot read 'x'",
                      self.report)
        self.assertIn("episodes.csv:57: column return: cannot read 'not-a-number'",
                      self.report)
        self.assertIn("eval/policy/trajectories/test2_0.csv:103: column t: cannot read 'oops'",
                      self.report)
        self.assertIn("episodes.csv:57", self.proc.stderr)

    def test_missing_inputs_named(self):
        self.assertIn("- missing: `progress.csv`", self.report)
        self.assertIn("- missing: `eval/pid/trajectories/current_0.csv`", self.report)

    def test_empty_run_directory(self):
        empty = os.path.join(self.tmp.name, "empty")
        os.makedirs(empty)
        proc = subprocess.run([PYTHON, SCRIPT, empty], capture_output=True, text=True,
                              timeout=120)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(os.path.join(empty, "report.md")) as f:
            report = f.read()
        self.assertIn("No evaluation in this run", report)
        self.assertIn("No training logs in this run", report)
        self.assertEqual(os.listdir(os.path.join(empty, "plots")), [])

    def test_garbage_inputs(self):
        """Binary junk, headers only, non-finite numbers, a missing column: still exit 0."""
        junk = os.path.join(self.tmp.name, "junk")
        header = trajectory(5.0).splitlines()[0]
        write(os.path.join(junk, "eval/policy/summary.csv"), SUMMARY_HEADER + "\n")
        write(os.path.join(junk, "eval/policy/trajectories/test1_0.csv"), header + "\n")
        rows = trajectory(5.0).splitlines()[:40]
        rows.append("4.0,nan,inf,-inf" + ",0" * (len(header.split(",")) - 4))
        write(os.path.join(junk, "eval/policy/trajectories/test2_0.csv"), "\n".join(rows))
        with open(os.path.join(junk, "eval/policy/trajectories/fault_0.csv"), "wb") as f:
            f.write(bytes(range(256)) * 20)
        os.makedirs(os.path.join(junk, "eval/pid"))
        with open(os.path.join(junk, "eval/pid/summary.csv"), "wb") as f:
            f.write(bytes(range(255, -1, -1)) * 20)
        write(os.path.join(junk, "episodes.csv"), "wall_s,return\n1.0,-5\n")
        write(os.path.join(junk, "learner.csv"), "wall_s,updates\n1,5\n2,nan\n")
        write(os.path.join(junk, "progress.csv"), "")
        proc = subprocess.run([PYTHON, SCRIPT, junk], capture_output=True, text=True,
                              timeout=120)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertNotIn("Traceback", proc.stderr)
        with open(os.path.join(junk, "report.md")) as f:
            report = f.read()
        self.assertIn("eval/pid/summary.csv: header lacks column(s)", report)
        self.assertIn("eval/policy/trajectories/fault_0.csv: header lacks column(s) t, x, y, z",
                      report)
        self.assertIn("progress.csv: empty file", report)
        self.assertTrue(os.path.isfile(os.path.join(junk, "plots", "eval_test2_position.png")))

    def test_not_a_directory(self):
        missing = os.path.join(self.tmp.name, "no_such_run")
        proc = subprocess.run([PYTHON, SCRIPT, missing], capture_output=True, text=True,
                              timeout=120)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("not a directory", proc.stderr)


if __name__ == "__main__":
    try:
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        print(f"skipped: {e} (apt-get install python3-matplotlib python3-numpy)")
        sys.exit(77)
    unittest.main(verbosity=2)
