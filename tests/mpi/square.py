"""Unstructured gmsh nodes on the unit square for the MPI scripts, meshed on rank 0 and
broadcast."""
import dolfinx_solver  # noqa: F401
import gmsh

from rkfx.geometry.gmsh_nodes import from_gmsh
from rkfx.geometry.particles import Particles


def unit_square(comm, h: float, parts: dict[str, list[int]]) -> Particles:
    """Nodes of spacing ~h; ``parts`` names boundary parts by side (0 bottom, 1 right, 2 top, 3 left)."""
    if comm.rank == 0:
        gmsh.initialize(interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        geo = gmsh.model.geo
        pts = [geo.addPoint(x, y, 0, h) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
        lines = [geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
        surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        for name, sides in parts.items():
            gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, [lines[i] for i in sides]), name)
        gmsh.model.addPhysicalGroup(2, [surf])
        gmsh.model.mesh.generate(2)
    p = from_gmsh(gmsh.model if comm.rank == 0 else None, comm=comm)
    if comm.rank == 0:
        gmsh.finalize()
    return p
