#!/usr/bin/python3
"""A model of a large run of surftrack.distributed.write_label_meshes, calibrated by a measured
run of bench/bench_distributed.py (its --calibration file): tasks, bytes read and written, the
map and reduce times on N workers, and the critical path.

The model scales what one worker process did per unit of work in the measured run:
  - map: seconds per block voxel (read the box from the store and decode it, scan its owned
    cubes, write its fragment file), bytes of compressed store per voxel, fragment bytes per
    voxel;
  - reduce: seconds per fragment byte (read the fragments, merge, write the PLY files), output
    bytes per fragment byte.
It assumes what the calibration cannot show, each stated in the output: every worker as fast as
the measured one, storage that keeps up with the bytes listed, labels of bounded size (a label's
merge is one task: its fragments must fit one worker; the largest label sets the reduce's
critical path), and a scheduler cost per task (--task-overhead, default 1 ms, an assumption).

    /usr/bin/python3 bench/model_distributed.py [--calibration bench/dask-calibration.json]
        [--voxels 2e12] [--workers 200] [--block 256] [--largest-label-fraction 1e-4]
"""
import argparse
import json
import math
import os


def si(n, unit):
    for factor, prefix in ((1e15, "P"), (1e12, "T"), (1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(n) >= factor:
            return f"{n / factor:.3g} {prefix}{unit}"
    return f"{n:.3g} {unit}"


def duration(s):
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.1f} min" if s < 7200 else f"{s / 3600:.1f} h"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser()
    ap.add_argument("--calibration", default=os.path.join(here, "dask-calibration.json"))
    ap.add_argument("--voxels", type=float, default=2e12)
    ap.add_argument("--workers", type=int, default=200, help="worker processes (default 200: 100 nodes x 2)")
    ap.add_argument("--block", type=int, default=256)
    ap.add_argument("--largest-label-fraction", type=float, default=1e-4,
                    help="the largest label's share of all fragment bytes (default 1e-4)")
    ap.add_argument("--task-overhead", type=float, default=1e-3, help="scheduler seconds per task (assumed)")
    ap.add_argument("--shard-bytes", type=float, default=512 * 2**20)
    args = ap.parse_args()
    c = json.load(open(args.calibration))
    per_voxel_map = c["map_seconds"] / c["voxels"]
    per_byte_reduce = c["reduce_seconds"] / c["fragment_bytes"]
    fragment_per_voxel = c["fragment_bytes"] / c["voxels"]
    store_per_voxel = c["store_bytes"] / c["voxels"]
    output_per_fragment = c["output_bytes"] / c["fragment_bytes"]

    V, W = args.voxels, args.workers
    blocks = math.ceil(V / args.block ** 3)
    fragments = V * fragment_per_voxel
    shards = max(2 * W, math.ceil(fragments / args.shard_bytes))
    block_seconds = per_voxel_map * args.block ** 3
    map_seconds = blocks * block_seconds / W + blocks * args.task_overhead
    shard_seconds = per_byte_reduce * fragments / shards
    reduce_seconds = max(math.ceil(shards / W) * shard_seconds, per_byte_reduce * fragments * args.largest_label_fraction)
    reduce_seconds += shards * args.task_overhead
    largest = per_byte_reduce * fragments * args.largest_label_fraction
    print(f"calibration: {c['source']}")
    print(f"  map {per_voxel_map * 1e9:.1f} ns per voxel ({c['block']}^3 blocks, {c['dtype']}), "
          f"reduce {per_byte_reduce * 1e9:.2f} ns per fragment byte, one worker process")
    print(f"  fragments {fragment_per_voxel:.2f} B per voxel, compressed store {store_per_voxel:.3f} B per voxel, "
          f"PLY output {output_per_fragment:.2f} B per fragment byte")
    print(f"model: {si(V, 'voxels')}, {W} workers, blocks {args.block}^3")
    print(f"  tasks: {blocks:,} block tasks, 1 plan task, {shards:,} reduce tasks")
    print(f"  bytes: store read {si(V * store_per_voxel, 'B')} compressed ({si(V * c['itemsize'], 'B')} decoded), "
          f"fragments written and read {si(fragments, 'B')}, PLY written {si(fragments * output_per_fragment, 'B')}")
    print(f"  map: {duration(map_seconds)} ({block_seconds:.2f} s per block; {si(blocks * block_seconds, 's')} of "
          f"work over {W} workers, {args.task_overhead * 1e3:g} ms scheduler time per task)")
    print(f"  reduce: {duration(reduce_seconds)} ({shard_seconds:.1f} s per shard of about "
          f"{si(fragments / shards, 'B')}; the largest label, {args.largest_label_fraction:g} of the fragments, "
          f"{duration(largest)} in one task)")
    print(f"  critical path: the map, then the longer of the reduce waves and the largest label's merge: "
          f"{duration(map_seconds + reduce_seconds)} in all")
    print("assumptions: every worker as fast as the calibration's; storage keeps up with the bytes above "
          f"({si((V * store_per_voxel + 2 * fragments) / (map_seconds + reduce_seconds), 'B/s')} on average); "
          "no label larger than one worker's memory (no hierarchical merge yet)")


if __name__ == "__main__":
    main()
