# ruff: noqa: E741, E501
"""Round-trip statistics quoted in docs/kotter.md (run: python tests/data/kotter_roundtrip_stats.py)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import kotter_ref as ref
import manakov
import numpy as np

T=np.linspace(0,20,81)
for name in manakov.problem_names():
    p=manakov.problem(name); X=ref.trajectory(p.a,p.b,p.l0,T)
    k=manakov.kotter(p.a,p.b,X); back=manakov.from_kotter(p.a,p.b,k)
    err=np.max(np.abs(back-X),axis=-1)/np.max(np.abs(X),axis=-1)
    q3=np.max(np.abs(np.sum(k.d*k.xi**2+k.eta**2/k.d,-1)))
    print(f"{name:16s} max {err.max():.1e} median {np.median(err):.1e}  |Q3| max {q3:.1e}  d = {np.round(k.d[0],4)}")
