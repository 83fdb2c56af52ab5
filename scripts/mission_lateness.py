#!/usr/bin/python3
"""Runs a policy and the PID baseline on every single-way-point mission of a folder (a set of
scripts/validation_missions.py) and prints, by the way-point's depth change, on how many the
policy arrives no sooner than the PID, by how much in all, and what thrust it spends against
the PID's: where a policy that is sooner on average is still later than the PID.

Each mission runs as `build/bin/auvrl eval --mission FILE` (the policy, then --controller pid);
their mission.csv files go to OUT_DIR/policy/<name>/ and OUT_DIR/pid/<name>/, one line per
mission to OUT_DIR/lateness.csv. A mission either controller does not complete (the time limit,
or an abort on the mission's limits) is counted apart and left out of the times.

Usage: scripts/mission_lateness.py MISSIONS_DIR OUT_DIR --policy P [--auvrl BIN]
"""
import argparse
import csv
import glob
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Classes of the way-point's depth change from the start, m (z is depth: > 0 dives).
CLASSES = (('climb > 2 m', -1e9, -2.0), ('level within 2 m', -2.0, 2.0),
           ('dive 2-7 m', 2.0, 7.0), ('dive > 7 m', 7.0, 1e9))
NUMBER_LIST = r'\[([^\]]*)\]'


def start_and_goal(path):
    """The mission's start position and its single way-point, NED, m."""
    with open(path) as f:
        text = f.read()
    found = re.findall(r'position_ned_m:\s*' + NUMBER_LIST, text)
    if len(found) != 2:
        sys.exit(f'mission_lateness.py: {path}: expected a start and one way-point '
                 f'(two position_ned_m), found {len(found)}')
    return [[float(v) for v in item.split(',')] for item in found]


def run(auvrl, mission, out_dir, controller_args):
    """The mission's one way-point as (time to reach s, None if not reached; energy)."""
    os.makedirs(out_dir, exist_ok=True)
    done = subprocess.run([auvrl, 'eval', '--mission', mission, '--out', out_dir] +
                          controller_args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    if done.returncode != 0:
        sys.exit(f'mission_lateness.py: {auvrl} eval --mission {mission} failed:\n{done.stderr}')
    with open(os.path.join(out_dir, 'mission.csv')) as f:
        row = next(csv.DictReader(f))
    return (float(row['time_to_reach_s']) if row['reached'] == '1' else None,
            float(row['energy']))


def summary(rows):
    """One line per class: missions, both reached, policy no sooner, total lateness, mean
    difference, energy ratio."""
    lines = ['| depth change | missions | both reached | policy no sooner | later by, in all [s] '
             '| mean difference [s] | energy, policy / PID |',
             '|---|---|---|---|---|---|---|']
    for name, low, high in CLASSES + (('all', -1e9, 1e9),):
        mine = [r for r in rows if low <= r['depth_change_m'] < high]
        both = [r for r in mine if r['policy_time_s'] is not None and r['pid_time_s'] is not None]
        diffs = [r['policy_time_s'] - r['pid_time_s'] for r in both]
        pid_energy = sum(r['pid_energy'] for r in mine)
        mean_s = sum(diffs) / len(diffs) if diffs else float('nan')
        ratio = sum(r['policy_energy'] for r in mine) / pid_energy if pid_energy else float('nan')
        lines.append(
            f'| {name} | {len(mine)} | {len(both)} | {sum(d >= 0 for d in diffs)} | '
            f'{sum(d for d in diffs if d > 0):.1f} | {mean_s:+.2f} | {ratio:.2f} |')
    return '\n'.join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('missions_dir')
    parser.add_argument('out_dir')
    parser.add_argument('--policy', required=True, help='policy network file')
    parser.add_argument('--auvrl', default=os.path.join(ROOT, 'build', 'bin', 'auvrl'))
    args = parser.parse_args()
    missions = sorted(glob.glob(os.path.join(args.missions_dir, '*.yaml')))
    if not missions:
        sys.exit(f'mission_lateness.py: {args.missions_dir}: no mission files (*.yaml)')
    rows = []
    for mission in missions:
        name = os.path.splitext(os.path.basename(mission))[0]
        start, goal = start_and_goal(mission)
        policy_time_s, policy_energy = run(args.auvrl, mission,
                                           os.path.join(args.out_dir, 'policy', name),
                                           ['--policy', args.policy])
        pid_time_s, pid_energy = run(args.auvrl, mission, os.path.join(args.out_dir, 'pid', name),
                                     ['--controller', 'pid'])
        rows.append({'mission': name, 'depth_change_m': goal[2] - start[2],
                     'policy_time_s': policy_time_s, 'pid_time_s': pid_time_s,
                     'policy_energy': policy_energy, 'pid_energy': pid_energy})
    with open(os.path.join(args.out_dir, 'lateness.csv'), 'w', newline='') as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    print(f'{len(rows)} missions of {args.missions_dir}; policy {args.policy}; not completed: '
          f'policy {sum(r["policy_time_s"] is None for r in rows)}, '
          f'PID {sum(r["pid_time_s"] is None for r in rows)}')
    print(summary(rows))


if __name__ == '__main__':
    main()
