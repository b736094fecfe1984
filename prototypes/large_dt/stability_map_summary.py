#!/usr/bin/env python3
"""Summarises the run directories of stability_map.sh (DIR, default /tmp/smap): per run, the end
time, steps, stop reason, blow-up, link drift, the largest rise of the potential energy between
rows, the final writhe and potential energy, the closest approach."""
import csv, glob, json, os, sys
D = sys.argv[1] if len(sys.argv) > 1 else "/tmp/smap"
for d in sorted(glob.glob(D + '/*_dlk*')):
    if not os.path.isdir(d): continue
    name=os.path.basename(d)
    ts=os.path.join(d,'timeseries.csv')
    if not os.path.exists(ts): continue
    r=list(csv.DictReader(open(ts)))
    if not r: continue
    t=[float(x['time_us']) for x in r]; E=[float(x['E_total_kT'])-float(x['E_kinetic_kT']) for x in r]
    lk=[float(x['link']) for x in r]; wr=[float(x['writhe']) for x in r]; ca=[float(x['closest_approach_A']) for x in r]
    rise=max([0]+[E[i]-E[i-1] for i in range(1,len(E))])
    summ={}
    try: summ=json.load(open(os.path.join(d,'summary.json')))
    except Exception: pass
    log=open(d+'.log').read()
    blow='blow-up' in log
    print(f"{name:22s} t_end={t[-1]:.3f} steps={r[-1]['step']:>6s} stop={summ.get('stop_reason','?'):10s} blowup={blow} |dLk|max={max(abs(x-lk[0]) for x in lk):.1e} maxrise(Epot)={rise:.3g} Wr={wr[-1]:.3f} Epot={E[-1]:.2f} dmin={min(ca):.1f}")
