#!/usr/bin/env python3
"""Writes an `nhdyn view` page: a stand-in, in Python (stdlib only), for the C++ writer.

    make_page.py MODEL [RUN_DIR] -o PAGE.html [options]

MODEL is a URDF file or a robot file (a JSON object with "urdf", "base", "locked": see
docs/model-format.md). RUN_DIR is an `nhdyn simulate` output folder (every <run>.csv in it,
in summary.json's order when there is one); without it the page shows one pose (--q, or
zeros). The page is dist/template.html with its `/*NHDYN_DATA*/` line replaced by
`window.NHDYN_DATA = {...};` (schema: viewer/README.md).

Meshes named by the URDF's <visual>s are embedded when they resolve: package://PKG/REL
through --package-path folders (DIR/PKG/REL, or DIR/REL when DIR is named PKG), a relative
path from the URDF's folder, an absolute path or file:// as is. Those that do not resolve
are reported here and drawn by the page as stand-ins with a notice.
"""

import argparse
import base64
import csv
import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATE = os.path.join(HERE, '..', 'dist', 'template.html')
PLACEHOLDER = '/*NHDYN_DATA*/'
PLANAR_NAMES = ['base_x', 'base_y', 'base_yaw']


def load_model(path):
    """(urdf_path, base, locked, name) from a URDF or a robot file."""
    if path.endswith('.json'):
        with open(path) as f:
            robot = json.load(f)
        if 'urdf' not in robot:
            sys.exit(f'make_page.py: {path}: not a robot file (no "urdf" key)')
        urdf = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), robot['urdf']))
        base = {'planar': False, 'joints': None}
        if (robot.get('base') or {}).get('type') == 'planar':
            base = {'planar': True, 'joints': list(PLANAR_NAMES)}
        c = robot.get('constraint') or {}
        if not base['planar'] and all(k in c for k in ('x', 'y', 'heading')):
            base = {'planar': False, 'joints': [c['x'], c['y'], c['heading']]}
        g = robot.get('gravity')
        up = None
        if isinstance(g, list) and len(g) == 3 and any(g):
            n = math.sqrt(sum(x * x for x in g))
            up = [-x / n for x in g]
            up = None if up == [0.0, 0.0, 1.0] else up
        return urdf, base, robot.get('locked') or {}, robot.get('name'), up
    return path, None, {}, None, None


def urdf_joints(root):
    """Movable joints in document order and every link name."""
    movable = [j.get('name') for j in root.findall('joint') if j.get('type') not in ('fixed', None)]
    links = [l.get('name') for l in root.findall('link')]
    return movable, links


def resolve_mesh(filename, urdf_dir, package_paths):
    if filename.startswith('package://'):
        pkg, _, rel = filename[len('package://'):].partition('/')
        for d in package_paths:
            for cand in (os.path.join(d, pkg, rel), os.path.join(d, rel) if os.path.basename(os.path.normpath(d)) == pkg else None):
                if cand and os.path.isfile(cand):
                    return cand
        return None
    p = filename[len('file://'):] if filename.startswith('file://') else filename
    p = p if os.path.isabs(p) else os.path.join(urdf_dir, p)
    return p if os.path.isfile(p) else None


def embed_meshes(root, urdf_dir, package_paths):
    meshes, missing = {}, []
    for mesh in root.iter('mesh'):
        # <visual> meshes only: the page does not draw collision geometry.
        fn = mesh.get('filename')
        if not fn or fn in meshes or fn in missing:
            continue
        in_visual = any(mesh in list(v.iter('mesh')) for v in root.iter('visual'))
        if not in_visual:
            continue
        p = resolve_mesh(fn, urdf_dir, package_paths)
        if p is None:
            missing.append(fn)
            continue
        with open(p, 'rb') as f:
            meshes[fn] = base64.b64encode(f.read()).decode('ascii')
    return meshes, missing


def num(s):
    v = float(s)
    return v if math.isfinite(v) else None


def rounder(values, digits):
    """Rounds a plotted column to `digits` significant digits of its largest magnitude (so
    1e-20 beside 268.8 becomes 0): plots need no more, and the page stays small."""
    big = max((abs(v) for v in values if v is not None), default=0.0)
    if big == 0.0:
        return lambda v: v
    decimals = digits - 1 - math.floor(math.log10(big))
    def r(v):
        if v is None:
            return None
        x = round(v, decimals)
        return int(x) if decimals <= 0 else (0.0 if x == 0 else x)
    return r


def column(body, i, digits):
    vals = [num(r[i]) for r in body]
    r = rounder(vals, digits)
    return [r(v) for v in vals]


def columns(body, idx, digits):
    cols = [column(body, i, digits) for i in idx]
    return [list(row) for row in zip(*cols)] if cols else []


def read_run(path, name, joint_names_hint, digits):
    with open(path, newline='') as f:
        rows = list(csv.reader(f))
    header, body = rows[0], [r for r in rows[1:] if r]
    col = {h: i for i, h in enumerate(header)}
    qcols = [h for h in header if re.fullmatch(r'q(\d+|_.+)', h)]
    names = [h[2:] if h.startswith('q_') else h for h in qcols]
    if joint_names_hint and all(h.startswith('q') and h[1:].isdigit() for h in qcols):
        names = joint_names_hint[:len(qcols)]          # paper5's q1..q5: the URDF's joints
    ecols = [h for h in header if re.fullmatch(r'eta(\d+|_.+)', h)]
    tcols = [h for h in header if re.fullmatch(r'tau(\d+|_.+)', h)]
    lab = lambda h, p: h[len(p) + 1:] if h.startswith(p + '_') else h
    # q and t as the CSV wrote them (shortest round-trip decimals: the same doubles); the
    # plotted columns rounded, which keeps a 20 s, 100 Hz page well under 3 MB.
    run = {
        'name': name,
        't': [num(r[col['t']]) for r in body],
        'q': [[num(r[col[h]]) for h in qcols] for r in body],
        'columns': {},
        'task': {},
    }
    c = run['columns']
    if 'err' in col:
        c['error'] = column(body, col['err'], digits)
    if tcols:
        c['tau'] = columns(body, [col[h] for h in tcols], digits)
        c['tau_names'] = [lab(h, 'tau') for h in tcols]
    if ecols:
        c['eta'] = columns(body, [col[h] for h in ecols], digits)
        c['eta_names'] = [lab(h, 'eta') for h in ecols]
    # task points: 0.1 um, whatever their size
    for key, task_cols in (('path', ('r_x', 'r_y', 'r_z')), ('reference', ('rd_x', 'rd_y', 'rd_z'))):
        if all(k in col for k in task_cols):
            run['task'][key] = [[None if v is None else round(v, 7) for v in (num(r[col[k]]) for k in task_cols)] for r in body]
    return run, names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('model', help='URDF file or robot file (.json)')
    ap.add_argument('run_dir', nargs='?', help='nhdyn simulate output folder (omit: one pose)')
    ap.add_argument('-o', '--out', required=True, help='HTML file to write')
    ap.add_argument('--template', default=TEMPLATE, help='template (default: dist/template.html)')
    ap.add_argument('--package-path', action='append', default=[], help='folder for package:// meshes (repeatable)')
    ap.add_argument('--q', help='the pose without a run: comma-separated, q order (default zeros)')
    ap.add_argument('--planar', action='store_true', help='q starts with base_x, base_y, base_yaw of a planar base')
    ap.add_argument('--max-runs', type=int, default=40, help='at most this many runs of a study (default 40)')
    ap.add_argument('--digits', type=int, default=6, help='significant digits of the plotted columns (error, tau, eta), relative to each column\'s largest value (default 6)')
    ap.add_argument('--title', help='page title')
    ap.add_argument('--up', help="the world's up, x,y,z (default: -gravity of a robot file, else 0,0,1)")
    ap.add_argument('--task-frame', help='the link carrying the task point r (the test compares its origin with r)')
    a = ap.parse_args()

    urdf_path, base, locked, model_name, up = load_model(a.model)
    if a.up:
        up = [float(v) for v in a.up.split(',')]
    with open(urdf_path, encoding='utf-8') as f:
        urdf_text = f.read()
    root = ET.fromstring(urdf_text)
    movable, links = urdf_joints(root)
    meshes, missing = embed_meshes(root, os.path.dirname(os.path.abspath(urdf_path)), a.package_path)
    for m in missing:
        print(f'make_page.py: mesh not found, the page draws a stand-in: {m}', file=sys.stderr)
    movable = [j for j in movable if j not in locked]

    runs, joint_names = [], None
    if a.run_dir:
        order = []
        sp = os.path.join(a.run_dir, 'summary.json')
        summary = {}
        if os.path.isfile(sp):
            with open(sp) as f:
                for r in json.load(f).get('runs', []):
                    order.append(r['name'])
                    summary[r['name']] = r
        csvs = sorted(f[:-4] for f in os.listdir(a.run_dir) if f.endswith('.csv') and not f.endswith('-bands.csv'))
        names = [n for n in order if n in csvs] + [n for n in csvs if n not in order]
        if not names:
            sys.exit(f'make_page.py: no <run>.csv in {a.run_dir}')
        if len(names) > a.max_runs:
            print(f'make_page.py: {len(names)} runs, the page holds the first {a.max_runs} (--max-runs)', file=sys.stderr)
            names = names[:a.max_runs]
        for n in names:
            run, jn = read_run(os.path.join(a.run_dir, n + '.csv'), n, movable, a.digits)
            if joint_names is None:
                joint_names = jn
            elif jn != joint_names:
                sys.exit(f'make_page.py: run {n} has other q columns than the first run')
            if n in summary:
                run['success'] = bool(summary[n].get('success'))
            runs.append(run)
    else:
        joint_names = (list(PLANAR_NAMES) if (a.planar or (base and base['planar'])) else []) + movable
        q = [float(v) for v in a.q.split(',')] if a.q else [0.0] * len(joint_names)
        if len(q) != len(joint_names):
            sys.exit(f'make_page.py: --q has {len(q)} values, q has {len(joint_names)}: {", ".join(joint_names)}')
        runs.append({'name': 'pose', 't': [0.0], 'q': [q], 'columns': {}, 'task': {}})

    if base is None:
        planar = all(n in joint_names for n in PLANAR_NAMES) and not any(n in movable for n in PLANAR_NAMES)
        base = {'planar': planar, 'joints': list(PLANAR_NAMES) if planar else None}

    data = {
        'version': 1,
        'title': a.title or None,
        'robot': {
            'name': model_name or root.get('name') or os.path.basename(urdf_path),
            'urdf': urdf_text,
            'meshes': meshes,
            'joint_names': joint_names,
            'base': base,
            'locked': locked,
        },
        'runs': runs,
        'link_names_to_report': links,
    }
    if data['title'] is None:
        del data['title']
    if up:
        data['up'] = up
    if a.task_frame:
        for r in runs:
            r['task']['frame'] = a.task_frame
    text = json.dumps(data, separators=(',', ':'), allow_nan=False, ensure_ascii=False)
    # Inside <script>: no '<' at all (no '</script>', no '<!--'), and the JavaScript
    # line terminators U+2028/2029 escaped for older engines.
    text = text.replace('<', '\\u003c').replace('\u2028', '\\u2028').replace('\u2029', '\\u2029')

    with open(a.template, encoding='utf-8') as f:
        tpl = f.read()
    lines = tpl.split('\n')
    idx = [i for i, l in enumerate(lines) if l.strip() == PLACEHOLDER]
    if len(idx) != 1:
        sys.exit(f'make_page.py: {a.template} must hold one line {PLACEHOLDER} (run node build.js)')
    lines[idx[0]] = 'window.NHDYN_DATA = ' + text + ';'
    html = '\n'.join(lines)
    with open(a.out, 'w', encoding='utf-8') as f:
        f.write(html)
    samples = sum(len(r['t']) for r in runs)
    print(f'{a.out}: {len(html.encode()) / 1e6:.2f} MB ({len(runs)} run(s), {samples} samples, '
          f'{len(meshes)} mesh(es) embedded, {len(missing)} missing)')


if __name__ == '__main__':
    main()
