#!/usr/bin/python3
"""scripts/robustness_census.py on fabricated comparison files: the groups passing and the
failures per group and criterion add up as written, the comparisons where every group passes
are counted, a file, its folder and a run directory are read alike, and a missing file, a
missing column, a bad cell and another suite's groups are named.

Usage: test_robustness_census.py SCRIPT
"""
import csv
import os
import subprocess
import sys
import tempfile

SCRIPT = sys.argv[1]
HEADER = ['group', 'passes', 'held', 'no_flip', 'time', 'energy', 'hold', 'smoothness',
          'episodes']
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


def write(path, rows, header=HEADER):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w', newline='') as f:
        writer = csv.writer(f)
        writer.writerow(header)
        writer.writerows(rows)


def row(group, failed=()):
    """A group's row: every criterion passes except those named."""
    flags = ['0' if c in failed else '1' for c in HEADER[2:8]]
    return [group, '0' if failed else '1'] + flags + ['20']


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


with tempfile.TemporaryDirectory() as tmp:
    a = os.path.join(tmp, 'a', 'robustness_comparison.csv')
    b_dir = os.path.join(tmp, 'b')
    run_dir = os.path.join(tmp, 'run')
    write(a, [row('rest_start'), row('t6_0pct', ('time', 'hold')), row('sensor_noise')])
    write(os.path.join(b_dir, 'robustness_comparison.csv'),
          [row('rest_start'), row('t6_0pct', ('time',)), row('sensor_noise', ('energy',))])
    write(os.path.join(run_dir, 'eval', 'robustness_comparison.csv'),
          [row('rest_start'), row('t6_0pct', ('held', 'hold')), row('sensor_noise')])
    out_csv = os.path.join(tmp, 'census.csv')
    done = run(a, b_dir, run_dir, '--out', out_csv)
    check(done.returncode == 0, f'three comparisons: exit {done.returncode}: {done.stderr}')
    text = done.stdout
    check('3 comparisons; groups passing: mean 1.67 of 3 (min 1, max 2)' in text, text)
    check('every group passes in 0 of 3 comparisons' in text, text)
    lines = {line.split()[0]: ' '.join(line.split()[1:]) for line in text.splitlines()[1:]}
    check(lines.get('t6_0pct') == 'failed 3 of 3: held 1, time 2, hold 2', text)
    check(lines.get('sensor_noise') == 'failed 1 of 3: energy 1', text)
    check('rest_start' not in text, f'a group that never failed is listed: {text}')
    check(text.index('t6_0pct') < text.index('sensor_noise'), f'most failures first: {text}')
    with open(out_csv) as f:
        rows = list(csv.reader(f))
    check(rows[0] == ['group', 'comparisons', 'failed', 'held', 'no_flip', 'time', 'energy',
                      'hold', 'smoothness'], f'header {rows[0]}')
    check(rows[1] == ['t6_0pct', '3', '3', '1', '0', '2', '0', '2', '0'], f'row {rows[1]}')
    check(rows[3] == ['rest_start', '3', '0', '0', '0', '0', '0', '0', '0'], f'row {rows[3]}')

    all_pass = os.path.join(tmp, 'all_pass.csv')
    write(all_pass, [row('rest_start'), row('t6_0pct'), row('sensor_noise')])
    done = run(all_pass, a, all_pass)
    check('every group passes in 2 of 3 comparisons' in done.stdout, done.stdout)

    done = run(os.path.join(tmp, 'nothing'))
    check(done.returncode != 0 and 'nothing: no robustness_comparison.csv' in done.stderr,
          f'missing file: {done.returncode} {done.stderr}')
    bad_header = os.path.join(tmp, 'bad_header.csv')
    write(bad_header, [['rest_start', '1']], header=['group', 'passes'])
    done = run(bad_header)
    check(done.returncode != 0 and 'bad_header.csv: missing column(s) held' in done.stderr,
          f'missing column: {done.returncode} {done.stderr}')
    bad_cell = os.path.join(tmp, 'bad_cell.csv')
    write(bad_cell, [row('rest_start'), ['t6_0pct', '1', 'yes'] + ['1'] * 5 + ['20']])
    done = run(bad_cell)
    check(done.returncode != 0 and "line 3: column held: expected 0 or 1, found 'yes'"
          in done.stderr, f'bad cell: {done.returncode} {done.stderr}')

    other_suite = os.path.join(tmp, 'other_suite.csv')
    write(other_suite, [row('rest_start'), row('t6_0pct')])
    done = run(a, other_suite)
    check(done.returncode != 0 and 'other_suite.csv: its groups differ' in done.stderr,
          f'another suite: {done.returncode} {done.stderr}')

for f in failures:
    print('FAIL:', f)
sys.exit(1 if failures else 0)
