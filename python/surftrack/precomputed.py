"""Neuroglancer's precomputed mesh format, legacy single-resolution variant (docs/python.md,
"Neuroglancer output"): ``write_precomputed(surfaces, path, axes=...)`` writes a dict of
label -> Surface (``label_surfaces``) or Mesh (``Mesher.get``) as a directory Neuroglancer opens
as ``precomputed://URL``. The writer is the CLI's (``surftrack labels --format precomputed``)."""
from __future__ import annotations

import math

import numpy as np

from . import _surftrack

#: Nanometres per unit.
_UNITS = {"nm": 1.0, "um": 1e3, "µm": 1e3, "mm": 1e6, "cm": 1e7, "m": 1e9}


def write_precomputed(surfaces: dict, path, *, axes: str, unit: str = "nm", spacing=None,
                      names: dict | None = None) -> None:
    """Writes ``surfaces`` (label -> an object with ``vertices`` and ``faces``) to the directory
    ``path`` (absent or empty; written whole or not at all).

    ``axes`` says which of Neuroglancer's x, y, z the vertex columns are: ``"zyx"`` for an
    array indexed ``[z, y, x]`` (zarr, N5, tifffile), ``"xyz"`` for one indexed ``[x, y, z]``
    (nibabel). ``unit`` is the vertices' unit (nm, um, mm, cm, m); Neuroglancer's are nanometres.
    ``spacing`` (the voxel size, in the vertices' axes and unit, as given to
    ``label_surfaces``) shifts every vertex by half a voxel, so that the meshes lie on the voxels
    as Neuroglancer draws them (voxel i over [i, i + 1)); without it, none. ``names``: label ->
    segment name (Neuroglancer's segment properties). Labels are exact ints, positive uint64.
    Raises ValueError for a label that is not a positive uint64, coordinates beyond float32
    nanometres; OSError when the directory cannot be written."""
    if axes not in ("xyz", "zyx"):
        raise ValueError(f"axes must be 'xyz' or 'zyx' (the vertex columns as Neuroglancer's x, y, z), not {axes!r}")
    if unit not in _UNITS:
        raise ValueError(f"unknown unit {unit!r}: expected one of " + ", ".join(_UNITS))
    k = _UNITS[unit]
    shift = np.zeros(3)
    if spacing is not None:
        s = [float(v) for v in spacing]
        if len(s) != 3 or not all(math.isfinite(v) and v > 0 for v in s):
            raise ValueError(f"spacing must be three positive finite numbers, not {spacing!r}")
        shift = np.asarray(s) / 2
    order = [0, 1, 2] if axes == "xyz" else [2, 1, 0]  # Neuroglancer's axis r is column order[r]
    linear = [[k if c == order[r] else 0.0 for c in range(3)] for r in range(3)]
    offset = [k * shift[order[r]] for r in range(3)]
    names = names or {}
    segments = []
    for label, surface in surfaces.items():
        if isinstance(label, bool) or not isinstance(label, (int, np.integer)):
            raise TypeError(f"a segment id is an integer, not {label!r}")
        segments.append((int(label), np.asarray(surface.vertices, dtype=np.float64),
                         np.asarray(surface.faces, dtype=np.int64), str(names.get(label, ""))))
    _surftrack.write_precomputed(segments, str(path), linear, offset)
