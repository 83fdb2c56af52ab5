#!/usr/bin/python3
"""Writes the mission files of two validation sets of our own (never the evaluation's
scenarios), drawn from fixed seeds so that anyone gets the same files:

  behind/b<k>.yaml  way-points straight behind the start: from the task's start (0, 0, 5 m) at
                    rest, a way-point drawn uniformly in the training region (at least 3 m away
                    horizontally), the start heading its bearing + pi (Python's
                    random.Random(4242); 30 by default);
  legs/l<k>.yaml    legs from anywhere: start and way-point drawn uniformly in the training
                    region (at least 3 m apart), the heading uniform (random.Random(777); 40 by
                    default), as a mission's later legs start;
  ahead/a<k>.yaml   way-points from the task's start at rest facing north, as test1 and the
                    fine-tuning's plain way-points start: a way-point drawn uniformly in the
                    training region at least 3 m away (random.Random(1357); 120 by default).

Every file is config/missions/test2.yaml with its start, heading and way-point replaced (so the
missions' limits are test2's: depth 0.5..20 m, |roll| <= 0.5 rad, |pitch| <= 0.8 rad), the
vehicle named by its absolute path, and for the legs at most 40 m from the start (a start and a
way-point in the region may be 31.5 m apart). Run each with
`build/bin/auvrl eval --policy P --mission FILE --out DIR` (or `--controller pid`), or a whole
set with scripts/mission_lateness.py; the lab notes docs/lab-notes/2026-11-25-facing-away.md and
docs/lab-notes/2026-11-26-mined-way-points.md measured policies on them.

Usage: scripts/validation_missions.py OUT_DIR [--behind N] [--legs N] [--ahead N]
"""
import argparse
import math
import os
import random
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEMPLATE = os.path.join(ROOT, 'config', 'missions', 'test2.yaml')
VEHICLE = os.path.join(ROOT, 'config', 'vehicles', 'nessie7.yaml')
# The fast preset's way-point region (task.goal_min_ned_m / goal_max_ned_m), m.
REGION = ((-10.0, 10.0), (-10.0, 10.0), (1.0, 15.0))
START = (0, 0, 5)
MIN_APART_M = 3.0


def point(rng):
    """A point drawn uniformly in the region, rounded to the millimetre."""
    return [round(rng.uniform(lo, hi), 3) for lo, hi in REGION]


def replace_once(text, old, new):
    if text.count(old) != 1:
        sys.exit(f'validation_missions.py: {TEMPLATE}: expected "{old}" once, '
                 f'found it {text.count(old)} times')
    return text.replace(old, new)


def mission(template, start, yaw_rad, goal, max_distance_m=None):
    """test2.yaml with its start, heading and way-point (and distance limit) replaced."""
    text = replace_once(template, 'vehicle: ../vehicles/nessie7.yaml', f'vehicle: {VEHICLE}')
    text = replace_once(text, 'euler_rpy_rad: [0, 0, -2.4329663814621227]',
                        f'euler_rpy_rad: [0, 0, {yaw_rad!r}]')
    text = replace_once(text, '- position_ned_m: [7, 6, 10]',
                        f'- position_ned_m: [{goal[0]}, {goal[1]}, {goal[2]}]')
    text = replace_once(text, 'position_ned_m: [0, 0, 5]',
                        f'position_ned_m: [{start[0]}, {start[1]}, {start[2]}]')
    if max_distance_m is not None:
        text = replace_once(text, 'max_distance_from_start_m: 25',
                            f'max_distance_from_start_m: {max_distance_m}')
    return text


def behind(template, count):
    """Way-points straight behind the task's start."""
    rng = random.Random(4242)
    for _ in range(count):
        while True:
            goal = point(rng)
            if math.hypot(goal[0], goal[1]) > MIN_APART_M:
                break
        yaw_rad = math.remainder(math.atan2(goal[1], goal[0]) + math.pi, 2 * math.pi)
        yield mission(template, START, yaw_rad, goal)


def legs(template, count):
    """Legs from rest anywhere in the region."""
    rng = random.Random(777)
    for _ in range(count):
        while True:
            start, goal = point(rng), point(rng)
            if math.dist(start, goal) > MIN_APART_M:
                break
        yaw_rad = round(rng.uniform(-math.pi, math.pi), 4)
        yield mission(template, start, yaw_rad, goal, max_distance_m=40)


def ahead(template, count):
    """Way-points from the task's start at its heading (north)."""
    rng = random.Random(1357)
    for _ in range(count):
        while True:
            goal = point(rng)
            if math.dist(START, goal) > MIN_APART_M:
                break
        yield mission(template, START, 0.0, goal)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('out_dir')
    parser.add_argument('--behind', type=int, default=30, help='way-points behind the start')
    parser.add_argument('--legs', type=int, default=40, help='legs from anywhere')
    parser.add_argument('--ahead', type=int, default=120,
                        help="way-points from the task's start at its heading")
    args = parser.parse_args()
    if args.behind < 0 or args.legs < 0 or args.ahead < 0:
        sys.exit('validation_missions.py: --behind, --legs and --ahead must be >= 0')
    with open(TEMPLATE) as f:
        template = f.read()
    sets = (('behind', 'b', behind(template, args.behind), args.behind),
            ('legs', 'l', legs(template, args.legs), args.legs),
            ('ahead', 'a', ahead(template, args.ahead), args.ahead))
    for name, prefix, texts, _ in sets:
        folder = os.path.join(args.out_dir, name)
        os.makedirs(folder, exist_ok=True)
        for k, text in enumerate(texts):
            with open(os.path.join(folder, f'{prefix}{k}.yaml'), 'w') as f:
                f.write(text)
    print('wrote ' + ', '.join(f'{count} missions to {os.path.join(args.out_dir, name)}'
                               for name, _, _, count in sets))


if __name__ == '__main__':
    main()
