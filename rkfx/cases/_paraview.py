"""ParaView files of the cases' runs (``--vtk``): the glue between a case's solution and the writers.

RKPM runs write their particles and nodal cells through ``rkfx.output.paraview``; FEM runs pass a
``fem_baselines.paraview.FemSeries`` to their solver, which writes at the same output times.
"""
from pathlib import Path

import numpy as np

from rkfx.models.damage_dynamics import Frames
from rkfx.output.paraview import FieldSeries, MeshSeries, among, nodal_cells


def write_biot(folder: Path, label: str, particles, sol, elastic, comm=None, times=None) -> FieldSeries:
    """A u-p solution (``rkfx.models.poroelasticity.BiotSolution``) at its output times (or at
    those of them in ``times`` [s]): displacement [m], pressure [Pa], strain tensor [-] and
    effective stress D eps(u^h) [Pa] at the particles, with the particles' median-dual cells (in
    3-D: their tetrahedra, the fields as point data)."""
    dim = particles.x.shape[1]
    cells = nodal_cells(particles) if dim == 2 else particles.tetrahedra
    series = FieldSeries(folder, label, particles.x, cells=cells, comm=comm)
    if series.writes:
        u, p, eps = sol.displacement(particles.x), sol.pressure(particles.x), sol.strain(particles.x)
        D = elastic.voigt(dim)
        # Engineering shears to the tensor's components (eps_xy = gamma_xy / 2).
        halve = [1.0, 1.0, 0.5] if dim == 2 else [1.0, 1.0, 1.0, 0.5, 0.5, 0.5]
        for k, t in enumerate(sol.times):
            if times is not None and not among(t, times):
                continue
            series.write(t, displacement=u[k], pressure=p[k], strain=eps[k] * halve, effective_stress=eps[k] @ D.T)
    return series


def write_elastic(folder: Path, label: str, particles, sol, material, comm=None) -> FieldSeries:
    """A static solution (``rkfx.models.elastostatics.ElasticSolution``) at t = 0: displacement
    [m], strain tensor [-] and stress D eps(u^h) [Pa] at the particles, with their median-dual cells."""
    series = FieldSeries(folder, label, particles.x, cells=nodal_cells(particles), comm=comm)
    if series.writes:
        grad = sol.gradient(particles.x)                                    # (n, 2, 2)
        voigt = np.column_stack([grad[:, 0, 0], grad[:, 1, 1], grad[:, 0, 1] + grad[:, 1, 0]])
        series.write(0.0, displacement=sol.displacement(particles.x), strain=voigt * [1.0, 1.0, 0.5],
                     stress=voigt @ material.D().T)
    return series


def snapshot(folder: Path, label: str, points, cells, t: float, comm=None, **fields) -> FieldSeries:
    """One time ``t`` [s] of particle fields (see ``FieldSeries.write`` for their shapes)."""
    series = FieldSeries(folder, label, points, cells=cells, comm=comm)
    series.write(t, **fields)
    return series


def damage_frames(folder: Path | None, label: str, points, cells, values, comm=None,
                  count: int = 20) -> Frames | None:
    """The frame writer of a damage run (``rkfx.models.damage_dynamics.Frames``) on particles (with
    their ``nodal_cells``), or ``None`` without ``--vtk``: damage, crack opening w / w_c,
    displacement u^h [m] and velocity [m/s] at ``count`` times and the end. ``values``: the
    shape functions at the particles, shape ``(n, n)`` (the run's coefficients are not nodal values)."""
    if folder is None:
        return None
    series = FieldSeries(folder, label, points, cells=cells, comm=comm)

    def write(t, damage, crack_opening, displacement, velocity):
        if series.writes:
            series.write(t, damage=damage, crack_opening=crack_opening, displacement=values @ displacement,
                         velocity=values @ velocity)

    return Frames(write, count)


def crack_band_frames(folder: Path | None, label: str, comm=None, count: int = 20):
    """For ``frames=`` of the crack-band FEM runs: ``(x, triangles) -> Frames`` writing damage and
    opening per element, displacement and velocity per vertex (rank 0 of ``comm`` writes; the
    fields reach it gathered); ``None`` without ``--vtk``."""
    if folder is None:
        return None

    def frames(x, triangles) -> Frames:
        series = MeshSeries(folder, label, x, triangles, comm=comm)

        def write(t, damage, crack_opening, displacement, velocity):
            series.write(t, point_data={"displacement": displacement, "velocity": velocity},
                         cell_data={"damage": damage, "crack_opening": crack_opening})

        return Frames(write, count)

    return frames


def path_frames(targets, count: int = 11) -> list[float]:
    """``count`` tip displacements spread over a load path's ``targets`` (some of the targets
    themselves, so that asking for snapshots there leaves the path as it is)."""
    targets = np.asarray(targets, float)
    return sorted({float(u) for u in targets[np.linspace(0, len(targets) - 1, count).round().astype(int)]})


def write_path(write, snapshots: dict, at) -> None:
    """``write(u_T, stress, damage)`` for each of the displacements ``at`` that the load path's
    ``snapshots`` (u_T -> (stress, damage, ...)) reached."""
    for u in at:
        if u in snapshots:
            write(u, snapshots[u][0], snapshots[u][1])


def fem_series(folder: Path | None, label: str, mesh, times=None):
    """The FEM writer of one run (keeping the writes at ``times`` [s], or all), or ``None`` without
    ``--vtk``."""
    if folder is None:
        return None
    from fem_baselines.paraview import FemSeries  # noqa: PLC0415  (dolfinx only for FEM runs)

    return FemSeries(folder, label, mesh, times)
