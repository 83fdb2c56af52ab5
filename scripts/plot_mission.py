#!/usr/bin/python3
"""Plots of an `auvrl run` mission directory.

Usage: /usr/bin/python3 scripts/plot_mission.py RUN [NAME]

NAME heads the titles (default: RUN's own name); `auvrl replay` gives the replayed run's, so that
the replay's plots are the run's.

Reads what `auvrl run` writes into RUN:
  trajectory.csv   t, x, y, z, phi, theta, psi, ..., cmd_1..cmd_n, thrust_1..thrust_n, distance_m
  waypoints.csv    index (from 0), x, y, z, reached, time_to_reach_s, ..., completed_s, ...
  vehicle.csv      the thrusters' names (T1, T2, ... without it)
  events.csv       time_s, event: the events injected during the mission (optional)
and writes RUN/plots/mission_3d.png (the 3-D path through every way-point, numbered from 1 as
"way-point i of n") and
RUN/plots/mission_thrusters.png (each thruster's realised and commanded thrust against time, the
way-points' completions and the injected events marked).

Exit 0 on success, 2 when RUN or its trajectory.csv is missing or holds no row, 3 when
matplotlib or numpy cannot be imported (Debian: apt install python3-matplotlib python3-numpy),
1 when the plots cannot be written.
"""
import csv
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
    import numpy as np  # noqa: E402

    # Beside this script: one 3-D framing, one reading of a CSV cell.
    from plot_run import number, set_3d_limits  # noqa: E402
except ImportError as e:  # a clear note, not a traceback: auvrl run reports it
    print(f"plot_mission: cannot import {e.name}: apt install python3-matplotlib python3-numpy",
          file=sys.stderr)
    sys.exit(3)

DPI = 100


def read_rows(path):
    """The rows of a CSV file as dicts, [] when it does not exist."""
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8", errors="replace", newline="") as f:
        return list(csv.DictReader(f))


def read_trajectory(path):
    """{column: numpy array} of trajectory.csv."""
    rows = read_rows(path)
    if not rows:
        return None
    return {k: np.array([number(r.get(k)) for r in rows]) for k in rows[0].keys()}


def thruster_names(run, n):
    names = [r.get("name", "") for r in read_rows(os.path.join(run, "vehicle.csv"))]
    return names if len(names) == n and all(names) else [f"T{i + 1}" for i in range(n)]


def plot_3d(traj, waypoints, title, path):
    """The path (matplotlib's x = east, y = north, z = depth pointing down) and the way-points."""
    e, n, d = traj["y"], traj["x"], traj["z"]
    wp = np.array([[number(w["y"]), number(w["x"]), number(w["z"])] for w in waypoints])
    fig = plt.figure(figsize=(9, 7.5))
    ax = fig.add_subplot(projection="3d")
    pts = np.column_stack([e, n, d])
    floor = set_3d_limits(ax, np.vstack([pts, wp]) if len(wp) else pts)
    ax.plot(e, n, d, color="tab:blue", lw=1.6, label="path")
    if floor is not None:
        ax.plot(e, n, np.full_like(d, floor), color="0.45", lw=0.9, ls=":",
                label="horizontal track (on the floor)")
    ax.scatter([e[0]], [n[0]], [d[0]], color="tab:green", marker="o", s=50, label="start",
               depthshade=False)
    ax.scatter([e[-1]], [n[-1]], [d[-1]], color="tab:blue", marker="s", s=25,
               label=f"end ({traj['t'][-1]:.1f} s)", depthshade=False)
    labelled = set()
    for i, w in enumerate(waypoints):
        reached = w.get("reached") == "1"
        label = "way-point (reached)" if reached else "way-point (not reached)"
        ax.scatter([wp[i][0]], [wp[i][1]], [wp[i][2]], color="tab:red" if reached else "0.5",
                   marker="*", s=170, depthshade=False,
                   label=None if label in labelled else label)
        labelled.add(label)
        ax.text(wp[i][0], wp[i][1], wp[i][2], f"  {i + 1}", fontsize=11,
                fontweight="bold", color="darkred" if reached else "0.35")
    ax.set_xlabel("east y [m]", labelpad=2)
    ax.set_ylabel("north x [m]", labelpad=2)
    ax.set_zlabel("depth z [m] (down)", labelpad=2)
    ax.tick_params(labelsize=7, pad=0)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.85)
    ax.set_title(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def plot_thrusters(traj, names, waypoints, events, title, path):
    """Realised (solid) and commanded (dashed) thrust per thruster against time."""
    t = traj["t"]
    fig, axes = plt.subplots(len(names), 1, figsize=(10, 1.35 * len(names) + 1.4), sharex=True,
                             sharey=True, squeeze=False)
    done = [(number(w.get("completed_s")), i + 1) for i, w in enumerate(waypoints)]
    for i, name in enumerate(names):
        ax = axes[i][0]
        cmd, real = traj.get(f"cmd_{i + 1}"), traj.get(f"thrust_{i + 1}")
        if cmd is not None:
            ax.plot(t, cmd, color="gray", lw=0.9, ls="--", alpha=0.8, label="commanded")
        if real is not None:
            ax.plot(t, real, color="tab:blue", lw=1.3, label="realised")
        ax.axhline(0, color="black", lw=0.5)
        for when, index in done:
            if math.isfinite(when):
                ax.axvline(when, color="tab:green", ls=":", lw=1.0)
                if i == 0:
                    ax.text(when, 1.02, f"{index}", transform=ax.get_xaxis_transform(),
                            ha="center", va="bottom", fontsize=8, color="darkgreen")
        for when, _ in events:
            ax.axvline(when, color="tab:red", ls="-.", lw=1.0)
        ax.set_ylabel(f"{name}\n[N]", fontsize=8)
        ax.grid(True, alpha=0.4)
        ax.tick_params(labelsize=7)
    axes[0][0].legend(loc="upper right", fontsize=7, ncol=2, framealpha=0.85)
    axes[-1][0].set_xlabel("mission time t [s] (green dotted: way-point i completed; "
                           "red dash-dot: an injected event)")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    run = argv[1]
    name = argv[2] if len(argv) == 3 else os.path.basename(os.path.normpath(run))
    traj = read_trajectory(os.path.join(run, "trajectory.csv")) if os.path.isdir(run) else None
    if traj is None or "t" not in traj or len(traj["t"]) == 0:
        print(f"plot_mission: {run}/trajectory.csv is missing or holds no row", file=sys.stderr)
        return 2
    waypoints = read_rows(os.path.join(run, "waypoints.csv"))
    events = [(number(r.get("time_s")), r.get("event", ""))
              for r in read_rows(os.path.join(run, "events.csv"))]
    events = [e for e in events if math.isfinite(e[0])]
    nthr = sum(1 for k in traj if k.startswith("thrust_"))
    names = thruster_names(run, nthr)
    reached = sum(1 for w in waypoints if w.get("reached") == "1")
    title = (f"{name}: {reached} of {len(waypoints)} "
             f"way-points reached in {traj['t'][-1]:.1f} s")
    plots = os.path.join(run, "plots")
    try:
        os.makedirs(plots, exist_ok=True)
        plot_3d(traj, waypoints, title, os.path.join(plots, "mission_3d.png"))
        if nthr:
            plot_thrusters(traj, names, waypoints, events, title,
                           os.path.join(plots, "mission_thrusters.png"))
    except OSError as e:
        print(f"plot_mission: cannot write the plots: {e}", file=sys.stderr)
        return 1
    print(f"plot_mission: wrote {plots}/mission_3d.png and mission_thrusters.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
