"""surftrack: connected, watertight iso-surfaces of 3-D images (docs/python.md).

One axis convention everywhere, the same as scikit-image's: a volume is indexed
``volume[i, j, k]`` and a vertex's coordinates follow the array's axes, ``(i, j, k)`` times
``spacing`` (plus ``origin``, through ``direction``). Whatever the memory order (C, Fortran,
strided), the engine reads the array in place, without a copy.
"""
from __future__ import annotations

from typing import Callable, Optional, Sequence

import os as _os
import os
import warnings as _warnings

import numpy as np

from . import _surftrack
from ._surftrack import Cancelled, InternalError, InvalidInput

__all__ = ["extract", "label_surfaces", "marching_cubes", "Mesher", "Mesh", "write_precomputed", "Surface", "InvalidInput",
           "InternalError", "Cancelled"]

#: The project's version (CMake's project VERSION, as ``surftrack --version`` prints it).
__version__ = _surftrack.__version__

_ADJACENCIES = ("26-6", "18-6", "6-18", "6-26")
_MAPPINGS = ("linear", "midpoint", "default")


class Surface:
    """A closed, oriented 2-manifold (one per component) whose vertices are boundary surfels.

    vertices  (N, 3) float64, physical coordinates in the array's axis order
    faces     (M, 3) uint32, oriented: normals point from the selected voxels outwards
    normals   (N, 3) float64, unit outward vertex normals (computed on first use)
    surfels   (N, 2, 3) int32, the voxel pair (c, d) of each vertex: c selected, d not, as
              array indices (computed on first use)
    components  one dict per component (surfels, triangles, edges, euler, genus, area,
              volume), by decreasing size; the counts, euler and genus are ints
    euler, genus  of the whole surface (sums over the components), ints
    boundaries_in_image  mode "largest" / "all": the boundaries the scan found
    timings   seconds per stage of the C++ core
    seed_distance  seeded by a voxel or a point: the physical distance to the seed surfel
    warnings  things to know, e.g. that a seeded surface is a speck (also issued as Python
              warnings)
    voxels    label_surfaces: the voxels of the label
    refine    with smooth / max_error / reduce: the figures of smoothing and decimation
              (smooth_iterations, max_vertex_displacement, steps_back, unguarded_cubes,
              triangles_before, triangles_after, volume_before, volume_after)
    """

    def __init__(self, vertices, faces, result=None, normals=None, surfels=None, components=(),
                 euler=0, boundaries_in_image=0, mapping="midpoint", timings=None,
                 seed_surfel=None, seed_walk_steps=0, seed_distance=None, warnings=(), voxels=None,
                 refine=None):
        self.vertices = vertices
        self.faces = faces
        self._result = result
        self._normals = normals
        self._surfels = surfels
        self._components = components
        self.euler = euler
        self.boundaries_in_image = boundaries_in_image
        self.mapping = mapping
        self.timings = dict(timings or {})
        self.seed_surfel = seed_surfel
        self.seed_walk_steps = seed_walk_steps
        self.seed_distance = seed_distance
        self.warnings = list(warnings)
        self.voxels = voxels
        self.refine = dict(refine or {})

    @property
    def normals(self) -> np.ndarray:
        if self._normals is None:
            self._normals = self._result.normals()
        return self._normals

    @property
    def surfels(self) -> np.ndarray:
        if self._surfels is None:
            self._surfels = self._result.surfels()
        return self._surfels

    _FIGURES = ("surfels", "triangles", "edges", "euler", "genus", "area", "volume")
    _COUNTS = ("surfels", "triangles", "edges", "euler", "genus")

    @property
    def components(self) -> list:
        if not isinstance(self._components, list):
            table = np.asarray(self._components).reshape(-1, len(self._FIGURES))
            # Every component is a closed orientable surface: its genus (2 - euler) / 2 is an
            # integer (docs/theory.md), exact in the table's doubles.
            self._components = [
                {k: (int(v) if k in self._COUNTS else float(v)) for k, v in zip(self._FIGURES, row)}
                for row in table]
        return self._components

    @property
    def genus(self) -> int:
        return sum(c["genus"] for c in self.components)

    def __repr__(self) -> str:
        return (f"Surface({len(self.vertices)} vertices, {len(self.faces)} triangles, "
                f"{len(self.components)} component(s), euler {self.euler})")

    def write(self, path: str, binary: bool = True) -> None:
        """Writes .ply, .obj, .off or .stl (the CLI's writers; atomic: never a partial file).

        Raises ValueError for an unknown extension, OSError (with ``errno``; e.g.
        FileNotFoundError, PermissionError, IsADirectoryError) naming the path and the reason
        when it cannot be written, KeyboardInterrupt on Ctrl-C (nothing written)."""
        _surftrack.write_arrays(self.vertices, self.faces, self.surfels, str(path), binary)

    def write_components(self, paths, binary: bool = True) -> None:
        """Writes each connected component (each boundary of ``mode="all"``) to its own file:
        ``paths[k]`` the k-th of ``components`` (by decreasing vertex count, ties by smallest
        vertex), its vertices and faces in this surface's order, renumbered from 0 (the CLI's
        ``mesh --all -o DIR/``). Each file as ``write``; ValueError when ``len(paths)`` is not
        the number of components."""
        _surftrack.write_component_arrays(self.vertices, self.faces, self.surfels, [str(p) for p in paths], binary)


def _store_path(volume) -> Optional[str]:
    """The directory of a chunked store the engine reads itself: a path to one, or a zarr array
    on a directory store; None for anything else (read as an array)."""
    if isinstance(volume, (str, os.PathLike)):
        path = os.fspath(volume)
        if not os.path.isdir(path):
            raise ValueError(f"'{path}' is not a directory: a chunked store (zarr, OME-Zarr, N5) is one")
        return path
    store = getattr(volume, "store", None)
    root = getattr(store, "path", None)
    if root is not None and hasattr(volume, "chunks") and isinstance(root, str) and os.path.isdir(root):
        return os.path.join(root, getattr(volume, "path", "") or "")
    return None


#: The chunk side used for an array-like that states no chunks (an h5py dataset stored
#: contiguously): each read is one slice of this many voxels a side.
_DEFAULT_SLICE = 64


def _sliced_array(volume):
    """(shape, chunks, dtype) of an array the engine reads slice by slice through Python (a dask
    array, an h5py dataset, a zarr array not on a directory: anything not numpy with ``.shape``,
    ``.dtype``, ``.chunks`` and slicing); None for anything else. ``chunks`` per axis is the
    array's chunk side (dask's first block along the axis), or _DEFAULT_SLICE when it states
    none; ``dtype`` the native type each slice is converted to (bool as uint8)."""
    if isinstance(volume, np.ndarray) or not all(hasattr(volume, a) for a in ("shape", "dtype", "chunks",
                                                                               "__getitem__")):
        return None
    shape = tuple(int(n) for n in volume.shape)
    dtype = np.dtype(volume.dtype)
    if len(shape) != 3:
        raise ValueError(f"the volume must be 3-D, not {len(shape)}-D")
    if dtype.kind not in "biuf":
        raise TypeError(f"unsupported volume dtype '{dtype}': expected bool, "
                        "uint8/16/32/64, int8/16/32/64, float32 or float64")
    if min(shape) == 0:
        raise ValueError(f"the volume is empty (shape {shape})")
    chunks = volume.chunks
    if chunks is None:
        chunks = (_DEFAULT_SLICE,) * 3
    chunks = tuple(int(c[0]) if isinstance(c, tuple) else int(c) for c in chunks)
    if len(chunks) != 3 or min(chunks) < 1:
        raise ValueError(f"the array's chunks {volume.chunks!r} are not three positive sizes")
    dtype = np.dtype(np.uint8) if dtype.kind == "b" else dtype.newbyteorder("=")
    return shape, chunks, dtype


def _chunked_surface(out: dict) -> Surface:
    """The Surface of an extraction read chunk by chunk, with what its cache did."""
    chunks = out.pop("chunks")
    surface = Surface(**out)
    surface.chunks = chunks
    for message in surface.warnings:
        _warnings.warn(message, stacklevel=3)
    return surface


def _as_volume(volume) -> np.ndarray:
    """The volume as an array the engine reads in place; checked before any voxel is read (a
    broadcast array can have a vast shape over a single value)."""
    array = np.asarray(volume)
    if array.dtype.kind not in "biuf":
        raise TypeError(f"unsupported volume dtype '{array.dtype}': expected bool, "
                        "uint8/16/32/64, int8/16/32/64, float32 or float64")
    if array.ndim != 3:
        raise ValueError(f"the volume must be 3-D, not {array.ndim}-D")
    if array.size == 0:
        raise ValueError(f"the volume is empty (shape {array.shape})")
    if max(array.shape) > _surftrack.MAX_DIMENSION:
        raise ValueError(f"volume shape {array.shape} is not supported: each dimension must be "
                         f"at most {_surftrack.MAX_DIMENSION}")
    if not array.dtype.isnative:
        array = array.astype(array.dtype.newbyteorder("="))
    if array.dtype.kind == "b":
        array = array.view(np.uint8)
    if any(s % array.itemsize for s in array.strides):
        array = np.ascontiguousarray(array)
    return array


def _triple(name: str, value, default) -> tuple:
    value = default if value is None else value
    out = tuple(float(v) for v in np.asarray(value, dtype=float).reshape(-1))
    if len(out) != 3 or not all(np.isfinite(out)):
        raise ValueError(f"{name} must be three finite numbers, not {value!r}")
    return out


def _available_cpus() -> int:
    """The CPUs this process may run on (its affinity mask, as TBB counts them)."""
    try:
        return len(_os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return _os.cpu_count() or 1


def _thread_count(threads) -> int:
    """``threads`` checked: an int >= 0 (0: all cores), larger counts lowered to the CPUs
    available, since the surface is the same for any count and more threads than CPUs only
    wait for each other."""
    if isinstance(threads, (bool, np.bool_)) or not isinstance(threads, (int, np.integer)):
        raise TypeError(f"threads must be an integer (0: all cores), not {threads!r}")
    if threads < 0:
        raise ValueError(f"threads {threads} is negative (0: all cores)")
    return min(int(threads), _available_cpus())


def _split_affine(affine):
    """spacing, origin, direction of a 4x4 affine index -> world map (columns: the axes)."""
    a = np.asarray(affine, dtype=float)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)) or not np.allclose(a[3], [0, 0, 0, 1]):
        raise ValueError("affine must be a 4x4 matrix with last row (0, 0, 0, 1)")
    spacing = np.linalg.norm(a[:3, :3], axis=0)
    if not np.all(spacing > 0):
        raise ValueError("affine has a zero column: the geometry is singular")
    return tuple(spacing), tuple(a[:3, 3]), a[:3, :3] / spacing


def _geometry(spacing, origin, direction):
    """The checked spacing, origin and 3x3 direction of a volume."""
    spacing = _triple("spacing", spacing, (1.0, 1.0, 1.0))
    if not all(s > 0 for s in spacing):
        raise ValueError(f"spacing must be positive, not {spacing}")
    origin = _triple("origin", origin, (0.0, 0.0, 0.0))
    direction = np.eye(3) if direction is None else np.asarray(direction, dtype=float)
    if direction.shape != (3, 3) or not np.all(np.isfinite(direction)):
        raise ValueError("direction must be a 3x3 matrix of finite numbers")
    return spacing, origin, direction


def _range_note(array: np.ndarray, level: float) -> str:
    lo, hi = float(np.nanmin(array)), float(np.nanmax(array))
    if level < lo or level >= hi:
        return f" (level {level:g} is outside the data range [{lo:g}, {hi:g}])"
    return ""


def extract(volume, *, level: Optional[float] = None, label: Optional[int] = None,
            seed: Optional[Sequence] = None, seed_point: Optional[Sequence[float]] = None,
            mode: str = "seed", seed_rule: str = "nearest", adjacency: str = "26-6",
            mapping: str = "default",
            spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None, affine=None,
            epsilon: float = 1e-3, threads: int = 0, figures: bool = True,
            progress: Optional[Callable[[str, int, int, int], None]] = None,
            smooth: int = 0, max_error: Optional[float] = None,
            reduce: Optional[float] = None, max_seed_distance: float = 256.0,
            store_level: int = 0, store_channel: Optional[int] = None, store_time: Optional[int] = None,
            cache_mib: int = 512) -> Surface:
    """The surface of one boundary (mode="seed"), of the largest, or of all boundaries.

    The selected voxels are ``volume > level`` or ``volume == label``. ``seed`` is a voxel index
    ``(i, j, k)`` or a surfel ``((i, j, k), (i2, j2, k2))``; ``seed_point`` is a physical point.
    A voxel or a point resolves to the boundary surfel nearest it (``seed_rule="nearest"``);
    ``seed_rule="ray"`` walks from the voxel along +k, -k, +j, -j, +i, -i (the last axis first)
    to the first boundary crossed instead; the nearest surfel is searched for up to
    ``max_seed_distance`` voxels (of the smallest spacing; default 256, ``float('inf')`` for no
    bound), and a seed farther from every boundary is a ValueError rather than a read of the
    whole volume. ``mapping`` places each
    vertex on its surfel's segment: "linear" (iso-value interpolation, the default for a
    level), "midpoint" (the default for a label). ``progress(stage, index, stages, surfels)``
    is called at each stage and while tracking. ``threads`` (an int, 0: all cores; more than
    the CPUs available count as those) runs the scan of
    "largest" and "all" and the smoothing in parallel; the surface is the same for any number. ``figures=False``
    skips the per-component figures (``components`` empty, ``euler`` 0). ``affine`` (a 4x4 voxel-to-world matrix, as
    nibabel's ``img.affine``) replaces spacing, origin and direction. ``smooth=N`` smooths
    with N Taubin iterations (at most 100000, as the CLI), every vertex kept on its surfel's
    segment (the same voxels inside, the same topology); ``max_error`` (physical units) and/or ``reduce`` (the fraction
    of triangles to remove) then decimate without changing the topology (docs/python.md).
    ``volume`` may also be a chunked store — a zarr array on local or network files
    (``zarr.open(path)``), or the path of a zarr array, OME-Zarr image or N5 dataset: read lazily,
    only the chunks near the surface decoded (``store_level``, ``store_channel``, ``store_time``
    choose in it, ``cache_mib`` bounds the decoded chunks kept; ``surface.chunks`` says how many
    were decoded); its spacing and origin are the store's unless given. Only ``mode="seed"`` with
    ``level`` or ``label`` (docs/python.md, "Chunked stores").
    Raises ValueError / TypeError on bad input; Ctrl-C stops any stage (KeyboardInterrupt).
    """
    store = _store_path(volume)
    if store is not None:
        # A chunked store is read lazily, chunk by chunk, by the engine's own readers: only a
        # seeded extraction with a level or a label, which reads near its surface.
        if mode != "seed":
            raise ValueError(f"mode='{mode}' reads every voxel of the store: read it whole "
                             "(np.asarray) or mesh it by blocks (surftrack.distributed)")
        if level is None and label is None:
            raise ValueError("a chunked store needs level= or label=: the default level, the middle "
                             "of the data range, would read every chunk")
        array = None
        sliced = None
    else:
        # An array-like read through Python: slice by slice when the extraction reads near its
        # surface only (a seed, with a level or a label), whole otherwise (as before).
        sliced = _sliced_array(volume) if mode == "seed" and (level is None) != (label is None) else None
        array = None if sliced is not None else _as_volume(volume)
    if affine is not None:
        spacing, origin, direction = _split_affine(affine)
    if (level is None) == (label is None):
        if level is None:
            level = (float(np.nanmin(array)) + float(np.nanmax(array))) / 2.0
        else:
            raise ValueError("give either level or label, not both")
    if int(smooth) != smooth or smooth < 0:
        raise ValueError(f"smooth takes a number of iterations >= 0, not {smooth!r}")
    if smooth > _surftrack.MAX_SMOOTH_ITERATIONS:
        raise ValueError(f"smooth takes at most {_surftrack.MAX_SMOOTH_ITERATIONS} iterations "
                         f"(as the CLI's --smooth), not {smooth!r}")
    threads = _thread_count(threads)
    if mode not in ("seed", "largest", "all"):
        raise ValueError(f"unknown mode '{mode}': expected 'seed', 'largest' or 'all'")
    if not float(max_seed_distance) > 0:
        raise ValueError(f"max_seed_distance takes a positive number of voxels, not {max_seed_distance!r}")
    if adjacency not in _ADJACENCIES:
        raise ValueError(f"unsupported adjacency pair '{adjacency}': expected one of "
                         + ", ".join(_ADJACENCIES))
    if mapping not in _MAPPINGS:
        raise ValueError(f"unknown mapping '{mapping}': expected linear, midpoint or default")
    seed_values = [0.0] * 6
    if mode == "seed":
        if (seed is None) == (seed_point is None):
            raise ValueError("mode='seed' needs exactly one of seed= and seed_point= "
                             "(or use mode='largest' / 'all')")
        if seed_point is not None:
            seed_kind = "point"
            seed_values[:3] = _triple("seed_point", seed_point, None)
        else:
            s = np.asarray(seed)
            if s.shape == (3,):
                if seed_rule not in ("nearest", "ray"):
                    raise ValueError(f"unknown seed_rule '{seed_rule}': expected 'nearest' or 'ray'")
                seed_kind = "voxel" if seed_rule == "nearest" else "ray"
                seed_values[:3] = [float(v) for v in s]
            elif s.shape == (2, 3):
                seed_kind, seed_values = "surfel", [float(v) for v in s.reshape(-1)]
            else:
                raise ValueError(f"seed must be a voxel (i, j, k) or a surfel ((i, j, k), "
                                 f"(i2, j2, k2)), not {seed!r}")
            if any(v != int(v) for v in seed_values):
                raise ValueError(f"seed indices must be integers, not {seed!r}")
    else:
        if seed is not None or seed_point is not None:
            raise ValueError(f"mode='{mode}' takes no seed")
        seed_kind = mode
    spacing, origin, direction = _geometry(spacing, origin, direction)
    # The engine's x, y, z are the array's last, middle, first axes, whatever the memory order:
    # the triangulation of a cube's loops depends on the axes, and the same array must give
    # the same surface. C order reads whole rows at a time (the fast path); other orders read
    # voxel by voxel, in place.
    order = [2, 1, 0]
    kind, value = ("label", label) if label is not None else ("threshold", float(level))
    if store is not None:
        given = lambda v, default: None if tuple(v) == default else list(v)  # noqa: E731
        out = _surftrack.extract_store(
            store, int(store_level), store_channel, store_time, int(cache_mib) << 20, kind, value, seed_kind,
            seed_values, adjacency, mapping, float(epsilon), given(spacing, (1.0, 1.0, 1.0)),
            given(origin, (0.0, 0.0, 0.0)),
            None if np.array_equal(direction, np.eye(3)) else direction.tolist(), int(threads), bool(figures),
            progress, int(smooth), None if max_error is None else float(max_error),
            None if reduce is None else float(reduce), float(max_seed_distance))
        return _chunked_surface(out)
    if sliced is not None:
        shape, chunk_shape, dtype = sliced
        out = _surftrack.extract_chunked(
            volume, list(shape), list(chunk_shape), dtype, int(cache_mib) << 20, kind, value, seed_kind,
            seed_values, adjacency, mapping, float(epsilon), spacing, origin, direction.tolist(), int(threads),
            bool(figures), progress, int(smooth), None if max_error is None else float(max_error),
            None if reduce is None else float(reduce), float(max_seed_distance))
        return _chunked_surface(out)
    if seed_kind in ("largest", "all") and not array.flags.c_contiguous:
        # The scan reads every voxel row by row: one C-ordered copy is faster than reading
        # across memory, and it is read once anyway (a seeded extraction never copies).
        array = np.ascontiguousarray(array)
    # A label goes to the engine as it is (an int stays exact beyond 2^53); a level as a float.
    try:
        out = _surftrack.extract_array(array, order, kind, value, seed_kind, seed_values,
                                       adjacency, mapping, float(epsilon), spacing, origin,
                                       direction.tolist(), int(threads), bool(figures),
                                       progress, int(smooth),
                                       None if max_error is None else float(max_error),
                                       None if reduce is None else float(reduce),
                                       float(max_seed_distance))
    except ValueError as error:
        note = _range_note(array, value) if kind == "threshold" else ""
        raise type(error)(f"{error}{note}") from None
    surface = Surface(**out)
    for message in surface.warnings:
        _warnings.warn(message, stacklevel=2)
    return surface


def label_surfaces(labels, *, only: Optional[Sequence[int]] = None, label_range=None,
                   background: int = 0, boundaries: str = "all", seeds: Optional[Sequence] = None,
                   adjacency: str = "26-6", spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                   direction=None, affine=None, threads: int = 0, figures: bool = True,
                   walls: Optional[str] = None, smooth: int = 0, max_error: Optional[float] = None,
                   reduce: Optional[float] = None) -> dict:
    """Every label of an integer label image as a closed surface: a dict label -> Surface.

    One scan of the cubes triangulates every boundary of every label at once ("largest" and
    ``seeds``: a scan for seeds, then each label's boundaries tracked, labels in parallel;
    ``threads``, 0: all cores). Vertices are surfel midpoints,
    so two touching labels share their interface vertices exactly. ``only`` lists the labels
    wanted (each must occur), ``label_range=(first, last)`` takes those in between; the
    ``background`` label gets no surface. ``boundaries`` is "all" (default) or "largest" per
    label; ``seeds`` (voxel indices) keeps only the boundaries reached walking along +k (the last
    axis) from each seed to its label's boundary, and only their labels. Geometry as in
    ``extract``. ``walls="shared"`` makes all the labels one conforming complex (every wall one
    set of triangles used by both its labels, space partitioned exactly; docs/theory.md, "Shared
    walls"; every boundary only: no seeds, not "largest"; adjacency 26-6 or 6-26);
    "independent" meshes each label against the rest. The default (None) is "shared" wherever it
    is made, "independent" with seeds, "largest" or the adjacencies 18-6 and 6-18. ``smooth=N`` (shared walls only) smooths the whole complex with
    N Taubin iterations as ``extract``'s smooth does one surface: every vertex moves once, to the
    same point in every label, along its surfel's segment, so each wall stays shared, space stays
    partitioned and each label keeps its voxels and topology (docs/theory.md §12, "Smoothing the
    complex"; each Surface's ``refine`` holds its volume before and after and its largest move).
    ``max_error`` (physical units) and/or ``reduce`` (the fraction of each wall's triangles to
    remove; shared walls only) then decimate the complex, each wall once, then its junction lines
    in all their walls at once: the walls stay shared triangle for triangle and each label keeps
    its components and genus, within ``max_error`` of the undecimated walls (docs/theory.md §12, "Decimating the
    complex"; ``refine`` then also holds the triangles before and after and the target).
    Raises ValueError (surftrack.InvalidInput) / TypeError on bad input.
    """
    array = _as_volume(labels)
    if array.dtype.kind not in "biu":
        raise ValueError(f"a label image needs integer voxels: this one has {array.dtype} voxels")
    if affine is not None:
        spacing, origin, direction = _split_affine(affine)
    if only is not None and label_range is not None:
        raise ValueError("give only= or label_range=, not both")
    if boundaries not in ("all", "largest"):
        raise ValueError(f"unknown boundaries '{boundaries}': expected 'all' or 'largest'")
    if boundaries == "largest" and seeds is not None:
        raise ValueError("boundaries='largest' takes no seeds")
    if adjacency not in _ADJACENCIES:
        raise ValueError(f"unsupported adjacency pair '{adjacency}': expected one of "
                         + ", ".join(_ADJACENCIES))
    if walls is None:  # shared walls wherever they are made (docs/theory.md §12)
        walls = _surftrack.default_label_walls(boundaries == "all" and seeds is None, adjacency,
                                               bool(smooth or max_error is not None or reduce is not None))
    if walls not in ("independent", "shared"):
        raise ValueError(f"unknown walls '{walls}': expected 'independent' or 'shared'")
    if isinstance(smooth, bool) or int(smooth) != smooth or smooth < 0:
        raise ValueError(f"smooth takes a number of iterations >= 0, not {smooth!r}")
    if smooth > _surftrack.MAX_SMOOTH_ITERATIONS:
        raise ValueError(f"smooth takes at most {_surftrack.MAX_SMOOTH_ITERATIONS} iterations "
                         f"(as the CLI's --smooth), not {smooth!r}")
    if smooth and walls != "shared":
        raise ValueError("smooth= on a label map needs walls='shared': each label smoothed on its own "
                         "would pull the vertices it shares with its neighbours apart")
    if (max_error is not None or reduce is not None) and walls != "shared":
        raise ValueError("max_error= and reduce= on a label map need walls='shared': each label decimated "
                         "on its own would no longer share its walls with its neighbours")
    # Labels reach the engine as Python ints (tolist() turns numpy integers into ints), never
    # through float: uint64 segment ids above 2^53 stay exact.
    kind, values, bounds = "all", [], []
    if only is not None:
        kind = "list"
        values = np.asarray(only).reshape(-1).tolist() if isinstance(only, np.ndarray) else \
            (list(only) if isinstance(only, (list, tuple, range)) else [only])
    elif label_range is not None:
        r = list(label_range.tolist() if isinstance(label_range, np.ndarray) else label_range)
        if len(r) != 2:
            raise ValueError(f"label_range must be (first, last), not {label_range!r}")
        kind, bounds = "range", r
    seed_list = []
    if seeds is not None:
        s = np.asarray(seeds)
        if s.ndim != 2 or s.shape[1] != 3 or len(s) == 0 or np.any(s != np.round(s)):
            raise ValueError(f"seeds must be voxel indices [(i, j, k), ...], not {seeds!r}")
        seed_list = [tuple(int(v) for v in row) for row in s]
    threads = _thread_count(threads)
    spacing, origin, direction = _geometry(spacing, origin, direction)
    # The axes as in extract(); the scan reads rows, so a C-ordered copy if need be.
    if not array.flags.c_contiguous:
        array = np.ascontiguousarray(array)
    out = _surftrack.label_surfaces_array(array, [2, 1, 0], kind, values, bounds, background,
                                          boundaries, seed_list, adjacency, spacing, origin,
                                          direction.tolist(), int(threads), bool(figures), walls,
                                          int(smooth),
                                          None if max_error is None else float(max_error),
                                          None if reduce is None else float(reduce))
    return {label: Surface(**fields) for label, fields in out.items()}


def marching_cubes(volume, level=None, *, spacing=(1.0, 1.0, 1.0), gradient_direction="descent",
                   step_size=1, allow_degenerate=True, method="lewiner", mask=None,
                   adjacency="26-6", threads=0):
    """A drop-in for ``skimage.measure.marching_cubes`` whose output is always a closed,
    oriented 2-manifold: every boundary of the image, by the scanning method.

    Returns ``(verts, faces, normals, values)`` with scikit-image's shapes and dtypes, written
    in parallel by the engine (``threads``, 0: all cores; the same arrays for any number). See
    docs/python.md for what each argument does here and how the result differs; ``step_size``
    other than 1, ``mask`` and ``allow_degenerate=False`` raise ValueError.
    """
    array = _as_volume(volume)
    lo, hi = float(np.nanmin(array)), float(np.nanmax(array))
    level = (lo + hi) / 2.0 if level is None else float(level)
    if not lo <= level <= hi:
        raise ValueError("Surface level must be within volume data range.")
    if method not in ("lewiner", "lorensen"):
        raise ValueError("method should be either 'lewiner' or 'lorensen'")
    if gradient_direction not in ("descent", "ascent"):
        raise ValueError("Incorrect input %s in `gradient_direction`, see docstring." % gradient_direction)
    if step_size != 1:
        raise ValueError("step_size other than 1 is not supported: surftrack never skips voxels")
    if mask is not None:
        raise ValueError("mask is not supported by surftrack.marching_cubes")
    if not allow_degenerate:
        # Removing a triangle merges its vertices: the mesh would no longer be the closed
        # 2-manifold of every boundary (docs/python.md, "Differences from scikit-image").
        raise ValueError("allow_degenerate=False is not supported: surftrack keeps every triangle, so the "
                         "mesh stays closed; a triangle is degenerate only where the level equals voxel "
                         "values (offset the level slightly to avoid it)")
    if adjacency not in _ADJACENCIES:
        raise ValueError(f"unsupported adjacency pair '{adjacency}': expected one of "
                         + ", ".join(_ADJACENCIES))
    threads = _thread_count(threads)
    spacing, _, _ = _geometry(spacing, None, None)
    # The scan reads rows: a C-ordered copy if need be, as extract(mode="all") makes.
    if not array.flags.c_contiguous:
        array = np.ascontiguousarray(array)
    try:
        verts, faces, normals, values, _ = _surftrack.marching_cubes_array(
            array, level, adjacency, spacing, gradient_direction == "descent", threads)
    except ValueError as error:
        raise type(error)(f"{error}{_range_note(array, level)}") from None
    return verts, faces, normals, values


from .mesher import Mesh, Mesher  # noqa: E402  (zmesh's interface over label_surfaces)
from .precomputed import write_precomputed  # noqa: E402  (Neuroglancer's format)
