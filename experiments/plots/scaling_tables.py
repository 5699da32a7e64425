#!/usr/bin/env python3
"""Markdown tables of a light-scaling sweep (experiments/sweeps/light-scaling.json): per light
density, frame time (assignment in brackets), peak resident memory against the estimate, and
culling efficiency, per stage and light count. Usage: scaling_tables.py RESULTS_DIR.
The tables in lighting/README.md ("From 10^2 to 10^6 lights") are its output."""
import csv,sys
rows=list(csv.DictReader(open(sys.argv[1]+'/results.csv')))
def f(r,k):
    v=r.get(k); return float(v) if v not in (None,'') else None
stages=['brute','tiled','tiled:assign=bvh','clustered','clustered:assign=bvh','clustered-explicit','zbinned','ideal']
for dens in ['constant-overlap','fixed']:
    counts=sorted({int(r['lights']) for r in rows if r['light-density']==dens})
    print(f"\n{dens}: assignment + shading ms (assignment in brackets), median of 3 after 1 warm-up\n")
    print('| stage | '+' | '.join(f'{c:,}' for c in counts)+' |')
    print('|---|'+'---:|'*len(counts))
    for s in stages:
        cells=[]
        for c in counts:
            rr=[r for r in rows if r['light-density']==dens and r['stage']==s and int(r['lights'])==c]
            if not rr or rr[0]['status']!='ok': cells.append('–'); continue
            r=rr[0]
            a=sum(f(r,k) or 0 for k in ['time_clusters_median_ms','time_cull_median_ms','time_assign_median_ms','time_index_median_ms'])
            st=f(r,'time_stage_median_ms')
            cells.append(f'{st:.1f} ({a:.1f})' if a>0 else f'{st:.1f}')
        print(f'| `{s}` | '+' | '.join(cells)+' |')
    # memory
    print(f"\n{dens}: peak resident MiB of the job's render (estimate in brackets)\n")
    print('| stage | '+' | '.join(f'{c:,}' for c in counts)+' |')
    print('|---|'+'---:|'*len(counts))
    for s in stages:
        cells=[]
        for c in counts:
            rr=[r for r in rows if r['light-density']==dens and r['stage']==s and int(r['lights'])==c]
            if not rr or rr[0]['status']!='ok': cells.append('–'); continue
            r=rr[0]
            cells.append(f"{f(r,'peak_rss_bytes')/2**20:.0f} ({f(r,'memory_estimate_bytes')/2**20:.0f})")
        print(f'| `{s}` | '+' | '.join(cells)+' |')
    print(f"\n{dens}: culling efficiency (oracle / evaluated)\n")
    print('| stage | '+' | '.join(f'{c:,}' for c in counts)+' |')
    print('|---|'+'---:|'*len(counts))
    for s in stages:
        cells=[]
        for c in counts:
            rr=[r for r in rows if r['light-density']==dens and r['stage']==s and int(r['lights'])==c]
            if not rr or rr[0]['status']!='ok': cells.append('–'); continue
            cells.append(f"{f(rr[0],'culling_efficiency'):.3f}")
        print(f'| `{s}` | '+' | '.join(cells)+' |')
