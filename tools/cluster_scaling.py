#!/usr/bin/env python3
"""The scaling model of docs/cluster.md: Monte-Carlo runs per minute on n Slurm nodes, from costs measured on one.

    T(N, n) = t_cal + t_submit + ceil(N / (n c)) (t_run + t_task) + t_dep + t_agg0 + t_agg1 N
    runs per minute = 60 N / T(N, n)

Prints the table for 1, 10 and 100 nodes and, with --plot PNG, draws runs per minute against nodes (gnuplot).
"""
import argparse
import math
import os
import subprocess
import tempfile


def wall_s(a, runs, nodes):
    waves = math.ceil(runs / (nodes * a.cores))
    return (a.t_cal + a.t_submit + waves * (a.t_run + a.t_task) + a.t_dep + a.t_agg0 + a.t_agg1 * runs)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cores", type=int, default=2, help="cores per node (tasks at once per node)")
    p.add_argument("--t-run", dest="t_run", type=float, default=8.6, help="one run inside its task [s]")
    p.add_argument("--t-task", dest="t_task", type=float, default=0.9,
                   help="per task: dispatch, roamlab start, shared inputs read [s]")
    p.add_argument("--t-submit", dest="t_submit", type=float, default=0.6, help="preparing and sbatch [s]")
    p.add_argument("--t-cal", dest="t_cal", type=float, default=15.0, help="shared calibration, once [s]")
    p.add_argument("--t-dep", dest="t_dep", type=float, default=1.0, help="array end to aggregation start [s]")
    p.add_argument("--t-agg0", dest="t_agg0", type=float, default=0.9, help="aggregation, fixed part [s]")
    p.add_argument("--t-agg1", dest="t_agg1", type=float, default=0.0057, help="aggregation per run [s]")
    p.add_argument("--runs", type=int, nargs="+", default=[1000, 10000], help="batch sizes N")
    p.add_argument("--plot", help="write this PNG (needs gnuplot)")
    a = p.parse_args()
    nodes = [1, 10, 100]
    print("| N runs | " + " | ".join(f"{n} node{'s' if n > 1 else ''}" for n in nodes) + " |")
    print("|---|" + "---|" * len(nodes))
    for runs in a.runs:
        cells = [f"{60 * runs / wall_s(a, runs, n):.0f} runs/min ({wall_s(a, runs, n):.0f} s)" for n in nodes]
        print(f"| {runs} | " + " | ".join(cells) + " |")
    if not a.plot:
        return
    with tempfile.TemporaryDirectory() as tmp:
        dat = os.path.join(tmp, "scaling.dat")
        with open(dat, "w") as f:
            for runs in a.runs:
                for n in [1, 2, 5, 10, 20, 50, 100]:
                    f.write(f"{n} {60 * runs / wall_s(a, runs, n)} {60 * n * a.cores / (a.t_run + a.t_task)}\n")
                f.write("\n\n")
        plots = [f"'{dat}' index {k} using 1:2 with linespoints title 'N = {runs} runs'"
                 for k, runs in enumerate(a.runs)]
        plots.append(f"'{dat}' index 0 using 1:3 with lines dashtype 2 title 'tasks alone (no start-up, no aggregation)'")
        script = (f"set terminal pngcairo size 800,500 noenhanced font 'sans,11'\nset output '{a.plot}'\n"
                  "set logscale xy\nset grid\nset key top left\nset xlabel 'nodes (2 cores each)'\n"
                  "set ylabel 'Monte-Carlo runs per minute'\n"
                  "set title 'ATV 30 s drive: 1 node measured, 10 and 100 nodes from the model'\n"
                  "plot " + ", ".join(plots) + "\n")
        subprocess.run(["gnuplot"], input=script, text=True, check=True)


if __name__ == "__main__":
    main()
