#!/usr/bin/python3
"""scripts/mission_lateness.py on three missions of scripts/validation_missions.py's `ahead` set
with the committed policy: every mission run by both controllers (their mission.csv files where
the script says), lateness.csv holding what those files say, and the summary's rows adding up
from it; a folder without missions and a mission with two way-points refused, naming them.

Usage: test_mission_lateness.py LATENESS_SCRIPT MISSIONS_SCRIPT AUVRL POLICY
"""
import csv
import os
import subprocess
import sys
import tempfile

SCRIPT, MISSIONS_SCRIPT, AUVRL, POLICY = sys.argv[1:5]
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


def lateness(missions_dir, out_dir):
    return subprocess.run([sys.executable, SCRIPT, missions_dir, out_dir, '--policy', POLICY,
                           '--auvrl', AUVRL], capture_output=True, text=True)


def first_row(path):
    with open(path) as f:
        return next(csv.DictReader(f))


with tempfile.TemporaryDirectory() as tmp:
    made = subprocess.run([sys.executable, MISSIONS_SCRIPT, tmp, '--behind', '0', '--legs', '0',
                           '--ahead', '3'], capture_output=True, text=True)
    check(made.returncode == 0, f'validation_missions.py: {made.stderr}')
    out = os.path.join(tmp, 'out')
    result = lateness(os.path.join(tmp, 'ahead'), out)
    check(result.returncode == 0, f'exit {result.returncode}: {result.stderr}')
    rows = list(csv.DictReader(open(os.path.join(out, 'lateness.csv'))))
    check([r['mission'] for r in rows] == ['a0', 'a1', 'a2'], f'missions {rows}')
    diffs = []
    for r in rows:
        for controller in ('policy', 'pid'):
            mission = first_row(os.path.join(out, controller, r['mission'], 'mission.csv'))
            check(mission['reached'] == '1', f'{controller} {r["mission"]}: not reached')
            check(float(r[f'{controller}_time_s']) == float(mission['time_to_reach_s']),
                  f'{controller} {r["mission"]}: time differs from its mission.csv')
            check(float(r[f'{controller}_energy']) == float(mission['energy']),
                  f'{controller} {r["mission"]}: energy differs from its mission.csv')
        diffs.append(float(r['policy_time_s']) - float(r['pid_time_s']))
    # a0's way-point is [9.646, -1.494, 3.078]: a climb of 1.9 m from 5 m, a level one.
    check(abs(float(rows[0]['depth_change_m']) - (3.078 - 5.0)) < 1e-9, 'a0 depth change')
    lines = result.stdout.splitlines()
    check(lines[0].startswith('3 missions of ') and 'not completed: policy 0, PID 0' in lines[0],
          f'first line: {lines[0]}')
    all_row = [line for line in lines if line.startswith('| all |')]
    check(len(all_row) == 1, f'no "all" row in {result.stdout}')
    if all_row:
        cells = [c.strip() for c in all_row[0].strip('|').split('|')]
        check(cells[1:4] == ['3', '3', str(sum(d >= 0 for d in diffs))], f'all row {cells}')
        check(cells[4] == f'{sum(d for d in diffs if d > 0):.1f}', f'later by {cells[4]}')
        check(cells[5] == f'{sum(diffs) / 3:+.2f}', f'mean difference {cells[5]}')
    class_counts = sum(int(line.split('|')[2]) for line in lines
                       if line.startswith('| ') and not line.startswith(('| all', '| depth')))
    check(class_counts == 3, f'the classes hold {class_counts} missions, expected 3')
    # Refused: a folder without missions; a mission with two way-points.
    empty = os.path.join(tmp, 'empty')
    os.makedirs(empty)
    refused = lateness(empty, os.path.join(tmp, 'o2'))
    check(refused.returncode != 0 and 'no mission files' in refused.stderr,
          f'empty folder: {refused.returncode} {refused.stderr}')
    two = os.path.join(tmp, 'two')
    os.makedirs(two)
    text = open(os.path.join(tmp, 'ahead', 'a0.yaml')).read()
    text = text.replace('waypoints:\n', 'waypoints:\n  - position_ned_m: [1, 1, 6]\n', 1)
    with open(os.path.join(two, 'x.yaml'), 'w') as f:
        f.write(text)
    refused = lateness(two, os.path.join(tmp, 'o3'))
    check(refused.returncode != 0 and 'x.yaml' in refused.stderr and 'found 3' in refused.stderr,
          f'two way-points: {refused.returncode} {refused.stderr}')

if failures:
    print('\n'.join(failures))
    sys.exit(1)
print('mission lateness: 3 missions, both controllers, the figures from their mission.csv')
