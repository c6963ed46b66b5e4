"""surftrack's Neuroglancer output opened in a real browser (docs/cli.md, "Opening it in
Neuroglancer").

Each case writes an output directory — the AAL atlas by the CLI (`surftrack labels aal.nii.gz -o
DIR --format precomputed`), a Voronoi label volume by `surftrack.write_precomputed`, and a
smaller one by the CLI from a raw file in the multi-resolution format (`--format
precomputed-multires --lods 3`, unsharded and `--sharded`) — serves it over HTTP on
127.0.0.1 with CORS and byte ranges, as a user serves theirs, and opens it in Neuroglancer (the
npm package, bundled by build_viewer.sh and served from another origin, as Neuroglancer's own
site would be) in headless Chromium with software WebGL (open_viewer.mjs), with a state whose
segmentation layer lists a few segments, each in a colour of its own, in the 3-D layout. It
checks that:
  - the viewer gets ready (every chunk of every visible layer loaded and drawn);
  - nothing went wrong: no console error (nor a console message that says error, as a chunk
    that fails to decode is logged), no uncaught exception, no failed request, no error in the
    layer's messages or Neuroglancer's status box;
  - the data server was asked for every listed segment's manifest and each of its fragments
    (and answered each), read from the files written; in the multi-resolution format, a far
    view asks for the byte ranges of every segment's coarsest level and none of the finer
    levels', a near view for those of every level-0 fragment, the ranges read from the
    manifests (and the shard index) by python/tests/multires_reader.py, written from the
    format's description;
  - the picture shows each segment: the screenshot of the 3-D panel differs from a state with no
    segment selected (taken once for all cases) in more than 1 % of its pixels, and
    each segment's colour (its hue, which the shading keeps) covers more than 0.2 % of them, in
    every view.
A case lists one or more views (state changes, such as a zoom and a meshRenderScale that make
Neuroglancer change levels of detail) and, for each, the requests it must and must not cause
(Case).

Skipped, with the reason, when node, the bundle (build_viewer.sh), Chromium, the CLI or the AAL
atlas (mricron-data) is missing. Run by ctest (python/CMakeLists.txt) after the bundle is built.
"""
import colorsys
import dataclasses
import functools
import json
import os
import re
import shutil
import subprocess
import sys
import typing
import urllib.parse

import numpy as np
import pytest

# The multi-resolution format's reader, written from the format's description (shared with
# python/tests/test_precomputed_multires.py): which byte ranges hold which level of detail.
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python", "tests"))
import multires_reader  # noqa: E402
from serve import Server  # noqa: E402  (tests/browser/serve.py: CORS and byte ranges)

BUNDLE = os.environ.get("SURFTRACK_NEUROGLANCER_BUNDLE", "")  # build_viewer.sh's OUT
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
EXE = os.environ.get("SURFTRACK_CLI", "")
AAL = "/usr/share/mricron/templates/aal.nii.gz"


def missing():
    """Why the test cannot run here, or None."""
    if shutil.which("node") is None:
        return "no node (Node.js 20.19 or later, as the machines have)"
    if not os.path.isfile(os.path.join(BUNDLE, "dist", "index.html")):
        return f"no Neuroglancer bundle in '{BUNDLE}' (tests/browser/build_viewer.sh builds it)"
    if not os.access(CHROMIUM, os.X_OK):
        return f"no Chromium at {CHROMIUM} (Debian's chromium; scripts/setup.sh installs it)"
    if not os.access(EXE, os.X_OK):
        return "no surftrack CLI (SURFTRACK_CLI)"
    if not os.path.isfile(AAL):
        return f"no {AAL} (Debian's mricron-data; scripts/setup.sh installs it)"
    return None


pytestmark = pytest.mark.skipif(missing() is not None, reason=f"browser test SKIPPED: {missing()}")


# --- the outputs --------------------------------------------------------------------------------

def write_aal(directory):
    """The AAL atlas (116 regions on a 181 x 217 x 181 grid of 1 mm voxels), by the CLI."""
    out = os.path.join(directory, "aal")
    run = subprocess.run([EXE, "labels", AAL, "-o", out, "--format", "precomputed"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return out


# [z, y, x] nm. The legacy case's volume; the multi-resolution cases' is smaller, as their
# writer's levels of detail take about 0.1 s per thousand voxels of a label (docs/cli.md).
VORONOI = dict(n=96, cells=50, seed=20261203, spacing=(16.0, 8.0, 8.0))
VORONOI_SMALL = dict(VORONOI, n=40, cells=20)


@functools.lru_cache(maxsize=2)
def voronoi_volume(n, cells, seed):
    """A Voronoi label volume indexed [z, y, x]: each voxel labelled 1 + its nearest centre's
    index (bench/bench_labels.py makes the large ones the same way), and the centres."""
    from scipy.spatial import cKDTree
    centres = np.random.default_rng(seed).random((cells, 3)) * n
    grid = np.stack(np.meshgrid(*(np.arange(n),) * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    _, nearest = cKDTree(centres).query(grid)
    return (nearest + 1).astype(np.uint32).reshape(n, n, n), centres


def write_voronoi(directory):
    import surftrack
    labels, _ = voronoi_volume(VORONOI["n"], VORONOI["cells"], VORONOI["seed"])
    spacing = VORONOI["spacing"]
    surfaces = surftrack.label_surfaces(labels, spacing=spacing)
    out = os.path.join(directory, "voronoi")
    surftrack.write_precomputed(surfaces, out, axes="zyx", unit="nm", spacing=spacing)
    return out


def voronoi_segments(count=6, v=VORONOI):
    """Cells whose centres lie far apart across the x-y plane (farthest points, greedily), so
    that seen along z none hides another."""
    _, centres = voronoi_volume(v["n"], v["cells"], v["seed"])
    xy = centres[:, [2, 1]]
    chosen = [int(np.argmin(np.linalg.norm(xy - v["n"] / 2, axis=1)))]
    while len(chosen) < count:
        d = np.min(np.linalg.norm(xy[:, None] - xy[chosen][None], axis=2), axis=1)
        chosen.append(int(np.argmax(d)))
    return [c + 1 for c in chosen]


LODS = 3


def write_voronoi_multires(directory, sharded):
    """The small Voronoi volume's shown cells (voronoi_segments) in the multi-resolution format,
    LODS levels of detail, by the CLI from a raw file, unsharded or sharded."""
    v = VORONOI_SMALL
    labels, _ = voronoi_volume(v["n"], v["cells"], v["seed"])
    raw = os.path.join(directory, "voronoi.raw")
    labels.tofile(raw)  # x fastest
    out = os.path.join(directory, "voronoi-sharded" if sharded else "voronoi-multires")
    segments = ",".join(str(s) for s in voronoi_segments(v=v))
    run = subprocess.run([EXE, "labels", raw, "--raw-dims", f"{v['n']},{v['n']},{v['n']}",
                          "--raw-type", "uint32", "--spacing", ",".join(str(x) for x in v["spacing"][::-1]),
                          "--unit", "nm", "--labels", segments, "--quiet", "-o", out + "/",
                          "--format", "precomputed-multires", "--lods", str(LODS),
                          *(["--sharded"] if sharded else [])], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    os.remove(raw)
    return out


def legacy_requests(out, segments, view):
    """The legacy format's requests for `segments`: each manifest and the fragments it lists;
    none refused."""
    paths = set()
    for s in segments:
        paths.add(f"{s}:0")
        with open(os.path.join(out, f"{s}:0")) as f:
            paths.update(json.load(f)["fragments"])
    return paths, set()


def legacy_vertices(out, segment):
    """The vertices (x, y, z nm) of a legacy segment, read from its fragments."""
    with open(os.path.join(out, f"{segment}:0")) as f:
        fragments = json.load(f)["fragments"]
    parts = []
    for name in fragments:
        data = np.fromfile(os.path.join(out, name), dtype=np.uint8)
        n = int(data[:4].view("<u4")[0])
        parts.append(data[4:4 + 12 * n].view("<f4").reshape(n, 3))
    return np.concatenate(parts)


def multires_info(out):
    with open(os.path.join(out, "info")) as f:
        info = json.load(f)
    assert info["@type"] == "neuroglancer_multilod_draco"
    return info


def multires_corners(out, segment):
    """The corners (x, y, z nm) of the level-0 nodes of a multi-resolution segment, read from
    its manifest: a box around its mesh, for the camera."""
    info = multires_info(out)
    if "sharding" in info:
        manifest, _ = multires_reader.read_sharded(out, info, segment)
    else:
        with open(os.path.join(out, f"{segment}.index"), "rb") as f:
            manifest = f.read()
    m = multires_reader.parse_manifest(manifest)
    low = m["origin"] + m["positions"][0] * m["chunk"]
    corners = np.concatenate([low + np.array(c) * m["chunk"] for c in np.ndindex(2, 2, 2)])
    t = np.asarray(info["transform"], float).reshape(3, 4)
    return corners @ t[:, :3].T + t[:, 3]


def multires_requests(out, segments, view):
    """The multi-resolution format's requests for `segments` in `view`, whose "levels" names
    the levels of detail it must fetch all the fragments of (the byte ranges the manifests
    give), and whose "not_levels" those it must fetch none of: paths "file#bytes=first-last",
    the data file or the shard file; and unsharded, each manifest "<id>.index"."""
    info = multires_info(out)
    wanted, refused = set(), set()
    for s in segments:
        if "sharding" not in info:
            wanted.add(f"{s}.index")
        for lod, level in enumerate(multires_reader.fragment_ranges(out, info, s)):
            paths = {f"{name}#bytes={first}-{last}" for name, first, last in level}
            if lod in view["levels"]:
                wanted |= paths
            if lod in view["not_levels"]:
                refused |= paths
    return wanted, refused


@dataclasses.dataclass
class Case:
    """One output opened in the viewer. `views` are the states it is seen in, each a dict of
    changes to the state made by `state()`: "zoom" divides the framing projectionScale (2: twice
    as close), "layer" is merged into the layer, "levels" and "not_levels" are for `requests`,
    any other key replaces the state's. Each view must cause the requests `requests` names and
    none of those it refuses, so a case for the multi-resolution format lists a far view and a
    near one, with the fragments of the coarse and of the fine levels of detail that each must
    (and must not) fetch, and `vertices` reads a box around level 0 (or the legacy vertices)
    for the framing."""
    name: str
    write: typing.Callable  # (directory) -> the output directory
    segments: typing.Callable  # () -> segment ids
    vertices: typing.Callable = legacy_vertices  # (out, segment) -> (N, 3) nm, for the camera
    # (out, segments, view) -> (the paths under `out` the view must request, those it must not)
    # ("path#bytes=a-b": that range of it)
    requests: typing.Callable = legacy_requests
    views: list = dataclasses.field(default_factory=lambda: [{}])


# AAL regions on the brain's upper surface, which a view from above shows side by side:
# Precentral_L/R, Frontal_Sup_L/R, Parietal_Sup_L/R (aal.nii.txt).
AAL_SEGMENTS = [1, 2, 3, 4, 59, 60]

# Neuroglancer draws a node of level k > 0 of the multi-resolution format, rather than its
# children, once its lod scale (2^k voxels, docs/cli.md) is at most the node's pixel size (in
# voxels of the coarsest axis, at its nearest corner) times the layer's meshRenderScale (1 by
# default); the top level is always fetched. The product is what a zoom changes, so the far view
# is the framed camera with meshRenderScale 256, which Neuroglancer treats as a camera 256 times
# farther, and keeps every segment large enough on screen for the picture's checks. Framed, a
# pixel of the small Voronoi volume is about 1/11 voxel (1.3 x 40 x 16 nm over 600 pixels, per
# 16 nm): the near view needs level 0 (1/11 < 2, the lod scale of level 1); the far one, a pixel
# "worth" about 23 voxels (over the 4 of the top level), the top level only.
MULTIRES_VIEWS = [
    {"layer": {"meshRenderScale": 256}, "levels": {LODS - 1}, "not_levels": set(range(LODS - 1))},
    {"levels": {0}, "not_levels": set()},
]

CASES = [
    Case("aal", write_aal, lambda: AAL_SEGMENTS),
    Case("voronoi", write_voronoi, voronoi_segments),
    Case("voronoi-multires", lambda d: write_voronoi_multires(d, sharded=False),
         lambda: voronoi_segments(v=VORONOI_SMALL), multires_corners, multires_requests, MULTIRES_VIEWS),
    Case("voronoi-sharded", lambda d: write_voronoi_multires(d, sharded=True),
         lambda: voronoi_segments(v=VORONOI_SMALL), multires_corners, multires_requests, MULTIRES_VIEWS),
]


# --- the state and the picture ------------------------------------------------------------------

HUES = [0, 60, 120, 180, 240, 300]  # degrees: red, yellow, green, cyan, blue, magenta


def colour(i):
    r, g, b = colorsys.hsv_to_rgb(HUES[i % len(HUES)] / 360, 1, 1)
    return "#%02x%02x%02x" % (round(255 * r), round(255 * g), round(255 * b))


def state(source, segments, vertices, view):
    """A Neuroglancer state: one segmentation layer from `source` showing `segments` in the 3-D
    layout, the camera on their bounding box, seen from +z; nothing else drawn; then `view`'s
    changes (Case)."""
    view = {k: v for k, v in view.items() if k not in ("levels", "not_levels")}
    zoom = view.pop("zoom", 1)
    layer = {
        "type": "segmentation",
        "name": "surftrack",
        "source": source,
        "segments": [str(s) for s in segments],
        "segmentColors": {str(s): colour(i) for i, s in enumerate(segments)},
    }
    layer.update(view.pop("layer", {}))
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    s = {
        "dimensions": {a: [1e-9, "m"] for a in "xyz"},
        "position": [float(v) for v in (low + high) / 2],
        "projectionScale": float(1.3 * np.max(high - low) / zoom),
        "projectionOrientation": [0, 0, 0, 1],
        "layers": [layer],
        "layout": "3d",
        "showAxisLines": False,
        "showDefaultAnnotations": False,
        "showScaleBar": False,
        "selectedLayer": {"visible": False},
    }
    s.update(view)
    return s


def viewer_url(base, s):
    return base + "/index.html#!" + urllib.parse.quote(json.dumps(s, separators=(",", ":")))


def open_pages(jobs, directory):
    """Runs open_viewer.mjs on [(url, screenshot path)]: its results, one per page."""
    path = os.path.join(directory, "jobs.json")
    with open(path, "w") as f:
        json.dump([{"url": u, "screenshot": str(p)} for u, p in jobs], f)
    driver = os.path.join(BUNDLE, "open_viewer.mjs")  # build_viewer.sh's copy, beside node_modules
    run = subprocess.run(["node", driver, path], capture_output=True, text=True,
                         env=dict(os.environ, CHROMIUM=CHROMIUM), timeout=60 + 35 * len(jobs))
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.strip().splitlines()[-1])


def pixels(path):
    from PIL import Image
    with Image.open(path) as image:
        return np.asarray(image.convert("RGB")).astype(np.int16)


def hue_coverage(rgb, count):
    """The fraction of pixels of each of the first `count` hues (saturated, not dark)."""
    c = rgb.reshape(-1, 3) / 255.0
    high, low = c.max(axis=1), c.min(axis=1)
    chroma = high - low
    lit = (chroma > 0.5 * high) & (high > 0.15)  # saturation above 0.5, value above 0.15
    r, g, b = c.T
    safe = np.where(chroma > 0, chroma, 1)
    hue = np.select([high == r, high == g], [(g - b) / safe % 6, (b - r) / safe + 2],
                    (r - g) / safe + 4) * 60
    out = []
    for i in range(count):
        d = np.abs((hue - HUES[i] + 180) % 360 - 180)
        out.append(float(np.mean(lit & (d < 15))))
    return out


def check_page(name, result, log):
    """The page got ready, with no error of any kind, every request answered."""
    print(f"{name} ready in {result['seconds']} s on {result['renderer']}; {len(log)} requests")
    for m in result["console"]:
        print(f"  console {m['type']}: {m['text']}")
    summary = {k: v for k, v in result.items() if k != "url"}
    assert result["ready"], f"{name}: the viewer did not get ready: {summary}"
    assert not result["pageErrors"], result["pageErrors"]
    assert not result["failedRequests"], result["failedRequests"]
    assert not result["statusErrors"], result["statusErrors"]
    # console.error, and what Neuroglancer's workers log with console.log when a chunk fails to
    # load or decode ("Error retrieving chunk ...")
    errors = [m["text"] for m in result["console"]
              if m["type"] == "error" or re.search(r"\berror\b", m["text"], re.I)]
    assert not errors, f"{name}: console errors: {errors}"
    assert all(status == 200 or status == 206 for _, status in log), log


@pytest.fixture(scope="module")
def opened(request, tmp_path_factory):
    """Every selected case's output written, served and opened, all in one browser session (a
    browser started per case cost about 4 s each): per case, its output and, per view, the
    screenshot, the driver's result and the requests the data server logged while the page was
    open (one page at a time); and under "none" the same for the state with no segment, the
    panel's background, the same for every case."""
    cases = [item.callspec.params["case"] for item in request.session.items
             if hasattr(item, "callspec") and "case" in item.callspec.params]
    tmp = tmp_path_factory.mktemp("browser")
    data = tmp / "data"
    data.mkdir()
    outputs = {}
    for case in cases:
        out = case.write(data)
        segments = case.segments()
        vertices = np.concatenate([case.vertices(out, s) for s in segments])
        outputs[case.name] = (out, os.path.relpath(out, data), segments, vertices)
    with Server(os.path.join(BUNDLE, "dist")) as page, Server(data) as files:
        jobs, owners = [], []
        for case in cases:
            out, name, segments, vertices = outputs[case.name]
            source = f"precomputed://{files.url}/{name}"
            if not jobs:
                jobs.append((viewer_url(page.url, state(source, [], vertices, case.views[0])), tmp / "none.png"))
                owners.append(("none", 0))
            for i, view in enumerate(case.views):
                jobs.append((viewer_url(page.url, state(source, segments, vertices, view)),
                             tmp / f"{case.name}-view{i}.png"))
                owners.append((case.name, i))
        results = open_pages(jobs, tmp)
        logs = [[(p, status) for t, p, status in files.log if r["startedAt"] <= t <= r["endedAt"]]
                for r in results]
    pages = {}
    for (owner, i), (_, shot), result, log in zip(owners, jobs, results, logs):
        pages.setdefault(owner, []).append((shot, result, log))
    return {name: (outputs.get(name), views) for name, views in pages.items()}


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_neuroglancer_shows_the_segments(case, opened):
    (_, [(none, result, log)]) = opened["none"]
    check_page("none.png", result, log)
    background = pixels(none)
    (out, name, segments, _), views = opened[case.name]
    for i, (view, (shot, result, log)) in enumerate(zip(case.views, views)):
        check_page(f"{case.name}: view {i}", result, log)
        asked = {p[len(name) + 2:] for p, _ in log if p.startswith(f"/{name}/")}
        wanted, refused = case.requests(out, segments, view)
        print(f"  view {i}: {len(asked)} requests, {len(wanted)} wanted, {len(refused)} refused")
        assert wanted <= asked, f"view {i}: not requested: {sorted(wanted - asked)}"
        assert not refused & asked, f"view {i}: requested: {sorted(refused & asked)}"
        shot = pixels(shot)
        assert shot.shape == background.shape
        changed = float(np.mean(np.any(np.abs(shot - background) > 24, axis=2)))
        coverage = hue_coverage(shot, len(segments))
        print(f"  view {i}: {changed:.1%} of the pixels changed; each segment's colour covers "
              + ", ".join(f"{c:.2%}" for c in coverage))
        assert changed > 0.01, f"view {i}: the 3-D panel looks blank ({changed:.2%} changed)"
        for s, c in zip(segments, coverage):
            assert c > 0.002, f"view {i}: segment {s} is not seen ({c:.3%} of the pixels)"
