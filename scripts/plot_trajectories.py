#!/usr/bin/env python3
"""Draws bench_trajectories' CSV as the membrane paper's Fig. 9: the XY trajectories of P1 and
P2, one line per solver, into one PNG (matplotlib from Debian's python3-matplotlib)."""
import argparse
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("csv", nargs="?", default="out/trajectories.csv")
    parser.add_argument("--out", default="out/trajectories.png")
    args = parser.parse_args()
    tracks = defaultdict(lambda: defaultdict(list))
    try:
        with open(args.csv, newline="") as f:
            for row in csv.DictReader(f):
                for key in ("p1_x", "p1_y", "p2_x", "p2_y"):
                    tracks[row["solver"]][key].append(float(row[key]))
    except (OSError, KeyError, ValueError) as error:
        sys.exit(f"{args.csv}: error: {error}. Run build/bench_trajectories {args.csv} first.")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, point, name in ((axes[0], "p1", "P1 (0.64, 0.84)"), (axes[1], "p2", "P2 (1.64, 1.64)")):
        for solver, t in tracks.items():
            ax.plot(t[point + "_x"], t[point + "_y"], label=solver, linewidth=1.2)
        ax.set_title(f"XY trajectory of {name}")
        ax.set_xlabel("X")
        ax.set_ylabel("Y")
        ax.grid(alpha=0.3)
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(args.out)


if __name__ == "__main__":
    main()
