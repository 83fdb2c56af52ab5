#!/usr/bin/python3
"""scripts/validation_missions.py: the three validation sets come out the same on every run,
in the region, with the geometry each set promises (way-points straight behind the start; legs
from anywhere at least 3 m long; way-points at least 3 m ahead of the start facing north), and
only the start, heading, way-point and distance limit differ from config/missions/test2.yaml.

Usage: test_validation_missions.py SCRIPT
"""
import filecmp
import math
import os
import re
import subprocess
import sys
import tempfile

SCRIPT = sys.argv[1]
TEMPLATE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(SCRIPT))), 'config',
                        'missions', 'test2.yaml')
REGION = ((-10.0, 10.0), (-10.0, 10.0), (1.0, 15.0))
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


def vector(text, key):
    """The three numbers after `key: [` in a mission file."""
    m = re.search(re.escape(key) + r': \[([^\]]*)\]', text)
    return [float(x) for x in m.group(1).split(',')]


def run(out_dir, *extra):
    return subprocess.run([sys.executable, SCRIPT, out_dir, *extra], capture_output=True,
                          text=True)


def changed_lines(text, template):
    return [(a, b) for a, b in zip(template.splitlines(), text.splitlines()) if a != b]


with tempfile.TemporaryDirectory() as tmp:
    first, second = os.path.join(tmp, 'a'), os.path.join(tmp, 'b')
    result = run(first)
    check(result.returncode == 0, f'exit {result.returncode}: {result.stderr}')
    check(run(second).returncode == 0, 'second run failed')
    template = open(TEMPLATE).read()
    for name, prefix, count in (('behind', 'b', 30), ('legs', 'l', 40), ('ahead', 'a', 120)):
        files = sorted(os.listdir(os.path.join(first, name)))
        check(len(files) == count, f'{name}: {len(files)} files, expected {count}')
        for k in range(count):
            path = os.path.join(first, name, f'{prefix}{k}.yaml')
            check(filecmp.cmp(path, os.path.join(second, name, f'{prefix}{k}.yaml'),
                              shallow=False), f'{path}: differs between two runs')
            text = open(path).read()
            start = vector(text, 'start:\n  position_ned_m')
            goal = vector(text, '- position_ned_m')
            yaw = vector(text, 'euler_rpy_rad')[2]
            for i, (lo, hi) in enumerate(REGION):
                check(lo <= goal[i] <= hi, f'{path}: way-point {goal} outside the region')
            check(len(text.splitlines()) == len(template.splitlines()),
                  f'{path}: not test2.yaml with values replaced')
            changed = changed_lines(text, template)
            if name == 'behind':
                check(start == [0.0, 0.0, 5.0], f'{path}: start {start}')
                bearing = math.atan2(goal[1] - start[1], goal[0] - start[0])
                check(abs(math.cos(yaw - bearing) + 1.0) < 1e-12,
                      f'{path}: heading {yaw} not straight away from bearing {bearing}')
                check(math.hypot(goal[0], goal[1]) > 3.0, f'{path}: way-point too close')
                check(len(changed) == 3, f'{path}: {len(changed)} lines changed, expected 3')
            elif name == 'ahead':
                check(start == [0.0, 0.0, 5.0], f'{path}: start {start}')
                check(yaw == 0.0, f'{path}: heading {yaw}, expected north (0)')
                check(math.dist(start, goal) > 3.0, f'{path}: way-point too close')
                check(len(changed) == 3, f'{path}: {len(changed)} lines changed, expected 3')
            else:
                for i, (lo, hi) in enumerate(REGION):
                    check(lo <= start[i] <= hi, f'{path}: start {start} outside the region')
                check(math.dist(start, goal) > 3.0, f'{path}: leg shorter than 3 m')
                check(-math.pi <= yaw <= math.pi, f'{path}: heading {yaw}')
                check('max_distance_from_start_m: 40' in text, f'{path}: distance limit')
                check(len(changed) == 5, f'{path}: {len(changed)} lines changed, expected 5')
    # The first of each set, as the lab note measured them.
    b0 = open(os.path.join(first, 'behind', 'b0.yaml')).read()
    check('- position_ned_m: [7.249, -1.686, 1.398]' in b0, 'behind/b0.yaml: not the lab note\'s')
    l0 = open(os.path.join(first, 'legs', 'l0.yaml')).read()
    check(len(vector(l0, '- position_ned_m')) == 3, 'legs/l0.yaml: no way-point')
    a0 = open(os.path.join(first, 'ahead', 'a0.yaml')).read()
    check('- position_ned_m: [9.646, -1.494, 3.078]' in a0, 'ahead/a0.yaml: not the lab note\'s')
    small = run(os.path.join(tmp, 'c'), '--behind', '2', '--legs', '0', '--ahead', '1')
    check(small.returncode == 0 and len(os.listdir(os.path.join(tmp, 'c', 'behind'))) == 2 and
          len(os.listdir(os.path.join(tmp, 'c', 'ahead'))) == 1, '--behind 2 --legs 0 --ahead 1')
    check(run(os.path.join(tmp, 'd'), '--legs', '-1').returncode != 0, '--legs -1 accepted')
    check(run(os.path.join(tmp, 'e'), '--ahead', '-1').returncode != 0, '--ahead -1 accepted')

if failures:
    print('\n'.join(failures))
    sys.exit(1)
print('validation missions: 30 behind the start, 40 legs and 120 ahead, the same on every run')
