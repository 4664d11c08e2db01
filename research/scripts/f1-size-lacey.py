#!/usr/bin/python3
"""Lacey's index of a bed of two sizes read three ways, from checkpoints (F1's size pair; research/f1-size-lacey).

Usage: /usr/bin/python3 research/scripts/f1-size-lacey.py CHECKPOINT.h5 [...]

Each particle gives one sample: itself and its 10 nearest others (no periodic wrap, as granflow's reducer). Species 0
is the kind A whose concentration is taken. Printed per checkpoint:
  product:  volume concentrations, samples weighted equally, sigma0^2 = P(1-P) with P A's volume fraction
            (granflow's `lacey_index`, seed 000 eq. 2.80 as implemented);
  count:    number concentrations, samples weighted equally, P A's number fraction;
  volume:   volume concentrations, each sample weighted by its centre particle's volume, P A's volume fraction.
"""
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

K = 10


def lacey(c, w, p, n):
    w = w / w.sum()
    mean = (w * c).sum()
    var = (w * (c - mean) ** 2).sum() * n / (n - 1)
    s0 = p * (1 - p)
    sr = s0 / n
    return (s0 - var) / (s0 - sr), np.sqrt(var)


for path in sys.argv[1:]:
    with h5py.File(path, "r") as f:
        x = f["/particles/position_m"][...]
        r = f["/particles/radius_m"][...]
        a = f["/particles/species"][...] == 0
    v = r**3
    _, idx = cKDTree(x).query(x, k=K + 1)
    c_vol = (v[idx] * a[idx]).sum(1) / v[idx].sum(1)
    c_num = a[idx].mean(1)
    n = len(x)
    p_vol = v[a].sum() / v.sum()
    p_num = a.mean()
    rows = {
        "product": lacey(c_vol, np.ones(n), p_vol, n),
        "count": lacey(c_num, np.ones(n), p_num, n),
        "volume": lacey(c_vol, v, p_vol, n),
    }
    print(path, f"N={n} A={a.sum()} P_vol={p_vol:.3f} P_num={p_num:.3f}",
          " ".join(f"{k}: M={m:.3f} IS={s:.3f}" for k, (m, s) in rows.items()))
