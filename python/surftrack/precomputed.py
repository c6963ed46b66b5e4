"""Neuroglancer's precomputed mesh formats (docs/python.md, "Neuroglancer output"):
``write_precomputed(surfaces, path, axes=...)`` writes a dict of label -> Surface
(``label_surfaces``) or Mesh (``Mesher.get``) as a directory Neuroglancer opens as
``precomputed://URL``, in the legacy single-resolution format or, with ``lods=N``, the
multi-resolution one (Draco fragments, N levels of detail, optionally sharded). The writers are
the CLI's (``surftrack labels --format precomputed`` / ``precomputed-multires``)."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from . import _surftrack

#: Nanometres per unit.
_UNITS = {"nm": 1.0, "um": 1e3, "µm": 1e3, "mm": 1e6, "cm": 1e7, "m": 1e9}


def write_precomputed(surfaces: dict, path, *, axes: str, unit: str = "nm", spacing=None,
                      names: dict | None = None, lods: int | None = None, sharded: bool | str = False,
                      quantization_bits: int = 16) -> None:
    """Writes ``surfaces`` (label -> an object with ``vertices`` and ``faces``) to the directory
    ``path`` (absent or empty; written whole or not at all).

    ``axes`` says which of Neuroglancer's x, y, z the vertex columns are: ``"zyx"`` for an
    array indexed ``[z, y, x]`` (zarr, N5, tifffile), ``"xyz"`` for one indexed ``[x, y, z]``
    (nibabel). ``unit`` is the vertices' unit (nm, um, mm, cm, m); Neuroglancer's are nanometres.
    ``spacing`` (the voxel size, in the vertices' axes and unit, as given to
    ``label_surfaces``) shifts every vertex by half a voxel, so that the meshes lie on the voxels
    as Neuroglancer draws them (voxel i over [i, i + 1)); without it, none. ``names``: label ->
    segment name (Neuroglancer's segment properties). Labels are exact ints, positive uint64.

    ``lods``: None (the default) writes the legacy format; an int from 1 to 10 writes the
    multi-resolution format ("neuroglancer_multilod_draco") with that many levels of detail,
    each a closed oriented mesh of the label's genus (level k within 0.5 (2^k - 1) voxels of
    level 0, the voxel being ``spacing``, or a vertex unit without it), every surface then
    needing to be closed and oriented. ``sharded``: the sharded layout (a few ``.shard`` files
    instead of two files per label), its ids hashed by ``"murmurhash3_x86_128"`` (``True``) or
    not (``"identity"``: consecutive ids share minishards). ``quantization_bits``: 16 (default) or 10, the fragments'
    vertex precision (a level-k fragment of a cell of c voxels has steps of c 2^k / (2^bits - 1)).
    Raises ValueError for a label that is not a positive uint64, coordinates beyond float32
    nanometres, a multi-resolution option out of range or a surface that is not closed;
    OSError when the directory cannot be written."""
    frame = _frame(axes=axes, unit=unit, spacing=spacing, lods=lods, sharded=sharded,
                   quantization_bits=quantization_bits)
    names = names or {}
    segments = []
    for label, surface in surfaces.items():
        if isinstance(label, bool) or not isinstance(label, (int, np.integer)):
            raise TypeError(f"a segment id is an integer, not {label!r}")
        segments.append((int(label), *_stored(surface, frame), str(names.get(label, ""))))
    _surftrack.write_precomputed(segments, str(path), frame.linear, frame.offset, frame.lods,
                                 frame.quantization_bits, frame.hashing)


class _Frame(NamedTuple):
    """What write_precomputed's arguments make of every segment: the map to nanometres, the
    divisor of the vertices (the multi-resolution format stores voxel units), the format."""
    linear: list
    offset: list
    scale: np.ndarray
    lods: int  # 0: the legacy format
    quantization_bits: int
    hashing: int  # 0 unsharded, 1 murmurhash3_x86_128, 2 identity


def _stored(surface, frame):
    """A surface's (vertices, faces) as the writer takes them."""
    return (np.asarray(surface.vertices, dtype=np.float64) / frame.scale,
            np.asarray(surface.faces, dtype=np.int64))


def _frame(*, axes, unit, spacing, lods, sharded, quantization_bits) -> _Frame:
    """write_precomputed's arguments checked (ValueError) and made into a _Frame (also what
    distributed.write_label_meshes checks before its run)."""
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
    if lods is None:
        if sharded or quantization_bits != 16:
            raise ValueError("sharded and quantization_bits are for the multi-resolution format: give lods=N")
        lods = 0
    elif isinstance(lods, bool) or not isinstance(lods, (int, np.integer)) or not 1 <= lods <= 10:
        raise ValueError(f"lods must be an int from 1 to 10, not {lods!r}")
    if sharded not in (False, True, "murmurhash3_x86_128", "identity"):
        raise ValueError(f"sharded must be False, True, 'murmurhash3_x86_128' or 'identity', not {sharded!r}")
    if quantization_bits not in (10, 16):
        raise ValueError(f"quantization_bits must be 10 or 16, not {quantization_bits!r}")
    order = [0, 1, 2] if axes == "xyz" else [2, 1, 0]  # Neuroglancer's axis r is column order[r]
    # The multi-resolution format stores voxel units (its grid lies off the voxel lattice,
    # docs/python.md): the vertices divided by the spacing, the transform scaled back.
    scale = np.ones(3)
    if lods and spacing is not None:
        scale = np.asarray(s)
    linear = [[k * scale[c] if c == order[r] else 0.0 for c in range(3)] for r in range(3)]
    offset = [k * shift[order[r]] for r in range(3)]
    hashing = {False: 0, True: 1, "murmurhash3_x86_128": 1, "identity": 2}[sharded]
    return _Frame(linear, offset, scale, int(lods), int(quantization_bits), hashing)
