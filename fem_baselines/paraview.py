"""FEM fields through time for ParaView, by dolfinx's VTK writer.

``FemSeries(folder, name, mesh)`` opens ``FOLDER/NAME.pvd``; each ``write(t, **functions)``
stores the functions at time ``t`` under their keyword names (one ``.vtu`` per time and rank,
listed in the ``.pvd``). Continuous fields are written at the mesh vertices (a P2 field is
interpolated onto P1), cellwise constants (DG0, e.g. damage) as cell data. The ``.pvd`` index is
complete after every step, so a run that stops keeps every step it wrote.

    series = FemSeries("out/vtk", "fem-p2", mesh)
    series.write(t, displacement=u, pressure=p)
    series.close()
"""
from pathlib import Path

import numpy as np

import dolfinx_solver  # noqa: F401  (MPI first)
from dolfinx import fem, io

from rkfx.output.paraview import among, file_stem


class FemSeries:
    """One VTK time series of a dolfinx mesh (see the module docstring).

    Args:
        folder: Output folder (created on rank 0).
        name: File name without suffix, e.g. the run's method label.
        mesh: The dolfinx mesh the functions live on.
        times: The times to keep [s]: a ``write`` at any other time is skipped (a solver that
            records every step writes only these). ``None``: every write is kept.
    """

    def __init__(self, folder, name: str, mesh, times=None):
        folder = Path(folder)
        if mesh.comm.rank == 0:
            folder.mkdir(parents=True, exist_ok=True)
        mesh.comm.barrier()
        self.path = folder / f"{file_stem(name)}.pvd"
        self.mesh = mesh
        self._file = io.VTKFile(mesh.comm, str(self.path), "w")
        self._spaces: dict[tuple, fem.FunctionSpace] = {}
        self._out: dict[str, fem.Function] = {}
        self.times = None if times is None else np.asarray(times, float)

    def _target(self, key: str, f: fem.Function) -> fem.Function:
        """The vertex (P1) or cell (DG0) function ``f`` is written through."""
        if key not in self._out:
            element = f.function_space.ufl_element()
            shape = f.function_space.value_shape
            cellwise = element.embedded_superdegree == 0
            spec = ("DG", 0, tuple(shape)) if cellwise else ("Lagrange", 1, tuple(shape))
            if spec not in self._spaces:
                self._spaces[spec] = fem.functionspace(self.mesh, (spec[0], spec[1], spec[2] or ()))
            out = fem.Function(self._spaces[spec], name=key)
            self._out[key] = out
        return self._out[key]

    def write(self, time: float, **functions: fem.Function) -> None:
        """Write the functions at ``time`` [s] (unless ``times`` leaves it out)."""
        if self.times is not None and not among(time, self.times):
            return
        out = []
        for key, f in functions.items():
            out.append(self._target(key, f))
            out[-1].interpolate(f)
        self._file.write_function(out, float(time))

    def close(self) -> None:
        """Close the file (also at garbage collection)."""
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
