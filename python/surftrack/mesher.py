"""A zmesh-compatible front door over ``label_surfaces`` (docs/python.md, "zmesh's Mesher").

People who mesh segmentations in Python write ``Mesher(anisotropy).mesh(labels)``, then
``ids()`` and ``get(id, ...)``; with ``from surftrack import Mesher`` such a script runs on
surftrack's surfaces: one scan of the cubes gives every label's boundaries (``label_surfaces``),
each a closed, oriented 2-manifold whose vertices are surfel midpoints, so that touching labels
share their interface vertices exactly. Simplification is the topology-safe decimation of
``extract`` (docs/theory.md, section 10), run on the label's bounding box only.
"""
from __future__ import annotations

import math
import numbers
import warnings

import numpy as np


class Mesh:
    """One label's mesh, as zmesh returns it: ``vertices`` (N, 3) float32 in physical units
    (voxel index times anisotropy, in the array's axis order), ``faces`` (M, 3) uint32 wound
    outwards, ``normals`` (N, 3) float32 unit outward vertex normals or None, ``segid``."""

    def __init__(self, vertices, faces, normals=None, segid=None):
        self.vertices = vertices
        self.faces = faces
        self.normals = normals
        self.segid = segid

    def triangles(self) -> np.ndarray:
        """The (M, 3, 3) corner coordinates of every face."""
        return self.vertices[self.faces]

    def __len__(self) -> int:
        return len(self.vertices)

    def __repr__(self) -> str:
        return f"Mesh({len(self.vertices)} vertices, {len(self.faces)} faces, segid={self.segid})"


def _anisotropy(value) -> tuple:
    try:
        a = tuple(float(v) for v in value)
    except TypeError:
        raise TypeError(f"anisotropy must be three numbers, not {value!r}") from None
    if len(a) != 3 or not all(math.isfinite(v) and v > 0 for v in a):
        raise ValueError(f"anisotropy must be three positive finite numbers, not {value!r}")
    return a


class Mesher:
    """``Mesher(anisotropy).mesh(labels)``, then ``ids()``, ``get(id, ...)``, ``erase(id)``,
    ``clear()``, as zmesh's Mesher. What differs from zmesh (docs/python.md): every surface is
    closed (``close`` has no effect), neighbouring labels share their interface vertices, the
    background is label 0 and gets no mesh, and simplification never changes a surface's
    topology. Label ids are exact Python ints (uint64 ids above 2^53 included)."""

    def __init__(self, anisotropy=(1.0, 1.0, 1.0)):
        self.anisotropy = _anisotropy(anisotropy)
        self._labels = None
        self._surfaces = {}

    def mesh(self, data, close: bool = True, threads: int = 0) -> None:
        """Meshes every nonzero label of the integer 3-D array ``data`` (replacing what an
        earlier call meshed). ``threads``: as in ``label_surfaces`` (0: all cores)."""
        from . import label_surfaces  # (the package imports this module first)
        if not close:
            warnings.warn("surftrack's surfaces are always closed: close=False has no effect",
                          stacklevel=2)
        array = np.asarray(data)
        if array.ndim != 3:
            raise ValueError(f"Mesher.mesh needs a 3-D label array, not one of shape {array.shape}")
        if array.dtype.kind not in "biu":
            raise ValueError(f"Mesher.mesh needs integer labels, not {array.dtype} voxels")
        # (all background: no mesh, as zmesh, where label_surfaces calls the selection empty)
        # Each label against the rest, as zmesh meshes it (and at the engine's full speed).
        self._surfaces = label_surfaces(array, spacing=self.anisotropy, background=0, threads=threads,
                                        figures=False, walls="independent") if array.any() else {}
        self._labels = array

    def ids(self) -> list:
        """The labels meshed, ascending (Python ints)."""
        return sorted(self._surfaces)

    def _surface(self, label):
        if not isinstance(label, (numbers.Integral, np.integer)) or isinstance(label, bool):
            raise TypeError(f"a label id is an integer, not {label!r}")
        key = int(label)
        if key not in self._surfaces:
            raise KeyError(f"label {key} was not meshed (Mesher.ids() lists those that were)")
        return key, self._surfaces[key]

    def get(self, label, normals: bool = False, reduction_factor: float = 0,
            max_error=None, voxel_centered: bool = False) -> Mesh:
        """The mesh of ``label``. ``reduction_factor`` r > 1 decimates toward 1/r of the
        triangles, within ``max_error`` (physical units; default: the smallest anisotropy, one
        voxel, as zmesh) of the surface, never changing its topology; 0 or 1: no decimation.
        ``voxel_centered`` shifts the vertices by half a voxel (voxel i on [i, i+1)), as zmesh."""
        key, surface = self._surface(label)
        if not isinstance(reduction_factor, (numbers.Real, np.number)) or isinstance(reduction_factor, bool) \
                or not math.isfinite(reduction_factor) or reduction_factor < 0:
            raise ValueError(f"reduction_factor must be a finite number >= 0, not {reduction_factor!r}")
        if max_error is not None and (not isinstance(max_error, (numbers.Real, np.number))
                                      or not math.isfinite(max_error) or max_error < 0):
            raise ValueError(f"max_error must be a finite number >= 0 or None, not {max_error!r}")
        if reduction_factor > 1:
            surface = self._decimated(key, surface, float(reduction_factor),
                                      min(self.anisotropy) if max_error is None else float(max_error))
        vertices = surface.vertices
        if voxel_centered:
            vertices = vertices + 0.5 * np.asarray(self.anisotropy)
        return Mesh(np.ascontiguousarray(vertices, dtype=np.float32),
                    np.ascontiguousarray(surface.faces, dtype=np.uint32),
                    np.ascontiguousarray(surface.normals, dtype=np.float32) if normals else None,
                    segid=key)

    def get_mesh(self, label, normals: bool = False, simplification_factor: float = 0,
                 max_simplification_error=None, voxel_centered: bool = False) -> Mesh:
        """zmesh's older name of ``get``."""
        return self.get(label, normals=normals, reduction_factor=simplification_factor,
                        max_error=max_simplification_error, voxel_centered=voxel_centered)

    def _decimated(self, key, surface, factor, max_error):
        """The label's boundaries extracted again from its bounding box with one voxel around
        (the same surfels: a label's boundary lies in that box), then decimated."""
        from . import extract
        voxels = surface.surfels[:, 0]  # the label's voxel of each surfel
        lo = np.maximum(voxels.min(axis=0) - 1, 0)
        hi = np.minimum(voxels.max(axis=0) + 2, self._labels.shape)
        box = self._labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        return extract(box, label=key, mode="all", mapping="midpoint", spacing=self.anisotropy,
                       origin=tuple(float(v) for v in lo * np.asarray(self.anisotropy)),
                       max_error=max_error, reduce=1.0 - 1.0 / factor, figures=False)

    def erase(self, label) -> None:
        """Forgets the mesh of ``label``."""
        key, _ = self._surface(label)
        del self._surfaces[key]

    def clear(self) -> None:
        """Forgets every mesh and the label array."""
        self._surfaces = {}
        self._labels = None
