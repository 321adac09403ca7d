#!/usr/bin/python3
"""Draws bench_accuracy's run time against error: one log-log PNG per case, one line per
setting family (a setting is "family/label"), each point labelled with its setting.

    scripts/plot_bench.py [CSV] [--out DIR]     (defaults: out/bench_accuracy.csv, out/bench_plots/)

Lines starting with '#' in the CSV (the bench's notes) are skipped.
"""

import argparse
import csv
import os
import sys
from collections import OrderedDict


def read_rows(path):
    """{case: {family: [(label, seconds, error)]}}, in file order (coarse to fine)."""
    cases = OrderedDict()
    with open(path, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    reader = csv.DictReader(lines)
    needed = {"case", "setting", "wall_seconds", "error"}
    if not needed <= set(reader.fieldnames or []):
        hint = (" It is a run's stats.csv: draw it with scripts/plot_run.py OUT_DIR."
                if "kinetic_energy" in (reader.fieldnames or []) else "")
        raise SystemExit(f"error: {path}: expected bench_accuracy's CSV with the columns "
                         f"{', '.join(sorted(needed))}.{hint}")
    for row in reader:
        family, _, label = row["setting"].rpartition("/")
        family = family or row["setting"]
        cases.setdefault(row["case"], OrderedDict()).setdefault(family, []).append(
            (label, float(row["wall_seconds"]), float(row["error"])))
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", nargs="?", default="out/bench_accuracy.csv")
    parser.add_argument("--out", default="out/bench_plots")
    args = parser.parse_args()

    try:
        import matplotlib
    except ImportError:
        # Debian's python3-matplotlib is installed for /usr/bin/python3 only: a python3 from
        # pyenv or a venv earlier on PATH does not see it, so retry once with Debian's.
        debian = "/usr/bin/python3"
        if (os.path.exists(debian) and os.path.realpath(sys.executable) != os.path.realpath(debian)
                and not os.environ.get("REND_PLOT_REEXEC")):
            os.environ["REND_PLOT_REEXEC"] = "1"
            os.execv(debian, [debian, os.path.abspath(__file__)] + sys.argv[1:])
        print("error: matplotlib is missing. Install it from Debian:\n"
              "    apt-get install python3-matplotlib", file=sys.stderr)
        return 1
    matplotlib.use("Agg")  # headless: no display needed
    import matplotlib.pyplot as plt

    if not os.path.exists(args.csv):
        print(f"error: {args.csv} not found; write it with: build-bench/bench_accuracy {args.csv}",
              file=sys.stderr)
        return 1
    cases = read_rows(args.csv)
    os.makedirs(args.out, exist_ok=True)
    for case, families in cases.items():
        fig, ax = plt.subplots(figsize=(7.5, 5.0))
        for index, (family, points) in enumerate(families.items()):
            # A log axis cannot show 0: a time of 0 is below the clock's resolution, an error of
            # 0 exact; both are clamped to a visible floor rather than dropped.
            t = [max(p[1], 1e-6) for p in points]
            e = [max(p[2], 1e-16) for p in points]
            line, = ax.loglog(t, e, "o-", label=family)
            # Families often share a point (the same run): stagger their labels vertically.
            for (label, _, _), x, y in zip(points, t, e):
                ax.annotate(label, (x, y), textcoords="offset points", xytext=(5, 4 - 9 * index),
                            fontsize=7, color=line.get_color())
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error")
        ax.set_title(f"{case}: run time against error (coarse to fine along each line)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = os.path.join(args.out, f"{case}.png")
        fig.savefig(path, dpi=120)
        plt.close(fig)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
