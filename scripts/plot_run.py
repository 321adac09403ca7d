#!/usr/bin/python3
"""Draws a run's stats.csv into one PNG: kinetic and strain energy, broken bonds, the largest
theta and speed, and the time step, each against simulated time.

    scripts/plot_run.py OUT_DIR [--out PNG]     (default: OUT_DIR/stats.png)

OUT_DIR is a rend run's output folder (stats.csv.partial is read while the run goes on).
"""

import argparse
import csv
import os
import sys

COLUMNS = ["time", "kinetic_energy", "strain_energy", "broken_bonds", "max_theta", "max_speed"]


def read_stats(folder):
    """The columns of stats.csv (else stats.csv.partial) as lists of floats."""
    for name in ("stats.csv", "stats.csv.partial"):
        path = os.path.join(folder, name)
        if os.path.exists(path):
            break
    else:
        raise SystemExit(f"error: {folder} holds no stats.csv: expected the output folder of "
                         "rend run (with [output] stats = true)")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    missing = [c for c in COLUMNS if rows and c not in rows[0]]
    if not rows or missing:
        raise SystemExit(f"error: {path}: expected rend's stats.csv with the columns "
                         f"{', '.join(COLUMNS)}; found {'no rows' if not rows else 'no ' + ', '.join(missing)}")
    keys = COLUMNS + (["dt"] if "dt" in rows[0] else [])
    try:
        return path, {key: [float(r[key]) for r in rows] for key in keys}
    except (TypeError, ValueError) as e:
        raise SystemExit(f"error: {path}: a value is not a number ({e})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--out")
    args = parser.parse_args()
    path, stats = read_stats(args.folder)
    try:
        import matplotlib
    except ImportError:
        print("error: matplotlib is missing. Install it from Debian:\n"
              "    apt-get install python3-matplotlib", file=sys.stderr)
        return 1
    matplotlib.use("Agg")  # headless
    import matplotlib.pyplot as plt

    t = stats["time"]
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    energy, broken, fields, step = axes.flat
    for key, label in (("kinetic_energy", "kinetic"), ("strain_energy", "strain")):
        energy.semilogy(t, [max(v, 1e-30) for v in stats[key]], label=label)
    energy.set_ylabel("energy [J]")
    energy.legend(fontsize=8)
    broken.plot(t, stats["broken_bonds"], color="tab:red")
    broken.set_ylabel("broken bonds")
    fields.plot(t, stats["max_speed"], label="largest speed [m/s]")
    fields.plot(t, stats["max_theta"], label="largest theta")
    fields.legend(fontsize=8)
    if "dt" in stats:
        step.semilogy(t, stats["dt"], color="tab:green")
        step.set_ylabel("time step, a frame's last [s]")
    else:
        step.text(0.5, 0.5, "no dt column (a run before rend 0.1.0's stats.csv had one)",
                  ha="center", va="center", transform=step.transAxes, fontsize=8)
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("simulated time [s]")
    fig.suptitle(os.path.abspath(args.folder), fontsize=9)
    fig.tight_layout()
    out = args.out or os.path.join(args.folder, "stats.png")
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, out)  # whole or absent
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
