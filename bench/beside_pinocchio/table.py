#!/usr/bin/env python3
"""The markdown table of docs/performance.md, "Beside Pinocchio", from the harness's output under
g++ and under clang (run.sh runs it): nhdyn's time / Pinocchio's, the median of the paired
blocks; for CRBA and ABA against the convention (LOCAL or WORLD) in which Pinocchio was faster."""
import re
import sys

NAMES = {'panda': 'Panda', 'ur5': 'UR5', 'tiago': 'TIAGo', 'pr2': 'PR2', 'talos': 'TALOS'}


def parse(path):
    out, cur = {}, None
    for line in open(path):
        m = re.match(r'^(\S+) n=(\d+)\s+agree', line)
        if m:
            cur = m.group(1)
            out[cur] = {'n': int(m.group(2))}
            continue
        m = re.match(r'^\s+(\w+)\s+(local|world)?\s*nhdyn\s+(\d+) ns\s+pinocchio\s+(\d+) ns\s+ratio ([\d.]+)', line)
        if m and cur:
            algo, conv, _, pin, ratio = m.groups()
            out[cur][algo + ('_' + conv if conv else '')] = (int(pin), float(ratio))
    return out


def ratio(d, algo):
    if algo not in ('crba', 'aba'):
        return d[algo][1]
    local, world = d[algo + '_local'], d[algo + '_world']
    return (local if local[0] <= world[0] else world)[1]


def main():
    g, c = parse(sys.argv[1]), parse(sys.argv[2])
    algos = [('rne', 'rne'), ('crba', 'CRBA'), ('aba', 'ABA'), ('rne_derivatives', '∂τ/∂(q, q̇)')]
    head = ['robot', 'n'] + [f'{label}, {comp}' for _, label in algos for comp in ('g++', 'clang')]
    print('| ' + ' | '.join(head) + ' |')
    print('|---|' + '---:|' * (len(head) - 1))
    lo, hi = {}, {}
    for robot in g:
        row = [NAMES.get(robot, robot), str(g[robot]['n'])]
        for algo, label in algos:
            for comp, d in (('g++', g), ('clang', c)):
                r = ratio(d[robot], algo)
                row.append(f'{r:.2f}')
                lo[label, comp] = min(lo.get((label, comp), 9.0), r)
                hi[label, comp] = max(hi.get((label, comp), 0.0), r)
        print('| ' + ' | '.join(row) + ' |')
    print()
    for key in lo:
        print(f'{key[0]}, {key[1]}: {lo[key]:.2f}–{hi[key]:.2f}')


if __name__ == '__main__':
    main()
