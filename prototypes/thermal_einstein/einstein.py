import sys, numpy as np, h5py
KB=1.380649e-16*1e16
def cen(run):
    with h5py.File(run+"/trajectory.h5md","r") as f:
        g=f["particles"]; n=list(g.keys())[0]
        p=g[n]["position"]["value"][:]; t=g[n]["position"]["time"][:]
        u=g[n]["position"]["time"].attrs.get("unit")
    u=u.decode() if isinstance(u,bytes) else str(u)
    return t*{"ns":1e-9,"us":1e-6,"µs":1e-6,"s":1.0}[u], p.mean(axis=1), p
def mob(run,d,F=10.0,skip=5):
    t,c,_=cen(run); return np.polyfit(t[skip:],c[skip:,d],1)[0]/F
px,pz=sys.argv[1],sys.argv[2]
mx,mz=mob(px,0),mob(pz,2); kT=KB*300
Dp=kT*(2*mx+mz)/3*1e-9
print(f"mob x {mx:.4g} z {mz:.4g} s/g; kT M = {Dp:.4g} A^2/ns")
lags=[int(x) for x in sys.argv[3].split(",")]
for run in sys.argv[4:]:
    t,c,p=cen(run); dt=t[1]-t[0]; skip=int(round(1e-7/dt))
    c=c[skip:]
    out=[]
    for lag in lags:
        m=(len(c)-1)//lag
        dc=c[lag:m*lag+1:lag]-c[0:(m-1)*lag+1:lag]
        s=(dc**2).sum(1)/(6*lag*dt)*1e-9/Dp
        out.append(f"{lag*dt*1e9:g}ns {s.mean():.3f}±{s.std(ddof=1)/np.sqrt(len(s)):.3f}(n{len(s)})")
    print(run, f"T={t[-1]*1e6:.1f}us", " ".join(out))
