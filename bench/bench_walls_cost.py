#!/usr/bin/python3
"""What shared walls (docs/theory.md §12, the default of label_surfaces) cost against independent
walls on the same label image, in the same minute (docs/performance.md, "Label maps as one
conforming complex"): label_surfaces(walls=W, threads=N, figures=False) on the cached Voronoi
volumes of bench_labels.py, independent then shared, each timed once after the array is loaded.
Refuses to time a run whose label set differs between the two.

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_walls_cost.py [--threads 2] [NPY ...]
"""
import argparse
import os
import time
import warnings

import numpy as np

import surftrack

DEFAULT = ["/tmp/surftrack-voronoi-256-20000.npy", "/tmp/surftrack-voronoi-512-2500.npy"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("volumes", nargs="*", default=DEFAULT,
                        help="label volumes as .npy (default: bench_labels.py's cached Voronoi volumes)")
    args = parser.parse_args()
    print(f"# bench_walls_cost: threads {args.threads}, load average at start {os.getloadavg()[0]:.2f}")
    print("| volume | independent s | shared s | shared / independent |\n|---|---:|---:|---:|")
    for path in args.volumes:
        labels = np.load(path)
        seconds = {}
        for walls in ("independent", "shared"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the pinches of shared walls are announced
                start = time.perf_counter()
                surfaces = surftrack.label_surfaces(labels, walls=walls, threads=args.threads, figures=False)
                seconds[walls] = (time.perf_counter() - start, sorted(surfaces))
        if seconds["independent"][1] != seconds["shared"][1]:
            raise SystemExit(f"{path}: the two walls give different label sets: no time printed")
        i, s = seconds["independent"][0], seconds["shared"][0]
        print(f"| {os.path.basename(path)} {labels.shape} | {i:.2f} | {s:.2f} | {s / i:.1f}× |", flush=True)
    print(f"# load average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
