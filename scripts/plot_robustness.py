#!/usr/bin/python3
"""The robustness suite of a policy against the PID baseline, in one figure.

Usage: /usr/bin/python3 scripts/plot_robustness.py POLICY PID OUT.png

POLICY and PID are robustness.csv files written by `auvrl eval --scenario robustness` (or the
directories holding one: `auvrl train` writes RUN/eval/policy/ and RUN/eval/pid/). The figure
has one row per group and five panels side by side: held rate, mean time to reach, mean thrust
energy, mean hold error and smoothness (mean |change of the normalised command| per step, on a
log axis), the two controllers' bars beside each other. A black tick marks the bar the policy
must clear in each group: held at least the PID's rate, time and energy at most the PID's, hold
error at most the PID's + 0.05 m, smoothness at most twice the PID's.

Exit 0 on success, 2 when an input is missing or holds no row, 3 when matplotlib or numpy
cannot be imported (Debian: apt install python3-matplotlib python3-numpy), 1 when the figure
cannot be written.
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

    from plot_run import number  # noqa: E402  (beside this script: one reading of a CSV cell)
except ImportError as e:
    print(f"plot_robustness: cannot import {e.name}: apt install python3-matplotlib "
          "python3-numpy", file=sys.stderr)
    sys.exit(3)

DPI = 100
HOLD_MARGIN_M = 0.05  # the bar: hold error within the PID's + this
SMOOTHNESS_RATIO = 2.0  # the bar: smoothness at most this times the PID's
COLORS = {"policy": "tab:blue", "pid": "tab:orange"}
LABELS = {"policy": "learned policy", "pid": "PID baseline"}


def read_groups(path):
    """{group: row} of a robustness.csv (or of DIR/robustness.csv), in the file's order; None
    when the file is missing or unreadable."""
    if os.path.isdir(path):
        path = os.path.join(path, "robustness.csv")
    try:
        with open(path, encoding="utf-8", errors="replace", newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError:
        return None
    out = {}
    for r in rows:
        if not r.get("group"):
            continue
        episodes = number(r.get("episodes"))
        held = number(r.get("held"))
        out[r["group"]] = {
            "controller": r.get("controller") or "",
            "held_pct": 100 * held / episodes if episodes > 0 else math.nan,
            "time_s": number(r.get("mean_time_to_reach_s")),
            "energy": number(r.get("mean_thrust_energy")),
            "hold_m": number(r.get("mean_hold_error_m")),
            "smoothness": number(r.get("mean_smoothness")),
        }
    return out


# (key, panel title, the bar for the policy as a function of the PID's value)
PANELS = [
    ("held_pct", "held [% of episodes]\n(more is better)", lambda v: v),
    ("time_s", "mean time to reach [s]", lambda v: v),
    ("energy", "mean thrust energy", lambda v: v),
    ("hold_m", "mean hold error [m]", lambda v: v + HOLD_MARGIN_M),
    ("smoothness", "smoothness: mean |du| per step\n(log axis)", lambda v: SMOOTHNESS_RATIO * v),
]


def draw(policy, pid, out_path, title=None):
    """Draws the figure from two read_groups() results to out_path."""
    groups = list(policy) + [g for g in pid if g not in policy]
    n = len(groups)
    height_in = 1.6 + 0.3 * n
    fig, axes = plt.subplots(1, len(PANELS), figsize=(16, height_in), sharey=True)
    y = np.arange(n)
    sides = [("policy", policy, -0.2), ("pid", pid, 0.2)]
    for ax, (key, heading, bar_of) in zip(axes, PANELS):
        for name, rows, dy in sides:
            values = np.array([rows.get(g, {}).get(key, math.nan) for g in groups], dtype=float)
            ax.barh(y + dy, np.nan_to_num(values, nan=0.0), height=0.38, color=COLORS[name],
                    label=LABELS[name])
            for i in np.nonzero(~np.isfinite(values))[0]:
                ax.text(0, y[i] + dy, " -", va="center", fontsize=7)
        limits = np.array([bar_of(pid.get(g, {}).get(key, math.nan)) for g in groups], dtype=float)
        ok = np.isfinite(limits)
        ax.plot(limits[ok], y[ok] - 0.2, "|", color="black", markersize=9, markeredgewidth=1.5,
                label="the policy's bar")
        if key == "smoothness":
            positive = [v for rows in (policy, pid) for r in rows.values()
                        for v in [r.get(key, math.nan)] if v > 0]
            if positive:
                ax.set_xscale("log")
                ax.set_xlim(min(positive) / 2, max(positive) * 3)
        ax.set_title(heading, fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(groups, fontsize=8)
    axes[0].invert_yaxis()
    axes[0].legend(loc="lower left", bbox_to_anchor=(0, 1.06), ncol=3, fontsize=8, frameon=False)
    fig.suptitle(title or "Robustness suite: learned policy against the PID baseline",
                 y=1 - 0.1 / height_in)
    fig.subplots_adjust(left=0.09, right=0.99, wspace=0.12, bottom=0.5 / height_in,
                        top=1 - 1.1 / height_in)
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def main(argv):
    if len(argv) != 4 or argv[1] in ("-h", "--help"):
        print(__doc__, file=sys.stderr if len(argv) != 2 else sys.stdout)
        return 0 if len(argv) == 2 else 2
    read = {}
    for name, path in (("policy", argv[1]), ("pid", argv[2])):
        read[name] = read_groups(path)
        if not read[name]:
            print(f"plot_robustness: {path}: no robustness.csv rows (expected what `auvrl eval "
                  "--scenario robustness` writes)", file=sys.stderr)
            return 2
    try:
        draw(read["policy"], read["pid"], argv[3])
    except OSError as e:
        print(f"plot_robustness: cannot write {argv[3]}: {e}", file=sys.stderr)
        return 1
    print(f"plot_robustness: wrote {argv[3]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
