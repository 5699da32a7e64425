#!/usr/bin/env python3
"""Markdown tables of a light-scaling sweep (experiments/sweeps/light-scaling.json): per light
density, frame time (assignment in brackets), peak resident memory against the estimate, and
culling efficiency, per stage and light count. Usage: scaling_tables.py RESULTS_DIR.
The tables in lighting/README.md ("From 10^2 to 10^6 lights") are its output."""
import csv
import sys

STAGES = ['brute', 'tiled', 'tiled:assign=bvh', 'clustered', 'clustered:assign=bvh',
          'clustered-explicit', 'zbinned', 'ideal']
ASSIGNMENT = ['time_clusters_median_ms', 'time_cull_median_ms', 'time_assign_median_ms',
              'time_index_median_ms']


def number(row, key):
    value = row.get(key)
    return float(value) if value not in (None, '') else 0.0


def frame_cell(row):
    assignment = sum(number(row, key) for key in ASSIGNMENT)
    frame = number(row, 'time_stage_median_ms')
    return f'{frame:.1f} ({assignment:.1f})' if assignment > 0 else f'{frame:.1f}'


def memory_cell(row):
    mib = 2.0 ** 20
    return f"{number(row, 'peak_rss_bytes') / mib:.0f} ({number(row, 'memory_estimate_bytes') / mib:.0f})"


def efficiency_cell(row):
    return f"{number(row, 'culling_efficiency'):.3f}"


def table(rows, density, title, cell):
    counts = sorted({int(r['lights']) for r in rows if r['light-density'] == density})
    print(f'\n{density}: {title}\n')
    print('| stage | ' + ' | '.join(f'{c:,}' for c in counts) + ' |')
    print('|---|' + '---:|' * len(counts))
    for stage in STAGES:
        cells = []
        for count in counts:
            found = [r for r in rows if r['light-density'] == density and r['stage'] == stage
                     and int(r['lights']) == count and r['status'] == 'ok']
            cells.append(cell(found[0]) if found else '–')
        print(f'| `{stage}` | ' + ' | '.join(cells) + ' |')


def main():
    with open(sys.argv[1] + '/results.csv', newline='') as f:
        rows = list(csv.DictReader(f))
    for density in ['constant-overlap', 'fixed']:
        table(rows, density, 'assignment + shading ms (assignment in brackets), median of 3 after '
              '1 warm-up', frame_cell)
        table(rows, density, "peak resident MiB of the job's render (estimate in brackets)",
              memory_cell)
        table(rows, density, 'culling efficiency (oracle / evaluated)', efficiency_cell)


if __name__ == '__main__':
    main()
