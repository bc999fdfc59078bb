#!/usr/bin/env python3
"""Draws the efficiency / whole-frame-time frontier from scripts/frontier.sh's results.

usage: frontier_plot.py OUT [PEERS_SUMMARY_MD]

OUT holds `homcull bench --workload frame --json` outputs named <config>_castle.passN.json (the
views of data/views/castle.json) and <config>_random.passN.json (random viewpoints), one per pass
(frontier.sh alternates the configurations' order from pass to pass); a view's frame time is
its median over the passes (names without .passN, from older runs, are one pass). PEERS_SUMMARY_MD is a
../shared/peers/measure.sh summary.md: its per-view whole-frame tables give the peers' points
(Intel MOC, rawrunprotected), scored by the peers' summarize.py over every hidden object.
Writes OUT/frontier.png (a panel per castle view, one for the random views) and OUT/frontier.md
(the same figures as a table). Efficiency is plotted over every hidden object, the basis the
peers are scored on; the table gives homcull's over the objects hidden outright beside it.
"""
import glob
import json
import os
import re
import statistics
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def pareto(points):
    """The points no other point beats on both time (lower) and efficiency (higher), by time."""
    front, best = [], -1.0
    for ms, eff in sorted(points):
        if eff > best:
            front.append((ms, eff))
            best = eff
    return front


def merge_passes(docs):
    """One bench output from the passes' outputs of one configuration: each view's frame time
    is its median over the passes (its stages', too), the summary's times recomputed from them.
    Every pass answers the same (the culler is deterministic): a pass that does not is an error."""
    merged = json.loads(json.dumps(docs[0]))
    for v, view in enumerate(merged['per_view']):
        for d in docs[1:]:
            other = d['per_view'][v]
            if (other['culled_hidden'], other['false_culls']) != (view['culled_hidden'], view['false_culls']):
                sys.exit('frontier_plot.py: the passes of %s answer view %d differently' % (merged['config'], v))
        view['frame_ms'] = statistics.median(d['per_view'][v]['frame_ms'] for d in docs)
        view['frame_min_ms'] = min(d['per_view'][v]['frame_min_ms'] for d in docs)
        for stage in view['stages_ms']:
            view['stages_ms'][stage] = statistics.median(d['per_view'][v]['stages_ms'][stage] for d in docs)
    times = [v['frame_ms'] for v in merged['per_view']]
    merged['summary']['frame_ms'] = {'mean': statistics.mean(times), 'median': statistics.median(times), 'max': max(times)}
    merged['summary']['stages_ms_mean'] = {
        stage: statistics.mean(v['stages_ms'][stage] for v in merged['per_view']) for stage in merged['per_view'][0]['stages_ms']}
    for v, view in enumerate(merged['per_view']):
        view['frame_ms_passes'] = [d['per_view'][v]['frame_ms'] for d in docs]
    merged['summary']['frame_ms_passes'] = [statistics.mean(v['frame_ms'] for v in d['per_view']) for d in docs]
    merged['passes'] = len(docs)
    merged['rounds'] = sum(d['rounds'] for d in docs)
    return merged


def load_homcull(out):
    """{config: {'castle': json, 'random': json}} from OUT's bench outputs, passes merged."""
    runs = {}
    name = re.compile(r'^(.*)_(castle|random)(\.pass\d+)?\.json$')
    for path in sorted(glob.glob(os.path.join(out, '*.json'))):
        m = name.match(os.path.basename(path))
        if not m:
            continue
        with open(path) as f:
            doc = json.load(f)
        runs.setdefault((m.group(1), m.group(2)), []).append(doc)
    points = {}
    for (_, kind), docs in sorted(runs.items()):
        doc = merge_passes(docs)
        c = doc['config']
        defaults = doc.get('defaults')
        if defaults is None:
            sys.exit('frontier_plot.py: %s has no "defaults" (a bench older than this script): rerun frontier.sh' % kind)
        changed = {key for key, value in c.items() if defaults.get(key) != value}
        label = ('boxes' if c['occludees'] == 'box' else 'triangles') + (', clusters' if c['clusters'] == 'on' else '')
        changed -= {'occludees', 'clusters'}
        # The options frontier.sh varies, in words; any other that differs from the defaults by its name.
        if 'occludee_parts' in changed:
            parts = c['occludee_parts']
            label += ', ' + (f'{parts} parts' if parts > 1 else 'no parts')
        if 'back_faces' in changed:
            label += f", back faces {'culled' if c['back_faces'] == 'cull' else c['back_faces']}"
        if changed & {'occluders', 'complexity'}:
            label += f", {c['occluders']} occluders" + (f" at complexity {c['complexity']:g}" if 'complexity' in changed else '')
        if 'min_occluder_size' in changed:
            label += f", those at least {c['min_occluder_size']:g} sr"
        for key in sorted(changed - {'occludee_parts', 'back_faces', 'occluders', 'complexity', 'min_occluder_size'}):
            label += f', {key} {c[key]}'
        if kind in points.get(label, {}):  # one would hide the other in the plot and the table
            sys.exit(f'frontier_plot.py: two configurations are both named "{label}"; name what tells them apart in load_homcull')
        points.setdefault(label, {})[kind] = doc
    return points


def load_peers(summary):
    """{label: [(frame_ms, efficiency %), ...] per castle view} from a measure.sh summary.md."""
    peers, label = {}, None
    row = re.compile(r'^\| C(\d+) \| [^|]* \| ([0-9.]+) \[[0-9.]+\] \| [^|]* \| ([0-9.]+) % ')
    with open(summary) as f:
        for line in f:
            if line.startswith('### '):
                label = line[4:].strip()
                continue
            m = row.match(line)
            if label and m and not label.startswith('homcull'):
                peers.setdefault(label, []).append((float(m.group(2)), float(m.group(3))))
    return peers


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    out = sys.argv[1]
    homcull = load_homcull(out)
    if not homcull:
        sys.exit('frontier_plot.py: no <config>_castle[.passN].json or <config>_random[.passN].json in ' + out)
    peers = load_peers(sys.argv[2]) if len(sys.argv) == 3 else {}
    views = max(len(d['castle']['per_view']) for d in homcull.values() if 'castle' in d)
    has_random = any('random' in d for d in homcull.values())
    panels = views + (1 if has_random else 0)
    columns = min(3, panels)
    rows = (panels + columns - 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.4 * rows + 1.0), sharey=True, squeeze=False)
    markers = 'osD^vP*Xh<>p'  # one per configuration: a repeated marker would merge two in the plot
    for p in range(rows * columns):
        ax = axes[p // columns][p % columns]
        if p >= panels:
            ax.axis('off')
            continue
        random_panel = has_random and p == views
        mine = []
        for k, (label, docs) in enumerate(sorted(homcull.items())):
            if random_panel and 'random' in docs:
                s = docs['random']['summary']
                point = (s['frame_ms']['mean'], 100 * s['efficiency_plain'])
            elif not random_panel and 'castle' in docs:
                v = docs['castle']['per_view'][p]
                point = (v['frame_ms'], 100 * v['efficiency_plain'])
            else:
                continue
            mine.append(point)
            ax.plot(*point, markers[k % len(markers)], color='C0', label='homcull ' + label)
        front = pareto(mine)
        ax.step([f[0] for f in front], [f[1] for f in front], where='post', color='C0', alpha=0.4, label='homcull frontier')
        if not random_panel:
            for k, (label, per_view) in enumerate(sorted(peers.items())):
                if p < len(per_view):
                    color = 'C1' if label.startswith('MOC') else 'C2'
                    ax.plot(per_view[p][0], per_view[p][1], markers[k % len(markers)], color=color, mfc='none', label=label)
        ax.set_xlim(left=0)
        ax.set_title('random views (mean)' if random_panel else 'castle C%d' % p)
        ax.set_xlabel('whole frame, ms (one thread)')
        ax.grid(True, which='both', alpha=0.3)
    for r in range(rows):
        axes[r][0].set_ylabel('efficiency, % of hidden objects culled')
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc='lower center', ncol=3, fontsize='small', frameon=False)
    fig.tight_layout(rect=(0, 0.8 / (3.4 * rows + 1.0) + 0.04, 1, 1))
    fig.savefig(os.path.join(out, 'frontier.png'), dpi=110)

    with open(os.path.join(out, 'frontier.md'), 'w') as f:
        some = next(iter(next(iter(homcull.values())).values()))
        f.write('homcull: each view\'s whole frame is its median over %d pass(es) of %d rounds in all, the configurations\' order '
                'alternating from pass to pass.\n\n' % (some.get('passes', 1), some['rounds']))
        f.write('| culler | view | frame ms | passes\' range | efficiency, hidden outright | efficiency, all hidden | '
                'the occluders\' bound | false culls |\n')
        f.write('|---|---|---|---|---|---|---|---|\n')
        for label, docs in sorted(homcull.items()):
            for kind in ('castle', 'random'):
                if kind not in docs:
                    continue
                doc = docs[kind]
                rows = [('C%d' % v['view'], v) for v in doc['per_view']] if kind == 'castle' else []
                s = doc['summary']
                rows.append(('%s, mean of %d' % (kind, s['views']), dict(s, frame_ms=s['frame_ms']['mean'], frame_ms_passes=s['frame_ms_passes'])))
                for name, v in rows:
                    # The share of the objects hidden outright that the occluders drawn hide at every
                    # pixel centre (bench's occluder_bound): no culler drawing them culls more.
                    bound = '%.1f %%' % (100 * v['occluder_bound']['efficiency_bound']) if 'occluder_bound' in v else ''
                    f.write('| homcull %s | %s | %.3f | %.3f-%.3f | %.1f %% | %.1f %% | %s | %d |\n' % (
                        label, name, v['frame_ms'], min(v['frame_ms_passes']), max(v['frame_ms_passes']), 100 * v['efficiency'],
                        100 * v['efficiency_plain'], bound, v['false_culls']))
        for label, per_view in sorted(peers.items()):
            for v, (ms, eff) in enumerate(per_view):
                f.write('| %s | C%d | %.3f | | | %.1f %% | | |\n' % (label, v, ms, eff))
    print('frontier_plot.py: wrote %s and %s' % (os.path.join(out, 'frontier.png'), os.path.join(out, 'frontier.md')))


if __name__ == '__main__':
    main()
