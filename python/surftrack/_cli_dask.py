"""The Dask side of the command line's ``surftrack labels STORE -o DIR/ --dask ...`` and
``surftrack mesh STORE --all --iso S -o FILE --dask ...`` (docs/cli.md, "Every label by blocks on
Dask"), run by the CLI as ``python3 -m surftrack._cli_dask JOB.json`` (cli/DaskJob.h).

The CLI checks the options, reads the store's metadata and the label names, and owns the outputs
(the staging directory, labels.csv, --table, the final rename); this module runs
``distributed``'s graph on the cluster the CLI names: each block task reads its box through the
engine's own store readers (any store the CLI reads), the reduce tasks write each label's mesh
into the staging directory under the CLI's file name, in the CLI's physical frame (x, y, z), and
the rows of the table come back to the CLI as JSON. An error the user can act on: exit status
1 and {"error": one line} in the result file, which the CLI reports."""
from __future__ import annotations

import json
import sys

import numpy as np

from . import _surftrack
from . import distributed


class StoreArray:
    """A chunked store's chosen array as the block tasks slice it ([z, y, x]), read by the
    engine's readers in the worker (picklable: only the store's path and choices travel)."""

    def __init__(self, path, level, channel, time):
        self.path, self.level, self.channel, self.time = path, level, channel, time
        shape, dtype = _surftrack.store_layout(path, level, channel, time)
        self.shape, self.dtype = tuple(shape), np.dtype(dtype)

    def __getitem__(self, box):
        lo = [s.start for s in box]
        hi = [s.stop for s in box]
        return _surftrack.read_store_box(self.path, self.level, self.channel, self.time, lo, hi)


def _client(address):
    from dask.distributed import Client, LocalCluster
    if address.startswith("local:"):
        n = address[len("local:"):]
        if not n.isdigit() or int(n) < 1:
            raise ValueError(f"--dask local:N takes a number of worker processes, not '{address}'")
        cluster = LocalCluster(n_workers=int(n), threads_per_worker=1, processes=True, dashboard_address=None)
        return Client(cluster), cluster
    return Client(address, timeout="30s"), None


def _precomputed(job):
    """--format precomputed or precomputed-multires: the frame of the single pass' writers
    (cli/PrecomputedOutput.cpp; the map computed by its own C++, converter/PrecomputedFrame.h),
    the engine's geometry (the multi-resolution format stores voxel indices), the names. The
    tasks write into the CLI's staging directory, which the CLI moves into place."""
    if not job.get("format"):
        return None
    from .precomputed import _Frame
    geometry = (job["spacing"], job["origin"], job["direction"])  # engine axes x, y, z
    lods = int(job["lods"])
    linear, offset = _surftrack.cli_precomputed_frame(*geometry, float(job["nanometres"]), lods > 0)
    frame = _Frame([list(r) for r in linear], list(offset), np.ones(3), lods, int(job["quantization_bits"]),
                   (2 if job["shard_hash"] == "identity" else 1) if job["sharded"] else 0)
    return {"frame": frame, "cli_geometry": geometry, "staging": job["staging"], "target": None,
            "names": {int(L): n for L, n in job["names"].items()}}


def run(job: dict) -> list:
    source = StoreArray(job["store"], job["level"], job["channel"], job["time"])
    # The CLI's frame: engine axis e (x, y, z) is array axis 2 - e; the merge takes its geometry
    # in array axes and places vertices in the physical rows of `direction`, here x, y, z.
    spacing = list(reversed(job["spacing"]))
    direction = [[row[2 - a] for a in range(3)] for row in job["direction"]]
    quiet = job["quiet"]
    last = {}

    def progress(stage, done, total):
        step = max(1, total // 20)
        if not quiet and (done == total or done - last.get(stage, 0) >= step):
            last[stage] = done
            what = {"blocks": "blocks meshed", "labels": "labels merged", "merge": "merged",
                    "shards": "shards written"}[stage]
            command = "labels" if job["kind"] == "labels" else "mesh"
            print(f"surftrack {command}: {what} {done} of {total}", file=sys.stderr, flush=True)

    client, cluster = _client(job["dask"])
    try:
        with distributed._work_dir(job["work_dir"]) as work:
            common = dict(block=tuple(reversed(job["block"])), spacing=spacing, origin=job["origin"],
                          direction=direction, adjacency=job["adjacency"], client=client, workers=None,
                          work_dir=work, progress=progress)
            if job["kind"] == "threshold":
                return distributed._run_threshold(source, job["iso"], mapping=job["mapping"], epsilon=1e-3,
                                                  figures=True, out_path=job["output"], binary=job["binary"],
                                                  out_dir=job.get("output_dir"), **common)
            precomputed = _precomputed(job)
            return distributed._run(source, background=int(job["background"]), figures=True,
                                    out_dir=None if precomputed else job["staging"], shards=None,
                                    naming={"names": job["names"], "binary": job["binary"]},
                                    precomputed=precomputed, merge_budget=job.get("merge_budget"), **common)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv) -> int:
    job = json.load(open(argv[1]))
    try:
        figures = run(job)
    except (ValueError, OSError, TimeoutError) as error:
        with open(job["result"], "w") as out:  # the CLI reports it, as its own errors
            json.dump({"error": str(error).splitlines()[0] if str(error) else type(error).__name__}, out)
        return 1
    if job["kind"] == "labels":
        figures = [{"label": str(label), **f} for label, f in sorted(figures.items())]
    with open(job["result"], "w") as out:
        json.dump(figures, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
