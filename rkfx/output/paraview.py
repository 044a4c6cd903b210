"""Particle fields through time as ParaView files: a ``.vtu`` per output time and a ``.pvd`` index.

A ``FieldSeries`` writes, for each ``write(t, **fields)``,

    FOLDER/NAME_particles_K.vtu   the particles as vertices, the fields as point data
    FOLDER/NAME_cells_K.vtu       the nodal cells as quadrilateral subcells (optional), the
                                  fields of each cell's particle as cell data

and rewrites ``NAME_particles.pvd`` / ``NAME_cells.pvd`` (the time index ParaView opens) after
every step, so a run that stops keeps every step it wrote. Fields are per particle: shape
``(n,)`` scalars, ``(n, 2)`` vectors (written with a zero z component) and ``(n, 3)`` plane
tensors in Voigt order (xx, yy, xy), written as ParaView's symmetric tensors (xx, yy, zz, xy,
yz, xz) with zero out-of-plane components. Under MPI only rank 0 writes (the fields are whole
there). 3-D particles (points ``(n, 3)``) take ``(n, 3)`` vectors and ``(n, 6)`` tensors in the
Voigt order (xx, yy, zz, yz, xz, xy), and as cells their tetrahedra ``(m, 4)``, which carry the
particles' fields as point data (``NAME_cells.pvd``: the solid, coloured continuously).

    series = FieldSeries("out/vtk", "rkpm", particles.x, cells=nodal_cells(particles))
    series.write(0.5, displacement=u, pressure=p)
    # paraview out/vtk/rkpm_particles.pvd

A ``MeshSeries`` writes fields on a mesh of triangles or quadrilaterals (vertex and cell data),
e.g. the crack-band FEM baselines' damage per element.
"""
import os
import re
from pathlib import Path

import numpy as np

from rkfx.errors import InputError
from rkfx.fracture.damage import CellGeometry, cell_geometry
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles


def file_stem(label: str) -> str:
    """A run label as a file name: ``rkpm-dpm n=150`` -> ``rkpm-dpm_n150``."""
    return str(label).replace("=", "").replace(" ", "_").replace("/", "-")


def among(time: float, times) -> bool:
    """Whether ``time`` [s] is one of ``times`` (to a relative 1e-9): the output times a writer keeps."""
    return bool(np.any(np.isclose(time, times, rtol=1e-9, atol=0.0)))


def nodal_cells(p: Particles | NodalDomains) -> CellGeometry:
    """The nodal cells of ``p`` as quadrilateral subcells (median-dual cells of particles, or grid
    cells of domains that carry their subcell vertices) for ``FieldSeries(cells=...)``."""
    return cell_geometry(p)


def _vtk_values(name: str, a: np.ndarray, n: int, dim: int = 2) -> np.ndarray:
    a = np.asarray(a, float)
    if a.shape[0] != n or a.ndim > 2:
        raise InputError(f"field {name!r} has shape {a.shape}; give one value, vector ({dim}) or Voigt tensor "
                         f"({3 if dim == 2 else 6}) per particle ({n})")
    if a.ndim == 1 or a.shape[1] == 1:
        return a.reshape(n)
    if dim == 3:
        if a.shape[1] == 3:
            return a
        if a.shape[1] == 6:  # Voigt (xx, yy, zz, yz, xz, xy) -> ParaView's (xx, yy, zz, xy, yz, xz)
            return a[:, [0, 1, 2, 5, 3, 4]]
        raise InputError(f"field {name!r} has {a.shape[1]} components; give 1, 3 (vector) or 6 "
                         "(xx, yy, zz, yz, xz, xy) in 3-D")
    if a.shape[1] == 2:
        return np.column_stack([a, np.zeros(n)])
    if a.shape[1] == 3:
        z = np.zeros(n)
        return np.column_stack([a[:, 0], a[:, 1], z, a[:, 2], z, z])
    raise InputError(f"field {name!r} has {a.shape[1]} components; give 1, 2 (vector) or 3 (xx, yy, xy)")


def pvd_times(path) -> np.ndarray:
    """The times listed in a ``.pvd`` time index, shape ``(k,)`` [s]."""
    return np.array([float(t) for t in re.findall(r'timestep="([^"]+)"', Path(path).read_text())])


def write_pvd(path: Path, entries: list[tuple[float, str]]) -> None:
    """The ParaView collection ``path`` listing ``(time, file)`` entries, replaced atomically."""
    rows = "\n".join(f'    <DataSet timestep="{t:.17g}" group="" part="0" file="{f}"/>' for t, f in entries)
    text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            f"{rows}\n  </Collection>\n</VTKFile>\n")
    tmp = path.with_suffix(".pvd.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


class FieldSeries:
    """Particle fields through time for ParaView (see the module docstring).

    Args:
        folder: Output folder (created).
        name: Prefix of the files, e.g. the run's method label.
        points: Particle coordinates, shape ``(n, 2)`` or ``(n, 3)`` [m].
        cells: The nodal cells (``nodal_cells``), or in 3-D the tetrahedra ``(m, 4)`` of the
            particles, or ``None`` to write the particles only.
        comm: MPI communicator; only its rank 0 writes. ``None``: this process writes.
    """

    def __init__(self, folder, name: str, points: np.ndarray, cells: CellGeometry | np.ndarray | None = None,
                 comm=None):
        self.folder, self.name = Path(folder), file_stem(name)
        self.points = np.asarray(points, float)
        self.cells = cells
        self.writes = comm is None or comm.rank == 0
        self.entries: dict[str, list[tuple[float, str]]] = {"particles": [], "cells": []}
        if self.writes:
            self.folder.mkdir(parents=True, exist_ok=True)

    @property
    def pvd(self) -> Path:
        """The particles' time index, the file to open in ParaView."""
        return self.folder / f"{self.name}_particles.pvd"

    def write(self, time: float, **fields: np.ndarray) -> None:
        """Write the fields at ``time`` [s] and update the time indices."""
        if not self.writes:
            return
        import meshio  # noqa: PLC0415  (an output dependency, loaded when output is asked for)

        n, dim = self.points.shape
        values = {k: _vtk_values(k, v, n, dim) for k, v in fields.items()}
        k = len(self.entries["particles"])
        xyz = self.points if dim == 3 else np.column_stack([self.points, np.zeros(n)])
        self._write(meshio.Mesh(xyz, [("vertex", np.arange(n).reshape(-1, 1))], point_data=values),
                    "particles", k, time)
        if self.cells is not None and dim == 3:
            self._write(meshio.Mesh(xyz, [("tetra", np.asarray(self.cells, np.int64))], point_data=values),
                        "cells", k, time)
        elif self.cells is not None:
            m = len(self.cells.node)
            corners = np.column_stack([self.cells.vertices.reshape(-1, 2), np.zeros(4 * m)])
            data = {key: [v[self.cells.node]] for key, v in values.items()}
            self._write(meshio.Mesh(corners, [("quad", np.arange(4 * m).reshape(m, 4))], cell_data=data),
                        "cells", k, time)

    def _write(self, mesh, kind: str, k: int, time: float) -> None:
        import meshio  # noqa: PLC0415

        file = f"{self.name}_{kind}_{k:05d}.vtu"
        meshio.write(self.folder / file, mesh, binary=True)
        self.entries[kind].append((float(time), file))
        write_pvd(self.folder / f"{self.name}_{kind}.pvd", self.entries[kind])


class MeshSeries:
    """Fields on a mesh of triangles (or quadrilaterals) through time: point data at its
    vertices, cell data on its cells, one ``NAME_K.vtu`` per time and the index ``NAME.pvd``.

    Args:
        folder: Output folder (created).
        name: Prefix of the files.
        points: Vertex coordinates, shape ``(n, 2)`` [m].
        cells: Vertex indices per cell, shape ``(m, 3)`` or ``(m, 4)``.
        comm: MPI communicator; only its rank 0 writes. ``None``: this process writes.
    """

    def __init__(self, folder, name: str, points: np.ndarray, cells: np.ndarray, comm=None):
        self.folder, self.name = Path(folder), file_stem(name)
        self.points, self.cells = np.asarray(points, float), np.asarray(cells, np.int64)
        if self.cells.ndim != 2 or self.cells.shape[1] not in (3, 4):
            raise InputError(f"cells of shape {self.cells.shape}: give (m, 3) triangles or (m, 4) quadrilaterals")
        self.writes = comm is None or comm.rank == 0
        self.entries: list[tuple[float, str]] = []
        if self.writes:
            self.folder.mkdir(parents=True, exist_ok=True)

    @property
    def pvd(self) -> Path:
        """The time index, the file to open in ParaView."""
        return self.folder / f"{self.name}.pvd"

    def write(self, time: float, point_data: dict | None = None, cell_data: dict | None = None) -> None:
        """Write the fields at ``time`` [s]: ``point_data`` per vertex, ``cell_data`` per cell
        (scalars, 2-vectors or Voigt tensors as for ``FieldSeries``)."""
        if not self.writes:
            return
        import meshio  # noqa: PLC0415

        n, m = len(self.points), len(self.cells)
        kind = "triangle" if self.cells.shape[1] == 3 else "quad"
        mesh = meshio.Mesh(np.column_stack([self.points, np.zeros(n)]), [(kind, self.cells)],
                           point_data={k: _vtk_values(k, v, n) for k, v in (point_data or {}).items()},
                           cell_data={k: [_vtk_values(k, v, m)] for k, v in (cell_data or {}).items()})
        file = f"{self.name}_{len(self.entries):05d}.vtu"
        meshio.write(self.folder / file, mesh, binary=True)
        self.entries.append((float(time), file))
        write_pvd(self.pvd, self.entries)
