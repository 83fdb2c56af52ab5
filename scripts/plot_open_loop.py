#!/usr/bin/python3
"""Plots an open-loop run of auv_sim (--open-loop ... --out OUT.csv): 3-D path, position and
attitude against time, realised thrust per thruster. Usage: plot_open_loop.py OUT.csv PNG"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{sys.argv[1]}: no rows")
    col = {k: [float(r[k]) for r in rows] for k in rows[0]}
    t = col["t"]
    thrusters = sorted((k for k in col if k.startswith("thrust_")), key=lambda k: int(k[7:]))

    fig = plt.figure(figsize=(14, 9))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    ax.plot(col["y"], col["x"], col["z"])
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_zlabel("depth z [m]")
    ax.invert_zaxis()
    ax.set_title("path (NED)")
    ax = fig.add_subplot(2, 2, 2)
    for k in ("x", "y", "z"):
        ax.plot(t, col[k], label=k)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("position [m]")
    ax.legend()
    ax.grid(True)
    ax = fig.add_subplot(2, 2, 3)
    for k in ("phi", "theta", "psi"):
        ax.plot(t, col[k], label=k)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("attitude [rad]")
    ax.legend()
    ax.grid(True)
    ax = fig.add_subplot(2, 2, 4)
    for i, k in enumerate(thrusters):
        ax.plot(t, col[k], label=f"T{i + 1}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("realised thrust [N]")
    ax.legend()
    ax.grid(True)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
