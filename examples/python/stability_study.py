#!/usr/bin/env python3
"""A stability study in Python, notebook style: each `# %%` is a cell
(VS Code, Jupyter's jupytext and Spyder run them one by one).

What it does: loads the demo job (examples/demo.yaml: a 24 mm two-flute end
mill on a KR 300-class robot), computes its stability lobe diagram, then
sweeps the radial depth of cut with overrides (the Python form of
`robomill stability --set process.ae=...`) and compares the diagrams:
the narrower the cut, the deeper it may go before it chatters.

Run it from the repository root after building:

    PYTHONPATH=build/python python3 examples/python/stability_study.py

With matplotlib installed it also saves stability_study.png.
"""

# %% Imports: the module is built into build/python (docs/python.md).
import pathlib
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "build" / "python"))  # when PYTHONPATH is not set
import robomill  # noqa: E402

# %% Load the job. Every field can be overridden as with --set; here fewer
# speeds than the job's 400, so the sweep below takes a few seconds.
job = robomill.Job(ROOT / "examples" / "demo.yaml",
                   overrides={"stability.speeds.count": 120})
print(job, "sections:", ", ".join(job.validate()))

# %% The diagram: a dict with the summary (summary.json) and the tables
# (sld.csv, sld_envelope.csv) as NumPy arrays.
result = robomill.stability(job)
summary, sld = result["summary"], result["sld"]
print(result["message"], end="")
print(f"weakest speed {summary['min_limit_spindle_rpm']:.0f} rpm: "
      f"{summary['min_limit_mm']:.3f} mm; best {summary['max_limit_mm']:.3f} mm")

# %% The best speed inside the robot's usable range, and the safe depth there.
speeds, limits = sld["spindle_rpm"], sld["depth_limit_mm"]
usable = (speeds >= 500) & (speeds <= 4000)
best = np.argmax(np.where(usable, limits, -np.inf))
print(f"best usable speed {speeds[best]:.0f} rpm: stable up to {limits[best]:.3f} mm "
      f"(chatter at {sld['chatter_freq_hz'][best]:.1f} Hz beyond)")

# %% Sweep the radial depth: one override per run, the job itself unchanged.
widths_mm = [1, 2, 4, 8, 12]
diagrams = {}
for ae in widths_mm:
    run = robomill.stability(job.with_overrides({"process.ae": f"{ae} mm"}))
    diagrams[ae] = run["sld"]
    s = run["summary"]
    print(f"ae = {ae:4.1f} mm: minimum limit {s['min_limit_mm']:7.3f} mm "
          f"at {s['min_limit_spindle_rpm']:6.0f} rpm, maximum {s['max_limit_mm']:7.3f} mm")

# %% Errors say what is wrong, as on the command line.
try:
    job.with_overrides({"process.ae": "30 mm"})  # wider than the 24 mm tool
except robomill.InputError as error:
    print(f"rejected: {error}")

# %% Plot (only when matplotlib is installed).
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no plot")
else:
    figure, axes = plt.subplots(figsize=(8, 4.5))
    for ae, table in diagrams.items():
        axes.plot(table["spindle_rpm"], table["depth_limit_mm"], label=f"ae = {ae} mm")
    axes.set_xlabel("spindle speed (rpm)")
    axes.set_ylabel("limiting axial depth (mm)")
    axes.set_yscale("log")
    axes.legend()
    axes.set_title("demo.yaml: stability lobes over the radial depth")
    figure.tight_layout()
    figure.savefig("stability_study.png", dpi=120)
    print("plot: stability_study.png")
