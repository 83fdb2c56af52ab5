#!/usr/bin/python3
"""Plots and report of an auvrl run directory.

Usage: /usr/bin/python3 scripts/plot_run.py RUN

RUN is what `auvrl train` writes (or any directory holding part of it):
  RUN/eval/<controller>/summary.csv and trajectories/<scenario>_<episode>.csv   (auvrl eval)
  RUN/eval/{policy,pid}/robustness.csv, RUN/eval/robustness_comparison.md   (robustness suite)
  RUN/episodes.csv, RUN/learner.csv, RUN/progress.csv                            (training)
An `auvrl eval --out DIR` directory (summary.csv directly inside) is taken as one controller;
one of `auvrl eval --scenario robustness --with-pid` (robustness.csv, pid/robustness.csv and
robustness_comparison.md) gives the robustness section.

Writes RUN/plots/*.png (the paper's Fig. 3-8 for test1, test2 and fault, the same for the
current scenario, a suite overview, the robustness suite against the PID
(scripts/plot_robustness.py), learning curves against episodes and wall-clock time) and
RUN/report.md (tables and the figures). Missing inputs are named in the report and skipped;
malformed rows are reported with file and line and skipped. Exit 0 on success, 2 when RUN is
not a directory, 1 when the outputs cannot be written.

Only Debian's python3 with python3-matplotlib and python3-numpy (apt) is needed.
"""
import csv
import datetime
import math
import os
import sys
import textwrap
import traceback

import matplotlib

matplotlib.use("Agg")
import matplotlib.lines  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REACH_M = 0.5  # "reached": within 0.5 m (auvrl eval's definition)
PAPER_SCENARIOS = ("test1", "test2", "fault", "current")  # one episode each, plotted in full
SUITE = "suite"
# Time to reach of the paper's learned policy (Carlucho et al. 2018, Sec. V, on its own plant).
PAPER_TIME_S = {"test1": "~25 s (Fig. 4)", "test2": "~17 s (Fig. 5)", "fault": "~30 s (Fig. 8)"}
PAPER_FIG = {"test1": "Fig. 3, 4", "test2": "Fig. 5, 6", "fault": "Fig. 7, 8", "current": "-"}
SCENARIO_TEXT = {
    "test1": "test 1: start [0, 0, 5] facing north, way-point [7, 6, 10]",
    "test2": "test 2: start [0, 0, 5] facing away from the way-point [7, 6, 10]",
    "fault": "fault: test 1 with thruster T1 at 10 % efficiency (90 % thrust loss)",
    "current": "current: test 1 in a 0.3 m/s horizontal current across the start-goal line",
}
CONTROLLER_LABEL = {"policy": "learned policy", "pid": "PID baseline"}
CONTROLLER_COLOR = {"policy": "tab:blue", "pid": "tab:orange"}
EXTRA_COLORS = ["tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"]
# episode_report_t's end_reason codes (episodes.csv writes the number).
END_REASONS = ["reached", "time_limit", "left_region", "flipped", "blow_up", "sim_timeout"]
DPI = 100
MAX_SCATTER = 20000  # per-episode points drawn at most (every k-th beyond)
DIST_FLOOR = 1e-5  # distances below are drawn at this value on log axes

# Plot files this script writes; stale ones (from an earlier call with more inputs) are removed.
OWN_PLOTS = [f"eval_{s}_{k}.png" for s in PAPER_SCENARIOS for k in ("3d", "position",
                                                                         "thrusters")]
OWN_PLOTS += ["eval_distance.png", "suite_overview.png", "suite_3d.png", "robustness.png",
              "training_vs_episodes.png", "training_vs_time.png"]


class Notes:
    """What was missing or damaged: printed to stderr and listed in the report."""

    def __init__(self):
        self.missing = []
        self.damaged = []

    def miss(self, text):
        self.missing.append(text)
        print(f"plot_run: missing: {text}", file=sys.stderr)

    def damage(self, text):
        self.damaged.append(text)
        print(f"plot_run: {text}", file=sys.stderr)


NOTES = Notes()


# ---------------------------------------------------------------------------------------------
# Reading CSVs
# ---------------------------------------------------------------------------------------------
def parse_float(s):
    return float(s)


def parse_float_or_empty(s):
    return math.nan if s.strip() == "" else float(s)


def number(text):
    """A float from a CSV cell; NaN for an empty or unreadable one."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def parse_bool(s):
    v = s.strip().lower()
    if v in ("1", "true", "yes"):
        return True
    if v in ("0", "false", "no"):
        return False
    raise ValueError(f"not a boolean: {s!r}")


def parse_end_reason(s):
    v = s.strip()
    if v.lstrip("-").isdigit():
        i = int(v)
        return END_REASONS[i] if 0 <= i < len(END_REASONS) else f"code {i}"
    if not v:
        raise ValueError("empty end_reason")
    return v


def parse_str(s):
    if s.strip() == "":
        raise ValueError("empty")
    return s.strip()


def short(text, n=24):
    """A cell or column name for a message: printable ASCII, at most n characters."""
    text = ascii(str(text))[1:-1]
    return text if len(text) <= n else text[:n] + "..."


MAX_ROW_NOTES = 5  # damaged rows listed per file; the rest are counted


def read_csv(path, spec, label=None, required=()):
    """Rows of a CSV as dicts, parsed per spec {column: parser}; None when the file is missing
    or unusable. Columns not in spec are parsed as floats. Columns of spec absent from the
    header are reported and given NaN/None; when a column of `required` is absent the file is
    skipped. Rows with a wrong field count or an unparsable cell are reported and skipped."""
    label = label or path
    if not os.path.isfile(path):
        return None
    rows = []
    bad = 0

    def damaged(text):
        nonlocal bad
        bad += 1
        if bad <= MAX_ROW_NOTES:
            NOTES.damage(text)

    try:
        with open(path, newline="", encoding="utf-8", errors="replace") as f:
            reader = csv.reader(f)
            header = None
            for fields in reader:
                if not fields or all(not x.strip() for x in fields):
                    continue
                if header is None:
                    header = [h.strip() for h in fields]
                    absent = [c for c in spec if c not in header]
                    if any(c in absent for c in required) or (spec and not set(header) & set(spec)):
                        NOTES.damage(f"{label}: header lacks column(s) "
                                     f"{', '.join(c for c in absent)}; file skipped")
                        return None
                    if absent:
                        NOTES.damage(f"{label}: header lacks column(s) {', '.join(absent)}")
                    parsers = [spec.get(h, parse_float) for h in header]
                    continue
                line = reader.line_num
                if len(fields) != len(header):
                    damaged(f"{label}:{line}: {len(fields)} fields, expected {len(header)}; "
                            "row skipped")
                    continue
                row = {}
                try:
                    for name, parse, cell in zip(header, parsers, fields):
                        try:
                            row[name] = parse(cell)
                        except ValueError:
                            raise ValueError(f"column {short(name)}: cannot read "
                                             f"'{short(cell.strip())}'")
                except ValueError as e:
                    damaged(f"{label}:{line}: {e}; row skipped")
                    continue
                for c in absent:
                    row[c] = None if spec[c] in (parse_str, parse_end_reason) else math.nan
                rows.append(row)
    except (OSError, csv.Error) as e:
        NOTES.damage(f"{label}: cannot read ({e}); what was read is used")
    if bad > MAX_ROW_NOTES:
        NOTES.damage(f"{label}: {bad - MAX_ROW_NOTES} more damaged rows skipped "
                     f"({bad} in all, {len(rows)} rows read)")
    if header is None:
        NOTES.damage(f"{label}: empty file")
        return None
    return rows


def columns(rows, names):
    """{name: numpy array} of numeric columns of parsed rows."""
    return {n: np.array([r.get(n, math.nan) for r in rows], dtype=float) for n in names}


SUMMARY_SPEC = {
    "scenario": parse_str, "controller": parse_str, "episode": parse_float,
    "goal_x": parse_float, "goal_y": parse_float, "goal_z": parse_float, "reached": parse_bool,
    "time_to_reach_s": parse_float_or_empty, "mean_error_after_reach_m": parse_float_or_empty,
    "final_error_m": parse_float, "thrust_energy": parse_float, "end_reason": parse_end_reason,
}
TRAJ_REQUIRED = ("t", "x", "y", "z")
EPISODES_SPEC = {
    "wall_s": parse_float, "actor_id": parse_float, "episode_id": parse_float,
    "policy_version": parse_float, "return": parse_float, "length_steps": parse_float,
    "success": parse_bool, "final_distance_m": parse_float, "min_distance_m": parse_float,
    "beta_m": parse_float, "end_reason": parse_end_reason, "thrust_energy": parse_float,
}
LEARNER_SPEC = {c: parse_float for c in (
    "wall_s", "updates", "updates_per_s", "transitions_received", "transitions_per_s",
    "buffer_size", "critic_loss", "actor_loss", "mean_q", "episodes", "beta_m",
    "weights_published")}
PROGRESS_SPEC = {c: parse_float for c in (
    "wall_s", "episodes", "success_rate", "beta_m", "env_steps_per_s", "updates_per_s",
    "best_suite_success")}


# ---------------------------------------------------------------------------------------------
# The evaluation: controllers, their summaries and trajectories
# ---------------------------------------------------------------------------------------------
def read_vehicle(directory):
    """(vehicle name, [thruster names]) from the evaluation's vehicle.csv, or (None, [])."""
    path = os.path.join(directory, "vehicle.csv")
    try:
        with open(path, encoding="utf-8", errors="replace", newline="") as f:
            rows = list(csv.DictReader(f))
        return (rows[0]["vehicle"] if rows else None), [r["name"] for r in rows]
    except (OSError, KeyError, csv.Error):
        return None, []


class Controller:
    def __init__(self, name, directory, run):
        self.dir = directory
        self.run = run
        rel = os.path.relpath(os.path.join(directory, "summary.csv"), run)
        self.summary = read_csv(os.path.join(directory, "summary.csv"), SUMMARY_SPEC, rel,
                                required=("scenario",))
        if name is None:  # an `auvrl eval --out` directory: named by its summary
            names = sorted({r["controller"] for r in self.summary or [] if r["controller"]})
            name = names[0] if names else os.path.basename(os.path.abspath(directory))
        self.name = name
        self.label = CONTROLLER_LABEL.get(name, name)
        self.color = CONTROLLER_COLOR.get(name)
        if self.summary is None:
            if not os.path.isfile(os.path.join(directory, "summary.csv")):
                NOTES.miss(f"{rel} (no summary table for {self.label})")
            self.summary = []
        self._traj = {}
        self.vehicle, self.thruster_names = read_vehicle(directory)

    def rows(self, scenario):
        return [r for r in self.summary if r["scenario"] == scenario]

    def row(self, scenario, episode):
        for r in self.rows(scenario):
            if r["episode"] == episode:
                return r
        return None

    def trajectory(self, scenario, episode):
        """{column: array} of trajectories/<scenario>_<episode>.csv, or None."""
        key = (scenario, episode)
        if key not in self._traj:
            path = os.path.join(self.dir, "trajectories", f"{scenario}_{episode}.csv")
            rel = os.path.relpath(path, self.run)
            rows = read_csv(path, {c: parse_float for c in TRAJ_REQUIRED}, rel,
                            required=TRAJ_REQUIRED)
            data = None
            if rows:
                names = list(rows[0].keys())
                if all(c in names for c in TRAJ_REQUIRED):
                    data = columns(rows, names)
                    order = np.argsort(data["t"], kind="stable")
                    data = {k: v[order] for k, v in data.items()}
                    if "distance_m" not in data:
                        data["distance_m"] = np.full_like(data["t"], math.nan)
                else:
                    NOTES.damage(f"{rel}: lacks columns t, x, y, z; skipped")
            elif rows is not None:
                NOTES.damage(f"{rel}: no readable rows")
            self._traj[key] = data
        return self._traj[key]

    def trajectory_episodes(self, scenario):
        d = os.path.join(self.dir, "trajectories")
        out = []
        if os.path.isdir(d):
            for f in os.listdir(d):
                stem, ext = os.path.splitext(f)
                sc, _, ep = stem.rpartition("_")
                if ext == ".csv" and sc == scenario and ep.isdigit():
                    out.append(int(ep))
        return sorted(out)


def find_controllers(run):
    ctrls = []
    eval_dir = os.path.join(run, "eval")
    if os.path.isfile(os.path.join(run, "summary.csv")):
        # RUN is itself an `auvrl eval --out` directory.
        c = Controller(None, run, run)
        c.color = c.color or EXTRA_COLORS[0]
        return [c]
    if not os.path.isdir(eval_dir):
        NOTES.miss("eval/ (no evaluation: the run stopped before it, or was not evaluated)")
        return ctrls
    names = [n for n in sorted(os.listdir(eval_dir))
             if os.path.isdir(os.path.join(eval_dir, n))]
    for expected in ("policy", "pid"):
        if expected not in names:
            NOTES.miss(f"eval/{expected}/ (no {CONTROLLER_LABEL[expected]} evaluation)")
    names.sort(key=lambda n: ({"policy": 0, "pid": 1}.get(n, 2), n))
    for n in names:
        ctrls.append(Controller(n, os.path.join(eval_dir, n), run))
    extra = iter(EXTRA_COLORS)
    for c in ctrls:
        if c.color is None:
            c.color = next(extra, "tab:gray")
    return ctrls


def robustness_paths(run):
    """[policy robustness.csv, PID robustness.csv, comparison .md] of a run (RUN/eval/...), or
    of an `auvrl eval --scenario robustness --with-pid` directory when the run has none."""
    layouts = [[os.path.join(run, "eval", "policy", "robustness.csv"),
                os.path.join(run, "eval", "pid", "robustness.csv"),
                os.path.join(run, "eval", "robustness_comparison.md")],
               [os.path.join(run, "robustness.csv"), os.path.join(run, "pid", "robustness.csv"),
                os.path.join(run, "robustness_comparison.md")]]
    for paths in layouts:
        if any(os.path.isfile(p) for p in paths):
            return paths
    return layouts[0]


def robustness_inputs(run):
    """robustness_paths(run), None for each file that is not there."""
    return tuple(p if os.path.isfile(p) else None for p in robustness_paths(run))


def plot_robustness_figure(run, plots_dir, written):
    """plots/robustness.png from the two robustness.csv files (scripts/plot_robustness.py)."""
    import plot_robustness  # beside this script
    policy_csv, pid_csv, _ = robustness_inputs(run)
    if not policy_csv or not pid_csv:
        return
    policy, pid = plot_robustness.read_groups(policy_csv), plot_robustness.read_groups(pid_csv)
    if not policy or not pid:
        NOTES.damage(f"{os.path.relpath(policy_csv if not policy else pid_csv, run)}: no "
                     "readable rows; robustness figure skipped")
        return
    plot_robustness.draw(policy, pid, os.path.join(plots_dir, "robustness.png"))
    written.append("robustness.png")


def reach_time(ctrl, scenario, episode, traj):
    """(time to reach in s or NaN, source): the summary's value, else from the trajectory."""
    row = ctrl.row(scenario, episode)
    if row is not None:
        return row["time_to_reach_s"], "summary"
    if traj is not None:
        inside = np.nonzero(traj["distance_m"] <= REACH_M)[0]
        if inside.size:
            return float(traj["t"][inside[0]]), "trajectory"
    return math.nan, "none"


def goal_of(ctrl, scenario, episode):
    row = ctrl.row(scenario, episode)
    if row is None:
        return None
    return np.array([row["goal_x"], row["goal_y"], row["goal_z"]])


# ---------------------------------------------------------------------------------------------
# Formatting
# ---------------------------------------------------------------------------------------------
def fmt(v, digits=1, unit=""):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:.{digits}f}{unit}"


def fmt_err(v):
    """Distances in m: 3 decimals, small ones in scientific notation (not a bare 0.000)."""
    if v is None or not math.isfinite(v):
        return "-"
    if v != 0 and abs(v) < 0.001:
        return f"{v:.1e} m"
    return f"{v:.3f} m"


def fmt_duration(s):
    if not math.isfinite(s):
        return "-"
    if s < 120:
        return f"{s:.0f} s"
    if s < 7200:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.2f} h"


def finite(a):
    a = np.asarray(a, dtype=float)
    return a[np.isfinite(a)]


def no_data(ax, text):
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, color="gray",
            fontsize=9, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])


def save(fig, plots_dir, name, written):
    path = os.path.join(plots_dir, name)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    written.append(name)
    return name


# ---------------------------------------------------------------------------------------------
# Evaluation figures
# ---------------------------------------------------------------------------------------------
def box_floor(pts):
    """(deepest z of the box set_3d_limits draws, its largest span)."""
    pts = np.asarray(pts, dtype=float)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if pts.size == 0:
        return None, 1.0
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 1.0)
    return hi[2] + 0.08 * span[2], float(span.max())


def set_3d_limits(ax, pts):
    """Equal scale on the three axes around the points (east, north, depth); returns the
    deepest z of the box (None without finite points). plot_mission.py uses it too."""
    pts = np.asarray(pts, dtype=float)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if pts.size == 0:
        return None
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 1.0)
    pad = 0.08 * span
    lo, hi = lo - pad, hi + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(hi[2], lo[2])  # depth increases downwards
    box = np.maximum(hi - lo, 0.25 * (hi - lo).max())
    ax.set_box_aspect(tuple(box))
    return hi[2]


def draw_3d(ax, traj, goal, color, label, reach_t, floor_z=None, arrow_m=0.8):
    """One path in a 3-D axes: matplotlib's x = east (y), y = north (x), z = depth, inverted so
    that depth points down (a right-handed east-north-up view of the NED path)."""
    e, n, d = traj["y"], traj["x"], traj["z"]
    ax.plot(e, n, d, color=color, lw=1.6, label=f"{label} path")
    if floor_z is not None:  # the horizontal track on the floor of the box
        ax.plot(e, n, np.full_like(d, floor_z), color="0.45", lw=0.9, ls=":",
                label="horizontal track (on the floor)")
    if "psi" in traj and len(e) > 1:
        # Heading on the way: up to the reach time (the whole episode if never reached), at
        # most ~12 arrows, skipping places where the vehicle has hardly moved.
        t = traj["t"]
        t_end = reach_t if math.isfinite(reach_t) else t[-1]
        every = max(2.0, (t_end - t[0]) / 12.0)
        idx, last = [], None
        for i in range(len(e)):
            if t[i] > t_end + 1e-6:
                break
            p = np.array([e[i], n[i], d[i]])
            if not np.all(np.isfinite(p)) or not math.isfinite(traj["psi"][i]):
                continue
            if last is None or (t[i] - t[last] >= every - 1e-6 and
                                np.linalg.norm(p - [e[last], n[last], d[last]]) > 0.4 * arrow_m):
                idx.append(i)
                last = i
        if idx:
            psi = traj["psi"][idx]
            ax.quiver(e[idx], n[idx], d[idx], np.sin(psi), np.cos(psi), np.zeros_like(psi),
                      length=arrow_m, color="black", lw=0.9, arrow_length_ratio=0.35,
                      label=f"heading (every {every:.0f} s" +
                      (" until reached)" if math.isfinite(reach_t) else ")"))
    ax.scatter([e[0]], [n[0]], [d[0]], color="tab:green", marker="o", s=45, label="start",
               depthshade=False)
    ax.scatter([e[-1]], [n[-1]], [d[-1]], color=color, marker="s", s=25, label="end (70 s)",
               depthshade=False)
    if goal is not None:
        ax.scatter([goal[1]], [goal[0]], [goal[2]], color="tab:red", marker="*", s=160,
                   label="way-point", depthshade=False)
    if math.isfinite(reach_t):
        i = int(np.searchsorted(traj["t"], reach_t - 1e-9))
        i = min(i, len(e) - 1)
        ax.scatter([e[i]], [n[i]], [d[i]], color="black", marker="x", s=50,
                   label=f"within {REACH_M} m ({reach_t:.1f} s)", depthshade=False)
    ax.set_xlabel("east y [m]", labelpad=2)
    ax.set_ylabel("north x [m]", labelpad=2)
    ax.set_zlabel("depth z [m] (down)", labelpad=2)
    ax.tick_params(labelsize=7, pad=0)


def scenario_panels(ctrls, scenario):
    """[(controller, episode, trajectory, goal, reach_t, reach_source)] with a trajectory."""
    out = []
    for c in ctrls:
        eps = c.trajectory_episodes(scenario)
        ep = 0 if 0 in eps else (eps[0] if eps else None)
        if ep is None:
            continue
        traj = c.trajectory(scenario, ep)
        if traj is None:
            continue
        t_reach, src = reach_time(c, scenario, ep, traj)
        out.append((c, ep, traj, goal_of(c, scenario, ep), t_reach, src))
    return out


def reach_text(t_reach, src):
    if not math.isfinite(t_reach):
        return f"never within {REACH_M} m"
    extra = " (from the trajectory)" if src == "trajectory" else ""
    return f"within {REACH_M} m at {t_reach:.1f} s{extra}"


def plot_scenario(ctrls, scenario, plots_dir, written):
    panels = scenario_panels(ctrls, scenario)
    if not panels:
        return []
    ncol = len(panels)
    names = []
    title = SCENARIO_TEXT.get(scenario, scenario)
    sep = ": " if ncol > 1 else "\n"  # one column: the title on two lines
    extra = 0.0 if ncol > 1 else 0.22  # inches for the second title line

    # --- 3-D trajectory (paper Fig. 3, 6, 7). ---
    fig = plt.figure(figsize=(max(7.5, 6.2 * ncol), 6.0 + extra))
    pts = []
    for c, ep, traj, goal, t_reach, src in panels:
        pts += list(np.column_stack([traj["y"], traj["x"], traj["z"]]))
        if goal is not None:
            pts.append(np.array([goal[1], goal[0], goal[2]]))
    zmax, span = box_floor(pts)
    for k, (c, ep, traj, goal, t_reach, src) in enumerate(panels):
        ax = fig.add_subplot(1, ncol, k + 1, projection="3d")
        draw_3d(ax, traj, goal, c.color, c.label, t_reach, floor_z=zmax, arrow_m=0.09 * span)
        set_3d_limits(ax, pts)
        ax.view_init(elev=22, azim=-60)
        ax.set_title(f"{c.label}\n{reach_text(t_reach, src)}", fontsize=10)
        ax.legend(loc="upper left", fontsize=7, framealpha=0.8)
    fig.suptitle(f"{title}{sep}3-D path (NED, depth down)", fontsize=11)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.03,
                        top=1 - (0.84 + extra) / fig.get_figheight(), wspace=0.08)
    names.append(save(fig, plots_dir, f"eval_{scenario}_3d.png", written))

    # --- Position against time (paper Fig. 4a, 5a, 8a) and distance to the way-point. ---
    fig, axes = plt.subplots(2, ncol, figsize=(max(7.5, 6.0 * ncol), 6.6 + extra),
                             squeeze=False,
                             sharex=True, sharey="row", gridspec_kw={"height_ratios": [3, 2]})
    axis_colors = {"x": "tab:blue", "y": "tab:green", "z": "tab:red"}
    axis_names = {"x": "x (north)", "y": "y (east)", "z": "z (depth, down +)"}
    for k, (c, ep, traj, goal, t_reach, src) in enumerate(panels):
        ax = axes[0][k]
        for i, a in enumerate("xyz"):
            ax.plot(traj["t"], traj[a], color=axis_colors[a], lw=1.5, label=axis_names[a])
            if goal is not None:
                ax.axhline(goal[i], color=axis_colors[a], ls="--", lw=1.0,
                           label=f"way-point {a} = {goal[i]:g} m")
        if math.isfinite(t_reach):
            ax.axvline(t_reach, color="black", ls=":", lw=1.2,
                       label=f"within {REACH_M} m: {t_reach:.1f} s")
        ax.set_title(f"{c.label}: {reach_text(t_reach, src)}", fontsize=10)
        ax.grid(True, alpha=0.4)
        ax.legend(loc="lower right", fontsize=7, ncol=2, framealpha=0.85)
        if k == 0:
            ax.set_ylabel("position [m]")
        ax = axes[1][k]
        dist = np.clip(traj["distance_m"], DIST_FLOOR, None)
        ax.semilogy(traj["t"], dist, color=c.color, lw=1.5, label="distance to way-point")
        ax.axhline(REACH_M, color="gray", ls="--", lw=1.0, label=f"{REACH_M} m")
        if math.isfinite(t_reach):
            ax.axvline(t_reach, color="black", ls=":", lw=1.2)
        ax.grid(True, alpha=0.4)
        ax.legend(loc="upper right", fontsize=7)
        ax.set_xlabel("t [s]")
        if k == 0:
            ax.set_ylabel("distance [m] (log)")
    fig.suptitle(f"{title}{sep}position against time", fontsize=11)
    fig.subplots_adjust(left=0.07 if ncol > 1 else 0.1, right=0.98, bottom=0.08,
                        top=1 - (0.66 + extra) / fig.get_figheight(), hspace=0.12, wspace=0.05)
    names.append(save(fig, plots_dir, f"eval_{scenario}_position.png", written))

    # --- The six thrusters (paper Fig. 4b, 5b, 8b): realised thrust, command faint. ---
    nthr = max(sum(1 for k in traj if k.startswith("thrust_")) for _, _, traj, *_ in panels)
    if nthr == 0:
        NOTES.damage(f"{scenario}: trajectories have no thrust_i columns; no thruster plot")
        return names
    # The thrusters' names from the evaluation's vehicle.csv (T1, T2, ... without it).
    thruster_names = panels[0][0].thruster_names
    fig, axes = plt.subplots(nthr, ncol, figsize=(max(8.0, 6.0 * ncol),
                                                  1.35 * nthr + 1.2 + extra),
                             squeeze=False, sharex=True, sharey=True)
    for k, (c, ep, traj, goal, t_reach, src) in enumerate(panels):
        for i in range(nthr):
            ax = axes[i][k]
            real, cmd = traj.get(f"thrust_{i + 1}"), traj.get(f"cmd_{i + 1}")
            if cmd is not None:
                ax.plot(traj["t"], cmd, color="gray", lw=0.9, ls="--", alpha=0.8,
                        label="commanded")
            if real is not None:
                ax.plot(traj["t"], real, color=c.color, lw=1.4, label="realised")
            if math.isfinite(t_reach):
                ax.axvline(t_reach, color="black", ls=":", lw=1.0)
            ax.grid(True, alpha=0.4)
            ax.axhline(0, color="black", lw=0.5)
            named = len(thruster_names) == nthr
            label = textwrap.fill(thruster_names[i].replace("_", " "), 12) if named \
                else f"T{i + 1}"
            if k == 0:
                ax.set_ylabel(f"{label}\n[N]", fontsize=7 if named else 8)
            if real is not None and cmd is not None:
                pc, pr = np.nanmax(np.abs(cmd)), np.nanmax(np.abs(real))
                if pc > 1.0 and pr < 0.5 * pc:
                    ax.text(0.99, 0.06, f"realised peak {pr:.1f} N = {100 * pr / pc:.0f} % of "
                            f"commanded peak {pc:.1f} N", transform=ax.transAxes, ha="right",
                            va="bottom", fontsize=7.5, color="darkred",
                            bbox=dict(fc="white", ec="none", alpha=0.8))
            ax.tick_params(labelsize=7)
        axes[0][k].set_title(f"{c.label}: {reach_text(t_reach, src)}", fontsize=10)
        axes[-1][k].set_xlabel("t [s]")
    handles = [matplotlib.lines.Line2D([], [], color=c.color, lw=1.4,
                                       label=f"realised thrust, {c.label}")
               for c, *_ in panels]
    handles += [matplotlib.lines.Line2D([], [], color="gray", lw=0.9, ls="--",
                                        label="commanded thrust"),
                matplotlib.lines.Line2D([], [], color="black", lw=1.0, ls=":",
                                        label=f"within {REACH_M} m")]
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=8,
               bbox_to_anchor=(0.5, 1 - (0.32 + extra) / fig.get_figheight()), frameon=False)
    fig.suptitle(f"{title}{sep}thruster outputs (realised: after delay, lag, slew and "
                 "efficiency)", fontsize=10.5)
    top = 1 - (0.85 + extra) / fig.get_figheight()
    fig.subplots_adjust(left=0.08 if ncol > 1 else 0.12, right=0.98, bottom=0.06, top=top,
                        hspace=0.15, wspace=0.05)
    names.append(save(fig, plots_dir, f"eval_{scenario}_thrusters.png", written))
    return names


def plot_distance_overview(ctrls, plots_dir, written):
    """Distance to the way-point against time for every paper scenario, per controller."""
    have = [(c, [(s, c.trajectory(s, 0)) for s in PAPER_SCENARIOS
                 if 0 in c.trajectory_episodes(s)]) for c in ctrls]
    have = [(c, [(s, t) for s, t in st if t is not None]) for c, st in have]
    have = [(c, st) for c, st in have if st]
    if not have:
        return None
    fig, axes = plt.subplots(1, len(have), figsize=(max(7.0, 6.0 * len(have)), 4.0),
                             squeeze=False,
                             sharey=True)
    colors = {"test1": "tab:blue", "test2": "tab:green", "fault": "tab:red",
              "current": "tab:purple"}
    for k, (c, st) in enumerate(have):
        ax = axes[0][k]
        for s, traj in st:
            ax.semilogy(traj["t"], np.clip(traj["distance_m"], DIST_FLOOR, None),
                        color=colors.get(s), lw=1.4, label=s)
        ax.axhline(REACH_M, color="gray", ls="--", lw=1.0, label=f"{REACH_M} m")
        ax.set_title(c.label, fontsize=10)
        ax.set_xlabel("t [s]")
        ax.grid(True, alpha=0.4)
        ax.legend(fontsize=8)
    axes[0][0].set_ylabel("distance to way-point [m] (log)")
    fig.suptitle("distance to the way-point, every scenario", fontsize=11)
    fig.subplots_adjust(left=0.07 if len(have) > 1 else 0.12, right=0.98, bottom=0.12,
                        top=0.86, wspace=0.05)
    return save(fig, plots_dir, "eval_distance.png", written)


def plot_suite(ctrls, plots_dir, written):
    names = []
    with_rows = [(c, c.rows(SUITE)) for c in ctrls]
    with_rows = [(c, r) for c, r in with_rows if r]
    if with_rows:
        fig, axes = plt.subplots(2, 3, figsize=(15, 8.2))
        width = 0.8 / len(with_rows)
        # (a) end reasons per controller
        ax = axes[0][0]
        reasons = sorted({r["end_reason"] or "?" for _, rows in with_rows for r in rows},
                         key=lambda s: (END_REASONS.index(s) if s in END_REASONS else 99, s))
        reasons = ["ever"] + reasons
        for j, (c, rows) in enumerate(with_rows):
            counts = [sum(r["reached"] for r in rows)]
            counts += [sum(1 for r in rows if (r["end_reason"] or "?") == s)
                       for s in reasons[1:]]
            xs = np.arange(len(reasons)) + (j - (len(with_rows) - 1) / 2) * width
            bars = ax.bar(xs, counts, width, color=c.color, label=f"{c.label} (n={len(rows)})")
            for b, v in zip(bars, counts):
                ax.text(b.get_x() + b.get_width() / 2, v, str(v), ha="center", va="bottom",
                        fontsize=7)
        ax.set_xticks(np.arange(len(reasons)))
        ax.set_xticklabels([f"end:\n{s}" if i else f"within {REACH_M} m\nat some time"
                            for i, s in enumerate(reasons)], fontsize=8)
        ax.set_ylabel("episodes")
        ax.set_title("outcome (end: the episode's end reason)", fontsize=10)
        ax.set_ylim(0, 1.35 * max(len(rows) for _, rows in with_rows))
        ax.legend(fontsize=7, loc="upper center", ncol=2)

        def hist(ax, key, xlabel, title, log=False, reached_only=False):
            vals = []
            for c, rows in with_rows:
                v = finite([r[key] for r in rows if (r["reached"] or not reached_only)])
                vals.append((c, v))
            allv = np.concatenate([v for _, v in vals]) if vals else np.array([])
            if allv.size == 0:
                no_data(ax, f"no {key} values")
                ax.set_title(title, fontsize=10)
                return
            pos = allv[allv > 0]
            if log and pos.size and pos.max() > 30 * pos.min():  # over 1.5 decades: log bins
                lo, hi = pos.min(), pos.max() * 1.001
                bins = np.logspace(math.log10(lo), math.log10(hi), 25)
                ax.set_xscale("log")
            else:
                lo, hi = allv.min(), allv.max()
                bins = np.linspace(lo, hi if hi > lo else lo + 1, 25)
            for c, v in vals:
                v = np.clip(v, bins[0], None)
                ax.hist(v, bins=bins, histtype="stepfilled", alpha=0.35, color=c.color)
                med = np.median(v) if v.size else math.nan
                ax.hist(v, bins=bins, histtype="step", lw=1.5, color=c.color,
                        label=f"{c.label}: n={v.size}, median {med:.3g}")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("episodes")
            ax.set_title(title, fontsize=10)
            ax.legend(fontsize=7)

        hist(axes[0][1], "time_to_reach_s", "time to reach [s]",
             f"time to reach {REACH_M} m (reached episodes)", reached_only=True)
        hist(axes[0][2], "mean_error_after_reach_m", "mean distance after reaching [m]",
             "hold error (reached episodes)", log=True, reached_only=True)
        hist(axes[1][0], "final_error_m", "distance at 70 s [m]", "final error (all episodes)",
             log=True)
        hist(axes[1][1], "thrust_energy", "thrust energy (sum of mean squared normalised "
             "command)", "thrust energy (all episodes)")
        # (f) per-episode time to reach, one controller against the other (same way-points).
        ax = axes[1][2]
        if len(with_rows) >= 2:
            (ca, ra), (cb, rb) = with_rows[0], with_rows[1]
            byep = {r["episode"]: r for r in rb}
            xa, yb, fails = [], [], 0
            for r in ra:
                o = byep.get(r["episode"])
                if o is None or abs(o["goal_x"] - r["goal_x"]) + abs(o["goal_y"] - r["goal_y"]) \
                        + abs(o["goal_z"] - r["goal_z"]) > 1e-3:
                    continue
                if r["reached"] and o["reached"]:
                    xa.append(o["time_to_reach_s"])
                    yb.append(r["time_to_reach_s"])
                else:
                    fails += 1
            if xa:
                ax.scatter(xa, yb, s=14, color="tab:gray", alpha=0.8)
                m = max(max(xa), max(yb)) * 1.05
                ax.plot([0, m], [0, m], color="black", lw=0.8, ls="--", label="equal time")
                ax.set_xlim(0, m)
                ax.set_ylim(0, m)
                ax.set_aspect("equal", adjustable="box")
                ax.set_xlabel(f"{cb.label}: time to reach [s]")
                ax.set_ylabel(f"{ca.label}: time to reach [s]")
                ax.legend(fontsize=7, title=f"{len(xa)} way-points both reached, "
                          f"{fails} not", title_fontsize=7)
                ax.grid(True, alpha=0.4)
            else:
                no_data(ax, "no way-point reached by both controllers\n(or different "
                        "way-points)")
            ax.set_title("same way-point, both controllers", fontsize=10)
        else:
            no_data(ax, "one controller only:\nno per-way-point comparison")
            ax.set_title("same way-point, both controllers", fontsize=10)
        fig.suptitle("suite: random way-points from [0, 0, 5] (auvrl eval --scenario suite)",
                     fontsize=11)
        fig.subplots_adjust(left=0.05, right=0.98, bottom=0.08, top=0.91, hspace=0.38,
                            wspace=0.22)
        names.append(save(fig, plots_dir, "suite_overview.png", written))

    # --- The suite trajectories that were saved (the first 10 by default). ---
    saved = [(c, c.trajectory_episodes(SUITE)) for c in ctrls]
    saved = [(c, eps) for c, eps in saved if eps]
    if saved:
        fig = plt.figure(figsize=(max(7.5, 6.2 * len(saved)), 6.0))
        pts, draw = [], []
        for c, eps in saved:
            items = []
            for ep in eps:
                traj = c.trajectory(SUITE, ep)
                if traj is None:
                    continue
                goal = goal_of(c, SUITE, ep)
                items.append((ep, traj, goal))
                pts += list(np.column_stack([traj["y"], traj["x"], traj["z"]]))
                if goal is not None:
                    pts.append(np.array([goal[1], goal[0], goal[2]]))
            draw.append((c, items))
        cmap = plt.get_cmap("tab10")
        for k, (c, items) in enumerate(draw):
            ax = fig.add_subplot(1, len(draw), k + 1, projection="3d")
            for j, (ep, traj, goal) in enumerate(items):
                col = cmap(j % 10)
                ax.plot(traj["y"], traj["x"], traj["z"], color=col, lw=1.1)
                if goal is not None:
                    ax.scatter([goal[1]], [goal[0]], [goal[2]], color=col, marker="*", s=90,
                               edgecolors="black", linewidths=0.4, depthshade=False)
            if items:
                t0 = items[0][1]
                ax.scatter([t0["y"][0]], [t0["x"][0]], [t0["z"][0]], color="tab:green",
                           marker="o", s=50, depthshade=False, label="start")
            ax.plot([], [], color="gray", label="path (colour = episode)")
            ax.scatter([], [], color="gray", marker="*", s=90, label="its way-point")
            set_3d_limits(ax, pts)
            ax.view_init(elev=22, azim=-60)
            ax.set_xlabel("east y [m]", labelpad=2)
            ax.set_ylabel("north x [m]", labelpad=2)
            ax.set_zlabel("depth z [m] (down)", labelpad=2)
            ax.tick_params(labelsize=7, pad=0)
            reached = sum(1 for ep, _, _ in items
                          if (c.row(SUITE, ep) or {}).get("reached"))
            ax.set_title(f"{c.label}: suite episodes {items[0][0] if items else ''}-"
                         f"{items[-1][0] if items else ''} ({reached}/{len(items)} reached)",
                         fontsize=10)
            ax.legend(loc="upper left", fontsize=7)
        fig.suptitle("suite: saved trajectories (NED, depth down)", fontsize=11)
        fig.subplots_adjust(left=0.0, right=0.97, bottom=0.03, top=0.88, wspace=0.08)
        names.append(save(fig, plots_dir, "suite_3d.png", written))
    return names


# ---------------------------------------------------------------------------------------------
# Training figures
# ---------------------------------------------------------------------------------------------
def rolling_mean(v, w):
    v = np.asarray(v, dtype=float)
    if v.size == 0:
        return v
    c = np.cumsum(np.insert(v, 0, 0.0))
    n = np.arange(1, v.size + 1)
    lo = np.maximum(0, n - w)
    return (c[n] - c[lo]) / (n - lo)


def rolling_median(v, w):
    v = np.asarray(v, dtype=float)
    out = np.empty_like(v)
    if v.size <= 5000 or w <= 1:
        for i in range(v.size):
            out[i] = np.median(v[max(0, i - w + 1):i + 1])
        return out
    win = np.lib.stride_tricks.sliding_window_view(v, w)
    out[w - 1:] = np.median(win, axis=1)
    for i in range(w - 1):
        out[i] = np.median(v[:i + 1])
    return out


def window_for(n):
    return int(min(100, max(1, n // 10)))


class Training:
    def __init__(self, run):
        self.ep = self.learner = self.progress = None
        rows = read_csv(os.path.join(run, "episodes.csv"), EPISODES_SPEC, "episodes.csv",
                        required=("wall_s",))
        if rows is None:
            if not os.path.isfile(os.path.join(run, "episodes.csv")):
                NOTES.miss("episodes.csv (no per-episode training log)")
        elif rows:
            rows.sort(key=lambda r: r["wall_s"])
            self.ep = columns(rows, [c for c in EPISODES_SPEC if c != "end_reason"])
            self.ep["n"] = np.arange(1, len(rows) + 1, dtype=float)
            self.ep_end_reasons = [r["end_reason"] for r in rows]
        for attr, name, spec in (("learner", "learner.csv", LEARNER_SPEC),
                                 ("progress", "progress.csv", PROGRESS_SPEC)):
            rows = read_csv(os.path.join(run, name), spec, name, required=("wall_s",))
            if rows is None:
                if not os.path.isfile(os.path.join(run, name)):
                    NOTES.miss(f"{name} (no {'learner' if attr == 'learner' else 'progress'}"
                               " log)")
            elif rows:
                rows.sort(key=lambda r: r["wall_s"])
                setattr(self, attr, columns(rows, list(spec)))

    def any(self):
        return any(x is not None for x in (self.ep, self.learner, self.progress))

    def wall_max(self):
        m = [np.nanmax(d["wall_s"]) for d in (self.ep, self.learner, self.progress)
             if d is not None and np.isfinite(d["wall_s"]).any()]
        return max(m) if m else math.nan


def plot_training(tr, plots_dir, written, modes=("episodes", "time")):
    if not tr.any():
        return []
    wall = tr.wall_max()
    if not math.isfinite(wall) or wall < 120:
        tscale, tunit = 1.0, "s"
    elif wall < 7200:
        tscale, tunit = 60.0, "min"
    else:
        tscale, tunit = 3600.0, "h"
    n = 0 if tr.ep is None else tr.ep["n"].size
    w = window_for(n)
    n_title = n
    for d in (tr.learner, tr.progress):  # no episodes.csv: the 1 Hz logs' episode count
        if n_title == 0 and d is not None and finite(d["episodes"]).size:
            n_title = int(finite(d["episodes"]).max())
    names = []
    for mode in modes:
        fig, axes = plt.subplots(3, 3, figsize=(15, 10.5), squeeze=False)
        if mode == "episodes":
            def xs(d, src):
                return d["n"] if src == "ep" else d["episodes"]
            xlabel = "episodes (completed, all actors)"
        else:
            def xs(d, src):
                return d["wall_s"] / tscale
            xlabel = f"wall-clock time [{tunit}]"

        def sub(idx):
            return axes[idx // 3][idx % 3]

        def scatter(ax, x, y, color, label):
            step = max(1, x.size // MAX_SCATTER)
            ax.scatter(x[::step], y[::step], s=3, color=color, alpha=0.25, lw=0, label=label,
                       rasterized=True)

        def panel(idx, title, draws, ylabel, logy=False, missing="", ylim=None):
            ax = sub(idx)
            drew = False
            for d, src, fn in draws:
                if d is not None:
                    fn(ax, xs(d, src), d)
                    drew = True
            if not drew:
                no_data(ax, f"no data ({missing} missing)")
            else:
                if logy == "auto":  # log when the positive values span over 1.5 decades
                    ys = [np.asarray(ln.get_ydata(), dtype=float) for ln in ax.get_lines()]
                    ys += [np.asarray(col.get_offsets())[:, 1] for col in ax.collections
                           if len(col.get_offsets())]
                    y = finite(np.concatenate(ys)) if ys else np.array([])
                    logy = bool(y.size) and y.min() > 0 and y.max() > 30 * y.min()
                if logy:
                    ax.set_yscale("log")
                if ylim:
                    ax.set_ylim(*ylim)
                ax.grid(True, alpha=0.35)
                h, lab = ax.get_legend_handles_labels()
                if h:
                    ax.legend(fontsize=7, loc="best", markerscale=3)
                ax.set_ylabel(ylabel, fontsize=9)
            ax.set_title(title, fontsize=10)
            ax.tick_params(labelsize=8)
            return ax

        def ep_return(ax, x, d):
            scatter(ax, x, d["return"], "tab:blue", "per episode")
            ax.plot(x, rolling_mean(d["return"], w), color="navy", lw=1.5,
                    label=f"mean of last {w}")

        def ep_success(ax, x, d):
            ax.plot(x, rolling_mean(d["success"], w), color="tab:green", lw=1.5,
                    label=f"episodes.csv, last {w}")

        def pr_success(ax, x, d):
            ax.plot(x, d["success_rate"], color="darkgreen", lw=1.0, ls="--",
                    label="progress.csv success_rate (last 100)")
            ax.step(x, d["best_suite_success"], where="post", color="tab:purple", lw=1.2,
                    label="best policy, quick suite")

        def ep_dist(ax, x, d):
            scatter(ax, x, np.clip(d["final_distance_m"], DIST_FLOOR, None), "tab:red",
                    "final, per episode")
            ax.plot(x, np.clip(rolling_median(d["final_distance_m"], w), DIST_FLOOR, None),
                    color="darkred", lw=1.5, label=f"final, median of last {w}")
            ax.plot(x, np.clip(rolling_median(d["min_distance_m"], w), DIST_FLOOR, None),
                    color="tab:orange", lw=1.2, label=f"closest, median of last {w}")

        def beta_of(key):
            def f(ax, x, d):
                ax.plot(x, d["beta_m"], lw=1.4, label=key, drawstyle="steps-post")
            return f

        def learner_col(col, color, label, positive=False):
            def f(ax, x, d):
                y = d[col]
                if positive:
                    y = np.where(y > 0, y, np.nan)
                ax.plot(x, y, color=color, lw=1.2, label=label)
            return f

        ep, le, pr = tr.ep, tr.learner, tr.progress
        panel(0, "episode return", [(ep, "ep", ep_return)], "return", missing="episodes.csv")
        panel(1, "success rate (goal radius beta reached)",
              [(ep, "ep", ep_success), (pr, "pr", pr_success)], "fraction",
              missing="episodes.csv, progress.csv", ylim=(-0.03, 1.03))
        panel(2, "distance to way-point at the end", [(ep, "ep", ep_dist)], "m",
              logy="auto", missing="episodes.csv")
        # beta from the first log that has it: per episode, else the 1 Hz logs.
        beta_src = [next(((d, src, beta_of(name)) for d, src, name in (
            (ep, "ep", "episodes.csv"), (pr, "pr", "progress.csv"), (le, "le", "learner.csv"))
            if d is not None), (None, "", None))]
        panel(3, "goal radius beta (curriculum)", beta_src, "m", logy="auto",
              missing="episodes.csv, progress.csv, learner.csv")
        panel(4, "critic loss", [(le, "le", learner_col("critic_loss", "tab:red",
                                                          "critic loss", positive=True))],
              "loss", logy="auto", missing="learner.csv")
        panel(5, "actor loss (-Q of the actor's action)",
              [(le, "le", learner_col("actor_loss", "tab:purple", "actor loss"))], "loss",
              missing="learner.csv")
        panel(6, "mean Q (critic, sampled batch)",
              [(le, "le", learner_col("mean_q", "tab:brown", "mean Q"))], "Q",
              missing="learner.csv")
        panel(7, "simulation rate",
              [(pr, "pr", learner_col("env_steps_per_s", "tab:blue", "env steps/s (sims)")),
               (le, "le", learner_col("transitions_per_s", "tab:cyan",
                                      "transitions/s received by the learner"))],
              "per second", missing="progress.csv, learner.csv")
        panel(8, "learner updates",
              [(le, "le", learner_col("updates_per_s", "tab:green", "updates/s"))]
              if le is not None else
              [(pr, "pr", learner_col("updates_per_s", "tab:green", "updates/s"))],
              "per second", missing="learner.csv, progress.csv")
        for ax in axes[-1]:
            ax.set_xlabel(xlabel)
        if mode == "time":
            for ax in axes[0]:
                ax.set_xlabel(xlabel, fontsize=8)
        fig.suptitle(f"training against {xlabel.split(' (')[0]} ({n_title} episodes, "
                     f"{fmt_duration(wall)} wall-clock)", fontsize=11)
        fig.subplots_adjust(left=0.06, right=0.98, bottom=0.06, top=0.93, hspace=0.35,
                            wspace=0.25)
        names.append(save(fig, plots_dir, f"training_vs_{mode}.png", written))
    return names


# ---------------------------------------------------------------------------------------------
# The report
# ---------------------------------------------------------------------------------------------
def md_table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def mean_or_nan(v):
    v = finite(v)
    return float(v.mean()) if v.size else math.nan


def scenario_row(c, scenario):
    rows = c.rows(scenario)
    if not rows:
        return None
    reached = [r for r in rows if r["reached"]]
    reasons = {}
    for r in rows:
        reasons[r["end_reason"] or "?"] = reasons.get(r["end_reason"] or "?", 0) + 1
    t = mean_or_nan([r["time_to_reach_s"] for r in reached])
    hold = mean_or_nan([r["mean_error_after_reach_m"] for r in reached])
    return [scenario, c.label, f"{len(reached)}/{len(rows)}", fmt(t, 1, " s"), fmt_err(hold),
            fmt_err(mean_or_nan([r["final_error_m"] for r in rows])),
            fmt(mean_or_nan([r["thrust_energy"] for r in rows]), 1),
            ", ".join(f"{k}" + (f" x{v}" if v > 1 else "") for k, v in reasons.items())]


def suite_rows(ctrls):
    out = []
    for c in ctrls:
        rows = c.rows(SUITE)
        if not rows:
            continue
        reached = [r for r in rows if r["reached"]]
        t = finite([r["time_to_reach_s"] for r in reached])
        hold = finite([r["mean_error_after_reach_m"] for r in reached])
        fin = finite([r["final_error_m"] for r in rows])
        reasons = {}
        for r in rows:
            reasons[r["end_reason"] or "?"] = reasons.get(r["end_reason"] or "?", 0) + 1
        out.append([
            c.label,
            f"{len(reached)}/{len(rows)} ({100 * len(reached) / len(rows):.0f} %)",
            fmt(t.mean(), 1, " s") if t.size else "-",
            fmt(float(np.median(t)), 1, " s") if t.size else "-",
            f"{t.min():.1f}-{t.max():.1f} s" if t.size else "-",
            (f"{fmt_err(hold.mean())} (max {fmt_err(hold.max())})") if hold.size else "-",
            (f"{fmt_err(fin.mean())} (max {fmt_err(fin.max())})") if fin.size else "-",
            fmt(mean_or_nan([r["thrust_energy"] for r in rows]), 1),
            ", ".join(f"{k} {v}" for k, v in sorted(reasons.items())),
        ])
    return out


def training_summary(tr):
    rows = []
    ep, le, pr = tr.ep, tr.learner, tr.progress
    wall = tr.wall_max()
    rows.append(["wall-clock time", fmt_duration(wall) + (f" ({wall:.0f} s)" if
                                                          math.isfinite(wall) and wall >= 120
                                                          else "")])
    if ep is not None:
        n = ep["n"].size
        w = window_for(n)
        steps = np.nansum(ep["length_steps"])
        rows.append(["episodes (episodes.csv)", f"{n}"])
        rows.append(["actors", f"{np.unique(finite(ep['actor_id'])).size}"])
        rows.append(["env steps in completed episodes",
                     f"{steps:.0f}" + (f" ({steps / wall:.0f} steps/s over the run)"
                                       if math.isfinite(wall) and wall > 0 else "")])
        rows.append([f"success rate, last {w} episodes",
                     f"{100 * np.nanmean(ep['success'][-w:]):.0f} %"])
        rows.append(["success rate, all episodes", f"{100 * np.nanmean(ep['success']):.0f} %"])
        rows.append([f"mean return, last {w} episodes", fmt(np.nanmean(ep["return"][-w:]), 1)])
        rows.append([f"median final distance, last {w} episodes",
                     fmt_err(float(np.nanmedian(ep["final_distance_m"][-w:])))])
        rows.append(["goal radius beta at the end", fmt_err(float(ep["beta_m"][-1]))])
        rows.append(["last policy version used by an actor",
                     f"{np.nanmax(ep['policy_version']):.0f}"])
    if pr is not None:
        sps = finite(pr["env_steps_per_s"])
        sps = sps[sps > 0]
        if sps.size:
            rows.append(["env steps/s (progress.csv, mean / max)",
                         f"{sps.mean():.0f} / {sps.max():.0f}"])
        best = finite(pr["best_suite_success"])
        if best.size:
            rows.append(["best quick-suite success (progress.csv)", f"{100 * best.max():.0f} %"])
        if ep is None:
            rows.append(["episodes (progress.csv)", f"{np.nanmax(pr['episodes']):.0f}"])
    if le is not None:
        last = {k: v[-1] for k, v in le.items()}

        def g(key, spec=".0f"):
            v = last[key]
            return format(v, spec) if math.isfinite(v) else "-"
        ups = finite(le["updates_per_s"])
        ups = ups[ups > 0]
        rows.append(["learner updates", g("updates") + (
            f" (mean {ups.mean():.0f} updates/s while updating)" if ups.size else "")])
        rows.append(["transitions received / replay buffer",
                     f"{g('transitions_received')} / {g('buffer_size')}"])
        rows.append(["last critic loss / actor loss / mean Q",
                     f"{g('critic_loss', '.4g')} / {g('actor_loss', '.4g')} / "
                     f"{g('mean_q', '.4g')}"])
        rows.append(["policy weights published", g("weights_published")])
    return rows


def vehicle_of(ctrls):
    """The evaluated vehicle's name (the paper's Nessie VII when the evaluation does not say)."""
    names = sorted({c.vehicle for c in ctrls if c.vehicle})
    return ", ".join(names) if names else "nessie7"


def robustness_section(run, L):
    """The robustness suite's comparison table (robustness_comparison.md, written by auvrl),
    or a note naming what is missing."""
    policy_csv, pid_csv, comparison = robustness_inputs(run)
    if not (policy_csv or pid_csv or comparison):
        if os.path.isdir(os.path.join(run, "eval")):
            NOTES.miss("eval/robustness_comparison.md (no robustness suite in this run)")
        return
    L.append("### Robustness")
    L.append("")
    L.append("The robustness suite (`auvrl eval --scenario robustness`, docs/usage.md): groups "
             "of episodes from random headings that each change one thing (start, way-point "
             "distance, a weak or dead thruster, current, sensor noise, a wrong model). The bar "
             "a policy must clear in every group against the PID: held at least as often, no "
             "flip, mean time to reach no later, thrust energy no more, hold error within "
             "0.05 m of the PID's, smoothness at most twice the PID's.")
    L.append("")
    if comparison:
        try:
            with open(comparison, encoding="utf-8", errors="replace") as f:
                L.append(f.read().strip())
        except OSError as e:
            NOTES.damage(f"{os.path.relpath(comparison, run)}: cannot read ({e})")
    else:
        NOTES.miss(f"{os.path.relpath(robustness_paths(run)[2], run)} (no comparison table)")
    for path in robustness_paths(run)[:2]:
        if not os.path.isfile(path):
            NOTES.miss(f"{os.path.relpath(path, run)} (no robustness figure)")
    L.append("")


def write_report(run, ctrls, tr, figures, path):
    L = []
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    L.append(f"# auvrl run report: {os.path.basename(os.path.abspath(run))}")
    L.append("")
    L.append(f"Generated by `scripts/plot_run.py` on {now} from `{os.path.abspath(run)}`. "
             "Reproduces Carlucho et al., *AUV Position Tracking Control Using End-to-End Deep "
             "Reinforcement Learning*, OCEANS 2018 (Sec. V, Fig. 3-8) on the vehicle "
             f"`{vehicle_of(ctrls)}`. "
             f"\"Reached\" means within {REACH_M} m of the way-point; every evaluation episode "
             "lasts 70 s (700 steps of 0.1 s).")
    sel = os.path.join(run, "eval", "selected_policy.txt")
    if os.path.isfile(sel):
        try:
            with open(sel, encoding="utf-8", errors="replace") as f:
                L.append("")
                L.append(f"Evaluated policy: `{f.read().strip()}`.")
        except OSError:
            pass
    L.append("")

    # --- Evaluation tables. ---
    L.append("## Evaluation")
    L.append("")
    if not ctrls:
        L.append("No evaluation in this run (`eval/` missing).")
        L.append("")
    else:
        L.append("Controllers: " + ", ".join(f"{c.label} (`{os.path.relpath(c.dir, run)}`)"
                                             for c in ctrls) + ".")
        L.append("")
        scen = [s for s in PAPER_SCENARIOS]
        scen += sorted({r["scenario"] for c in ctrls for r in c.summary} - set(scen) - {SUITE})
        rows = [r for s in scen for c in ctrls for r in [scenario_row(c, s)] if r]
        if rows:
            L.append("### Paper scenarios")
            L.append("")
            L.append(md_table(["scenario", "controller", "reached", "time to reach",
                               "mean hold error", "final error", "thrust energy",
                               "end"], rows))
            L.append("")
            L.append("Time to reach: first time within 0.5 m; mean hold error: mean distance "
                     "from then to 70 s; final error: distance at 70 s; thrust energy: sum "
                     "over the steps of the mean squared normalised command (all six at full "
                     "thrust for 70 s = 700).")
            L.append("")
            L.append("Compared with the paper (its learned policy, on its own plant):")
            L.append("")
            cmp_rows = []
            for s in ("test1", "test2", "fault"):
                cells = [s, PAPER_FIG[s], PAPER_TIME_S[s]]
                for c in ctrls:
                    rs = c.rows(s)
                    r = rs[0] if rs else None
                    cells.append("-" if r is None else
                                 (fmt(r["time_to_reach_s"], 1, " s") if r["reached"]
                                  else "not reached"))
                cmp_rows.append(cells)
            L.append(md_table(["scenario", "paper figure", "paper: time to reach"]
                              + [f"{c.label}: time to reach" for c in ctrls], cmp_rows))
            L.append("")
        srows = suite_rows(ctrls)
        if srows:
            L.append("### Suite")
            L.append("")
            L.append(md_table(["controller", "success", "mean time to reach",
                               "median time to reach", "range", "mean hold error",
                               "final error", "mean thrust energy", "end reasons"], srows))
            L.append("")
            L.append("Times and hold errors over the reached episodes; final error and "
                     "energy over all.")
            L.append("")
    robustness_section(run, L)

    # --- Figures. ---
    L.append("## Figures")
    L.append("")
    for s in PAPER_SCENARIOS:
        figs = [f for f in (f"eval_{s}_3d.png", f"eval_{s}_position.png",
                            f"eval_{s}_thrusters.png") if f in figures]
        if not figs:
            continue
        paper = f" (the paper's {PAPER_FIG[s]})" if PAPER_FIG[s] != "-" else ""
        L.append(f"### {SCENARIO_TEXT[s]}{paper}")
        L.append("")
        for f in figs:
            what = {"3d": "3-D path", "position": "position against time",
                    "thrusters": "thruster outputs"}[f[len(f"eval_{s}_"):-4]]
            L.append(f"![{s}: {what}](plots/{f})")
            L.append("")
    for f, title in (("eval_distance.png", "### Distance to the way-point, all scenarios"),
                     ("suite_overview.png", "### Suite"), ("suite_3d.png", None),
                     ("robustness.png", "### Robustness suite: policy against the PID")):
        if f in figures:
            if title:
                L.append(title)
                L.append("")
            L.append(f"![{f[:-4]}](plots/{f})")
            L.append("")

    # --- Training. ---
    L.append("## Training")
    L.append("")
    if tr.any():
        L.append(md_table(["", "value"], training_summary(tr)))
        L.append("")
        for f in ("training_vs_episodes.png", "training_vs_time.png"):
            if f in figures:
                L.append(f"![{f[:-4]}](plots/{f})")
                L.append("")
    else:
        L.append("No training logs in this run (episodes.csv, learner.csv and progress.csv "
                 "missing).")
        L.append("")

    # --- Fine-tuning (finetune.csv, only in runs that fine-tuned). ---
    ft_rows = read_csv(os.path.join(run, "finetune.csv"),
                       {"iteration": parse_float, "objective_s": parse_float,
                        "elapsed_s": parse_float,
                        "validation_reached": parse_float_or_empty,
                        "validation_mean_time_s": parse_float_or_empty,
                        "validation_hold_m": parse_float_or_empty,
                        "validation_worst_time_ratio": parse_float_or_empty},
                       "finetune.csv", required=("iteration", "objective_s"))
    if ft_rows:
        L.append("## Fine-tuning")
        L.append("")
        L.append(f"{len(ft_rows)} iterations of evolution strategies in "
                 f"{fmt_duration(ft_rows[-1]['elapsed_s'])}; objective (mean over the "
                 "fine-tuning's way-points of the time to within 0.5 m plus the weighted hold "
                 "error, tilt beyond the flip margin and lag behind the PID: config.yaml's "
                 f"finetune section) {fmt(ft_rows[0]['objective_s'], 3, ' s')} after the first "
                 "iteration, "
                 f"{fmt(ft_rows[-1]['objective_s'], 3, ' s')} after the last. Validation "
                 "way-points at the checkpoints (the kept one is named above, as the "
                 "evaluated policy):")
        L.append("")
        table = []
        for r in ft_rows:
            if r["validation_reached"] is None or not np.isfinite(r["validation_reached"]):
                continue
            table.append([int(r["iteration"]), fmt(r["objective_s"], 3, " s"),
                          int(r["validation_reached"]), fmt(r["validation_mean_time_s"], 2, " s"),
                          fmt(r["validation_hold_m"], 3, " m"),
                          fmt(r["validation_worst_time_ratio"], 2)])
        L.append(md_table(["iteration", "objective", "reached", "mean time", "hold error",
                           "worst time ratio to the PID"], table))
        L.append("")

    # --- What was missing or damaged. ---
    L.append("## Inputs missing or damaged")
    L.append("")
    if not NOTES.missing and not NOTES.damaged:
        L.append("None: every input was present and readable.")
    for m in NOTES.missing:
        head = m.split(" ")[0].rstrip(":")
        L.append(f"- missing: `{head}`{m[len(head):]}")
    cap = 50
    for d in NOTES.damaged[:cap]:
        L.append(f"- {d}")
    if len(NOTES.damaged) > cap:
        L.append(f"- ... and {len(NOTES.damaged) - cap} more (see the script's error output)")
    L.append("")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("\n".join(L) + "\n")
    os.replace(tmp, path)


CONTEXT = {}  # what the figure jobs draw from (set before the worker processes fork)


def check_and_load(ctrls):
    """Names what the evaluation lacks and reads every trajectory (once, before forking)."""
    for c in ctrls:
        rel = os.path.relpath(c.dir, c.run)
        for s in PAPER_SCENARIOS + (SUITE,):
            if c.summary and not c.rows(s):
                NOTES.miss(f"{rel}/summary.csv: no {s} rows")
        for s in PAPER_SCENARIOS:
            if not c.trajectory_episodes(s):
                NOTES.miss(f"{rel}/trajectories/{s}_0.csv")
        for s in PAPER_SCENARIOS + (SUITE,):
            for ep in c.trajectory_episodes(s):
                c.trajectory(s, ep)


def run_job(job):
    """Draws one group of figures; returns (files written, missing, damaged). A failure is
    reported and the other figures are still drawn."""
    global NOTES
    kind, arg = job
    saved, NOTES = NOTES, Notes()
    written = []
    ctrls, tr, plots_dir = CONTEXT["ctrls"], CONTEXT["tr"], CONTEXT["plots_dir"]
    try:
        if kind == "scenario":
            plot_scenario(ctrls, arg, plots_dir, written)
        elif kind == "distance":
            plot_distance_overview(ctrls, plots_dir, written)
        elif kind == "suite":
            plot_suite(ctrls, plots_dir, written)
        elif kind == "robustness":
            plot_robustness_figure(CONTEXT["run"], plots_dir, written)
        elif kind == "training":
            plot_training(tr, plots_dir, written, modes=(arg,))
    except Exception as e:  # a figure must not cost the report
        traceback.print_exc()
        NOTES.damage(f"figures {kind} {arg or ''}: drawing failed ({type(e).__name__}: {e})")
        plt.close("all")
    finally:
        notes, NOTES = NOTES, saved
    return written, notes.missing, notes.damaged


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr if len(argv) != 2 else sys.stdout)
        return 0 if len(argv) == 2 else 2
    run = argv[1]
    if not os.path.isdir(run):
        print(f"plot_run: {run}: not a directory (expected a run directory written by "
              "`auvrl train` or an `auvrl eval --out` directory)", file=sys.stderr)
        return 2
    plots_dir = os.path.join(run, "plots")
    try:
        os.makedirs(plots_dir, exist_ok=True)
    except OSError as e:
        print(f"plot_run: cannot create {plots_dir}: {e}", file=sys.stderr)
        return 1
    plt.rcParams.update({"figure.max_open_warning": 0, "axes.titlesize": 10})

    ctrls = find_controllers(run)
    check_and_load(ctrls)
    tr = Training(run)
    CONTEXT.update(ctrls=ctrls, tr=tr, plots_dir=plots_dir, run=run)
    jobs = [("scenario", s) for s in PAPER_SCENARIOS] + [("distance", None), ("suite", None)]
    if all(robustness_inputs(run)[:2]):
        jobs.append(("robustness", None))
    if tr.any():
        jobs += [("training", "episodes"), ("training", "time")]
    results = None
    workers = min(len(jobs), os.cpu_count() or 1)
    if workers > 1:
        try:  # one figure job per process: the figures take seconds each to draw
            import multiprocessing
            with multiprocessing.get_context("fork").Pool(workers) as pool:
                results = pool.map(run_job, jobs)
        except Exception as e:  # no fork or no semaphores here: draw them one by one
            print(f"plot_run: parallel drawing unavailable ({e}); drawing serially",
                  file=sys.stderr)
            results = None
    if results is None:
        results = [run_job(j) for j in jobs]
    written = []
    for names, missing, damaged in results:
        written += names
        NOTES.missing += missing
        NOTES.damaged += damaged
    for f in OWN_PLOTS:  # stale figures of an earlier call with more inputs
        if f not in written and os.path.isfile(os.path.join(plots_dir, f)):
            os.remove(os.path.join(plots_dir, f))
    report = os.path.join(run, "report.md")
    try:
        write_report(run, ctrls, tr, written, report)
    except OSError as e:
        print(f"plot_run: cannot write {report}: {e}", file=sys.stderr)
        return 1
    print(f"plot_run: wrote {report} and {len(written)} figures in {plots_dir}"
          + (f" ({len(NOTES.missing)} inputs missing, {len(NOTES.damaged)} problems, listed "
             "in the report)" if NOTES.missing or NOTES.damaged else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
