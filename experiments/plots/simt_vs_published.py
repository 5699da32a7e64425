#!/usr/bin/env python3
"""The SIMT cost model against the seeds' published ratios (issue 14, section 3).

Reads a reproduction sweep's file (experiments/sweeps/) and its results.csv, and prints a
Markdown table: published time ratio, modelled ratio (simt_lane_slots), measured CPU time
ratios and the light-evaluation ratio, side by side.

  thesis-tiled-backface: tiled / tiled-backface per Test 1-4 (both vfc blocks)
  ortegren-clustered:    no clustering (brute) / clustered per grid, and brute / ideal

usage: simt_vs_published.py SWEEP.json RESULTS.csv
"""
import csv
import json
import sys


def ok_rows(path):
    return [r for r in csv.DictReader(open(path)) if r['status'] == 'ok']


def pick(rows, **select):
    found = [r for r in rows if all(str(r.get(k)) == str(v) for k, v in select.items())]
    if len(found) != 1:
        raise SystemExit('expected one row for %s, found %d' % (select, len(found)))
    return found[0]


def value(row, key):
    return float(row[key]) if row.get(key) not in ('', None) else float('nan')


def ratio(a, b, key):
    return value(a, key) / value(b, key)


def thesis(sweep, rows):
    print('| test | vfc | published tiled / tiled-backface (frame time) | modelled: SIMT lane slots '
          '| measured: shading time | measured: frame time | light evaluations |')
    print('|---|---|---|---|---|---|---|')
    for block in sweep['published']:
        labels = [c['label'] for c in block['columns']]
        tiled, backface = labels.index('tiled'), labels.index('tiled-backface')
        stages = {r['stage'] for r in rows}
        if not {block['columns'][i]['select']['stage'] for i in (tiled, backface)} <= stages:
            continue  # a sweep run with fewer stages (e.g. culling on only)
        for row in block['rows']:
            select = dict(row['select'])
            t = pick(rows, stage=block['columns'][tiled]['select']['stage'], **select)
            b = pick(rows, stage=block['columns'][backface]['select']['stage'], **select)
            vfc = block['columns'][tiled]['select']['stage'].split('vfc=')[-1]
            print('| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f |' % (
                row['label'], vfc, row['values'][tiled] / row['values'][backface],
                ratio(t, b, 'simt_lane_slots'), ratio(t, b, 'time_shading_median_ms'),
                ratio(t, b, 'time_total_median_ms'), ratio(t, b, 'light_evaluations')))


def ortegren(sweep, rows):
    shading = next(b for b in sweep['published'] if b['metric'] == 'time_shading_median_ms')
    total = next(b for b in sweep['published'] if b['metric'] == 'time_stage_median_ms')
    labels = [c['label'] for c in shading['columns']]
    brute_column = labels.index('no clustering')
    print('| lights | grid | published brute / clustered: shading | published: assign + shading '
          '| modelled: SIMT lane slots | measured: shading | measured: assign + shading '
          '| simt_efficiency |')
    print('|---|---|---|---|---|---|---|---|')
    for r, row in enumerate(shading['rows']):
        select = dict(row['select'])
        brute = pick(rows, stage='brute', **select)
        for c, column in enumerate(shading['columns']):
            if c == brute_column:
                continue
            stage = column['select']['stage']
            s = pick(rows, stage=stage, **select)
            published = row['values'][c]
            published_total = total['rows'][r]['values'][c] if c < len(total['rows'][r]['values']) else None
            print('| %s | %s | %s | %s | %.1f | %.1f | %s | %.3f |' % (
                select.get('lights'), column['label'],
                '%.1f' % (row['values'][brute_column] / published) if published else '—',
                '%.1f' % (total['rows'][r]['values'][brute_column] / published_total) if published_total else '—',
                ratio(brute, s, 'simt_lane_slots'), ratio(brute, s, 'time_shading_median_ms'),
                '%.1f' % ratio(brute, s, 'time_stage_median_ms') if stage != 'ideal' else '—',
                value(s, 'simt_efficiency')))


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    sweep = json.load(open(sys.argv[1]))
    rows = ok_rows(sys.argv[2])
    if sweep['name'].startswith('thesis'):
        thesis(sweep, rows)
    elif sweep['name'].startswith('ortegren'):
        ortegren(sweep, rows)
    else:
        raise SystemExit('no SIMT comparison for sweep ' + sweep['name'])


if __name__ == '__main__':
    main()
