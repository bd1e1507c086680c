# %% [markdown]
# # polepatch in a notebook: analyse, patch, plot the feed ratio along s
#
# Open this file as a notebook (Jupyter with jupytext, VS Code and PyCharm read the `# %%`
# cells) or run it as a script:
#
#     pip install "crates/python[examples]"      # polepatch, numpy, matplotlib
#     python examples/notebook.py [PROGRAM] [MACHINE] [--out FIGURE.png]
#
# The default program is C17's `%SING` (A down to 1°, C sweeping 114°→245° around X = 25)
# on the Mikron UCP710 of G16 Table 2.

# %%
import argparse
import sys
from pathlib import Path

import matplotlib

SCRIPT = __name__ == "__main__" and "ipykernel" not in sys.modules
if SCRIPT:
    matplotlib.use("Agg")  # a script writes the figure to a file
import matplotlib.pyplot as plt
import numpy as np

import polepatch

ROOT = Path(__file__).resolve().parents[1] if "__file__" in globals() else Path.cwd()
parser = argparse.ArgumentParser(description="analyse, patch and plot a program")
parser.add_argument("program", nargs="?", type=Path, default=ROOT / "fixtures/c17/SING.I")
parser.add_argument("machine", nargs="?", default="mikron-ucp710")
parser.add_argument("--out", type=Path, default=Path("feed-ratio.png"))
args = parser.parse_args() if SCRIPT else parser.parse_args([])
PROGRAM, MACHINE, OUT = args.program, args.machine, args.out

data = PROGRAM.read_bytes()
machine = polepatch.Machine.builtin(MACHINE)
print(machine, "limits (mm/s…, °/s…):", machine.limits)

# %% [markdown]
# ## Analyse: Equation 6 along every run
# `analyze_nc` returns the report of `polepatch analyze --json` as a dict.

# %%
analysis = polepatch.analyze_nc(data, machine, name=PROGRAM.name)
for run in analysis["runs"]:
    if "error" in run:
        print(f"run {run['run']} (lines {run['lines']}): not analysed: {run['error']}")
        continue
    print(
        f"run {run['run']} (lines {run['lines'][0]}–{run['lines'][1]}, F{run['feed_mm_min']}): "
        f"min feed ratio {run['min_ratio']:.3f} "
        f"({run['limiting_axis'] or 'the feed'} {run['limiting_limit']}), "
        f"time {run['time_s']:.2f} s against L/F {run['ideal_time_s']:.2f} s"
    )
    for z in run["zones"]:
        print(
            f"  singular zone lines {z['lines'][0]}–{z['lines'][1]} ({z['kind']}), "
            f"min |{analysis['primary']}| {z['min_abs_primary_deg']:.3f}°, C ratio {z['c_ratio_min']:.3f}"
        )

# %% [markdown]
# ## Patch: the rotary words near the pole, the rest of the file byte for byte

# %%
patched, report = polepatch.patch_nc(data, machine, name=PROGRAM.name)
changed = sum(a != b for a, b in zip(data.splitlines(), patched.splitlines()))
print(f"{report['words_changed']} words changed on {changed} lines")
for z in report["zones"]:
    print(
        f"zone lines {z['lines'][0]}–{z['lines'][1]}: {z['outcome']} ({z['method']}), "
        f"C ratio {z['before']['c_ratio']:.3f} → {z['after']['c_ratio']:.3f}, "
        f"time {z['before']['time_s']:.2f} s → {z['after']['time_s']:.2f} s (ideal {z['ideal_time_s']:.2f} s), "
        f"max orientation change {z['max_deviation_deg']:.3f}°"
    )

# %% [markdown]
# ## Plot: the feed ratio along s, before and after
# `feed_profile` samples Equation 6 every F·Tcy mm and at every CL point. The zone is
# shaded; the C-limited ratio is dashed.

# %%
before = polepatch.feed_profile(data, machine)
after = polepatch.feed_profile(patched, machine)
zoned = sorted({z["run"] for z in report["zones"]}) or [
    min(analysis["runs"], key=lambda r: r.get("min_ratio", 2.0))["run"]
]
fig, axes = plt.subplots(len(zoned), 1, figsize=(10, 3.6 * len(zoned)), squeeze=False)
for ax, number in zip(axes[:, 0], zoned):
    b, a = before[number - 1], after[number - 1]
    c = b["axes"].index("C")
    ax.plot(b["s_mm"], b["ratio"], color="tab:red", lw=3, alpha=0.5, label="before")
    ax.plot(b["s_mm"], b["axis_ratio"][:, c], color="tab:red", ls="--", lw=1, label="before, C")
    ax.plot(a["s_mm"], a["ratio"], color="tab:blue", lw=1.2, label="after")
    ax.plot(a["s_mm"], a["axis_ratio"][:, c], color="tab:blue", ls=":", lw=1, label="after, C")
    for z in report["zones"]:
        if z["run"] == number:
            lines = np.array(b["point_lines"])
            s0 = b["point_s_mm"][np.searchsorted(lines, z["lines"][0])]
            s1 = b["point_s_mm"][np.searchsorted(lines, z["lines"][1])]
            ax.axvspan(s0, s1, color="0.9", zorder=0)
    ax.set_ylim(0, 1.05)
    ax.set_xlabel("s along the run, mm")
    ax.set_ylabel("feed ratio (reachable / F)")
    ax.set_title(f"{PROGRAM.name} on {machine.name}, run {number} (F{b['feed_mm_min']})")
    ax.legend(loc="lower left")
fig.tight_layout()
fig.savefig(OUT, dpi=110)
print(f"figure: {OUT}")
