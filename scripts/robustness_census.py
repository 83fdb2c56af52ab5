#!/usr/bin/python3
"""Counts, over many robustness comparisons (robustness_comparison.csv of `auvrl eval
--scenario robustness --with-pid`, or a training run's eval/), which groups fail the bar and on
which criteria: where a method loses its groups on average, rather than on one draw.

Each argument is a robustness_comparison.csv file, a directory holding one, or a run directory
(its eval/robustness_comparison.csv). Prints the comparisons read, the mean number of groups
passing, in how many comparisons every group passes (how often one run meets a bar of every
group at one draw), then one line per group that failed anywhere: in how many comparisons it
failed and how often each criterion did (a group can fail several at once), most failures
first. With --out, the same as CSV: group, comparisons, failed, then one column per criterion.

Usage: scripts/robustness_census.py COMPARISON [COMPARISON ...] [--out CSV]
"""
import argparse
import csv
import os
import signal
import sys

CRITERIA = ('held', 'no_flip', 'time', 'energy', 'hold', 'smoothness')
FILE = 'robustness_comparison.csv'


def comparison_path(argument):
    """The comparison file an argument names (the file, or one in it or in its eval/)."""
    for path in (argument, os.path.join(argument, FILE), os.path.join(argument, 'eval', FILE)):
        if os.path.isfile(path):
            return path
    sys.exit(f'robustness_census.py: {argument}: no {FILE} there (nor in its eval/)')


def flag(path, line, row, column):
    """A 0/1 cell as a bool; anything else ends the script naming the file, line and column."""
    value = row.get(column)
    if value not in ('0', '1'):
        sys.exit(f'robustness_census.py: {path}: line {line}: column {column}: expected 0 or 1, '
                 f'found {value!r}')
    return value == '1'


def read_comparison(path):
    """[(group, passes, {criterion: passes})] of one comparison file."""
    with open(path, newline='') as f:
        reader = csv.DictReader(f)
        missing = [c for c in ('group', 'passes') + CRITERIA if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f'robustness_census.py: {path}: missing column(s) {", ".join(missing)}')
        groups = []
        for line, row in enumerate(reader, start=2):
            criteria = {c: flag(path, line, row, c) for c in CRITERIA}
            groups.append((row['group'], flag(path, line, row, 'passes'), criteria))
    if not groups:
        sys.exit(f'robustness_census.py: {path}: no groups')
    return groups


def census(comparisons):
    """Per group: (comparisons it appears in, failures, {criterion: failures})."""
    table = {}
    for groups in comparisons:
        for group, passes, criteria in groups:
            seen, failed, by_criterion = table.get(group, (0, 0, dict.fromkeys(CRITERIA, 0)))
            for c, ok in criteria.items():
                by_criterion[c] += 0 if ok else 1
            table[group] = (seen + 1, failed + (0 if passes else 1), by_criterion)
    return table


def main():
    # Piped into head or less, end quietly when the reader stops.
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('comparisons', nargs='+', help='robustness_comparison.csv or its folder')
    parser.add_argument('--out', help='also write the census as CSV here')
    args = parser.parse_args()
    paths = [comparison_path(a) for a in args.comparisons]
    comparisons = [read_comparison(p) for p in paths]
    # The mean "of N" is one suite's: comparisons of different suites would mix their counts.
    for path, groups in zip(paths, comparisons):
        if sorted(g for g, _, _ in groups) != sorted(g for g, _, _ in comparisons[0]):
            sys.exit(f'robustness_census.py: {path}: its groups differ from those of {paths[0]} '
                     f'(another vehicle or suite?); count each suite apart')
    table = census(comparisons)
    passing = [sum(1 for _, passes, _ in groups if passes) for groups in comparisons]
    print(f'{len(comparisons)} comparisons; groups passing: mean {sum(passing) / len(passing):.2f} '
          f'of {len(comparisons[0])} (min {min(passing)}, max {max(passing)})')
    every = sum(1 for n in passing if n == len(comparisons[0]))
    print(f'every group passes in {every} of {len(comparisons)} comparisons')
    ordered = sorted(table.items(), key=lambda item: (-item[1][1], item[0]))
    for group, (seen, failed, by_criterion) in ordered:
        if failed == 0:
            continue
        detail = ', '.join(f'{c} {n}' for c, n in by_criterion.items() if n)
        print(f'  {group:<17} failed {failed} of {seen}: {detail}')
    if args.out:
        with open(args.out, 'w', newline='') as f:
            writer = csv.writer(f)
            writer.writerow(('group', 'comparisons', 'failed') + CRITERIA)
            for group, (seen, failed, by_criterion) in ordered:
                writer.writerow([group, seen, failed] + [by_criterion[c] for c in CRITERIA])


if __name__ == '__main__':
    main()
