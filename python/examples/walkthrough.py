# %% [markdown]
# # crr from Python: a block, a record, and a small fragility study on a Dask cluster
#
# Run it as a script (`python python/examples/walkthrough.py`; the figures go to
# `results/python_walkthrough/` of the repository, or to `$CRR_EXAMPLE_OUT`), or cell by cell (`# %%`) in VS Code, Spyder or
# Jupyter with jupytext. Needs `pip install ./python matplotlib "dask[distributed]" pandas`.

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:
    matplotlib.use("Agg")  # files only, when run as a script
import matplotlib.pyplot as plt
import numpy as np

import crr

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
OUT = Path(os.environ.get("CRR_EXAMPLE_OUT", ROOT / "results" / "python_walkthrough"))
OUT.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The model: Housner's block (0.4 × 0.4 × 2 m)
# `check()` is `crr check --json`: the activation multiplier λ (= tan α for a block), the
# equivalent block's slenderness α_eq (rad) and frequency parameter p_eq (rad/s).

# %%
model = crr.Model.from_file(ROOT / "examples/models/single_block.toml")
report = model.check()
mechanism = report["mechanism"]
alpha = mechanism["alpha_eq"]
print(model.name, model.coordinates, "λ =", mechanism["lambda"], "α =", alpha, "rad,",
      "p =", mechanism["p_eq"], "rad/s")

# %% [markdown]
# ## A record: the bundled synthetic accelerogram (PEER .AT2, in g), scaled by 1.5

# %%
record = crr.Record.from_file(
    ROOT / "examples/records/synthetic.AT2", format="peer-at2", scale=1.5
)
result = crr.simulate(model, ground_motion=record, duration=25.0)
theta = result.q[:, 0]
print(result)
print("peak |θ|/α =", result.summary["coordinates"][0]["peak_over_alpha"])
impacts = result.impacts_frame()
print(impacts.head())

# %% [markdown]
# ## θ/α against time, impacts marked

# %%
fig, ax = plt.subplots(figsize=(8, 3))
ax.plot(result.t, theta / alpha, lw=0.8, label="θ/α")
ax.plot(impacts["t"], np.zeros(len(impacts)), "|", color="k", ms=8, label="impacts")
ax.axhline(1.0, color="r", ls=":", lw=0.8)
ax.axhline(-1.0, color="r", ls=":", lw=0.8)
ax.set_xlabel("t (s)")
ax.set_ylabel("θ/α")
ax.legend(loc="upper right")
fig.tight_layout()
fig.savefig(OUT / "theta_over_alpha.png", dpi=120)

# %% [markdown]
# ## The same record as arrays (any source: numpy, pandas, obspy …)
# Times in s, accelerations in m/s² (or `units="g"`, `"cm/s2"`); the record drives `x`.

# %%
t = np.arange(0.0, 4.0, 0.005)
a = 3.0 * np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.6 * t)  # m/s²
pulse = crr.simulate(model, ground_motion=(t, a), duration=8.0)
print("decaying sine:", pulse.summary["impacts"], "impacts, collapse:",
      pulse.summary["collapse"]["collapsed"])

# %% [markdown]
# ## A small fragility study on a Dask LocalCluster
# Five synthetic records (seeds 1–5) scaled to six PGA levels on the block: 30 cases. The
# workers here are threads of this process (`processes=False`): crr releases the GIL, so they
# run in parallel, and a script of cells needs no `if __name__ == "__main__"` guard (worker
# processes would re-import it). On a real cluster only the cluster line changes (see
# python/README.md: dask-jobqueue's SLURMCluster); the cases.csv is the same as `crr study`'s.

# %%
from distributed import Client, LocalCluster

import crr.dask

study = {
    "name": "block_fragility",
    "model": str(ROOT / "examples/models/single_block.toml"),
    "duration": 25.0,
    "records": {"synthetic": {"seeds": {"from": 1, "to": 5, "count": 5}}},
    "intensity": {"pga": {"from": 0.05, "to": 0.4, "count": 6}},
}
with LocalCluster(
    n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
) as cluster, Client(cluster) as client:
    cases = crr.dask.run_study(study, client, chunk_size=5, out=OUT / "fragility")
print(cases[["id", "record", "pga_g", "collapse", "peak_base_over_alpha"]].head(8))
fraction = cases.groupby("pga_g")["collapse"].mean()
print(fraction)

# %%
fig, ax = plt.subplots(figsize=(5, 3))
ax.plot(fraction.index.to_numpy(), fraction.to_numpy(), "o-")
ax.set_xlabel("PGA (g)")
ax.set_ylabel("fraction overturned")
ax.set_ylim(-0.05, 1.05)
fig.tight_layout()
fig.savefig(OUT / "fragility.png", dpi=120)
print("figures in", OUT)
