"""ParaView files of the cases' runs (``--vtk``): the glue between a case's solution and the writers.

RKPM runs write their particles and nodal cells through ``rkfx.output.paraview``; FEM runs pass a
``fem_baselines.paraview.FemSeries`` to their solver, which writes at the same output times.
"""
from pathlib import Path

from rkfx.output.paraview import FieldSeries, nodal_cells


def write_biot(folder: Path, label: str, particles, sol, elastic, comm=None) -> FieldSeries:
    """A u-p solution (``rkfx.models.poroelasticity.BiotSolution``) at its output times:
    displacement [m], pressure [Pa], strain tensor [-] and effective stress D eps(u^h) [Pa] at the
    particles, with the particles' median-dual cells."""
    series = FieldSeries(folder, label, particles.x, cells=nodal_cells(particles), comm=comm)
    if series.writes:
        u, p, eps = sol.displacement(particles.x), sol.pressure(particles.x), sol.strain(particles.x)
        D = elastic.D()
        for k, t in enumerate(sol.times):
            tensor = eps[k] * [1.0, 1.0, 0.5]  # engineering gamma_xy to the tensor's eps_xy
            series.write(t, displacement=u[k], pressure=p[k], strain=tensor, effective_stress=eps[k] @ D.T)
    return series


def fem_series(folder: Path | None, label: str, mesh):
    """The FEM writer of one run, or ``None`` without ``--vtk``."""
    if folder is None:
        return None
    from fem_baselines.paraview import FemSeries  # noqa: PLC0415  (dolfinx only for FEM runs)

    return FemSeries(folder, label, mesh)
