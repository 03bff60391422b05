"""Mesh files of a URDF's ``<collision>`` elements, read as convex hulls (issue 27).

A URDF names a mesh by ``package://PKG/path``, ``file:///abs/path`` or a path relative to the
URDF file.  ``package://PKG/...`` is looked for, in order, in the ``package_dirs`` given
(each either the package folder ``PKG`` itself or a folder holding it), in the folders of the
``ROS_PACKAGE_PATH`` environment variable, and in the URDF's own folder and the folders above
it (a URDF inside its package, as ROS lays them out).

The file is read with trimesh (STL, OBJ, PLY, OFF, GLB; DAE with pycollada), its vertices
multiplied by the ``scale`` and reduced to those of their convex hull (scipy's Qhull).  A
clearance against the hull never exceeds the one against the mesh: the hull contains it.
trimesh comes with the ``mesh`` extra (``pip install 'jointlock[mesh]'``).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..bounds import shown
from ..errors import ModelError

#: What to do with a URDF's ``<mesh>`` collision elements: read each as its convex hull, or
#: leave them out (the links they belong to are then geometry-blind, and the model's
#: description says how many were left out).
MESH_MODES = ("convex", "skip")

def _named(path: str | Path) -> str:
    """A mesh file in a message: its name whole, its folder shortened."""
    path = Path(path)
    return f"{path.name!r} (in {shown(str(path.parent))})"


def resolve_mesh(filename: str, urdf_dir: Path | None, package_dirs: Sequence[str | Path] = ()) -> Path:
    """The file a URDF's ``<mesh filename>`` names (see the module), or a
    :class:`~jointlock.errors.ModelError` saying where it was looked for."""
    if filename.startswith("file://"):
        path = Path(filename[len("file://") :])
        if path.is_file():
            return path
        raise ModelError(f"mesh file {shown(filename)} not found")
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        roots = [Path(p) for p in package_dirs]
        roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        if urdf_dir is not None:
            roots += [urdf_dir, *urdf_dir.resolve().parents]
        for root in roots:
            for candidate in ((root / rest) if root.name == package else None, root / package / rest):
                if candidate is not None and candidate.is_file():
                    return candidate
        raise ModelError(
            f"mesh file {shown(filename)} not found: package {shown(package)} is not in package_dirs, "
            "ROS_PACKAGE_PATH or a folder above the URDF (give its folder in package_dirs)"
        )
    path = Path(filename)
    if not path.is_absolute() and urdf_dir is not None:
        path = urdf_dir / path
    if path.is_file():
        return path
    raise ModelError(f"mesh file {shown(filename)} not found (looked for {_named(path)})")


def hull_vertices(path: Path, scale: ArrayLike = (1.0, 1.0, 1.0)) -> np.ndarray:
    """(V, 3) the vertices of the convex hull of the mesh in ``path`` [m] after ``scale`` (3,)."""
    stat = path.stat()
    key = (str(path.resolve()), (stat.st_mtime_ns, stat.st_size), tuple(float(s) for s in np.asarray(scale, dtype=float).reshape(3)))
    return _hull(*key).copy()


@functools.lru_cache(maxsize=256)
def _hull(path: str, stamp: tuple[int, int], scale: tuple[float, ...]) -> np.ndarray:
    del stamp  # part of the key: an edited file is read again
    try:
        import trimesh
    except ImportError:
        raise ModelError(f"reading the mesh {_named(path)} needs trimesh: pip install 'jointlock[mesh]'") from None
    try:
        mesh = trimesh.load(path, force="mesh", process=False)
        vertices = np.asarray(getattr(mesh, "vertices", ()), dtype=float)
    except Exception as exc:  # trimesh raises many kinds (format, parser, missing plugin)
        raise ModelError(f"mesh {_named(path)} could not be read ({type(exc).__name__}: {str(exc)[:120]})") from None
    if vertices.ndim != 2 or vertices.shape[0] < 4 or not np.all(np.isfinite(vertices)):
        raise ModelError(f"mesh {_named(path)} has no solid to read (fewer than 4 finite vertices)")
    vertices = vertices * np.asarray(scale)
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(vertices)
    except QhullError:
        raise ModelError(f"mesh {_named(path)} is flat (no volume): it has no convex hull to collide with") from None
    out = vertices[np.sort(hull.vertices)]
    out.setflags(write=False)
    return out
