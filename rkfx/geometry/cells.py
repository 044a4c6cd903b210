"""The default nodal cells of a particle set, in either dimension.

2-D particles take the median-dual cells of their triangulation (``rkfx.geometry.nodal_domains``);
3-D particles the box cells of their tensor grid when they have one (the seed's 13-point rule,
§3.3.2) and otherwise the median-dual cells of their tetrahedralization
(``rkfx.geometry.nodal_cells3d``).
"""
import numpy as np


def nodal_cells(p, nodes: np.ndarray | None = None):
    """The nodal cells of ``p`` (``Particles`` or ``Particles3D``).

    Args:
        p: The particles.
        nodes: Build just the cells around these nodes (a rank's own; see
            ``rkfx.geometry.nodal_domains.nodal_domains`` and ``rkfx.geometry.nodal_cells3d``).
    """
    if p.x.shape[1] == 2:
        from rkfx.geometry.nodal_domains import nodal_domains  # noqa: PLC0415

        return nodal_domains(p, nodes=nodes)
    from rkfx.geometry.nodal_cells3d import box_cells, median_dual_cells  # noqa: PLC0415

    return box_cells(p, nodes) if p.grid is not None else median_dual_cells(p, nodes)


def cell_measures(cells) -> tuple[np.ndarray, np.ndarray]:
    """(measure of each cell, measure of each subcell): areas [m^2] in 2-D, volumes [m^3] in 3-D."""
    if hasattr(cells, "volume"):
        return cells.volume, cells.subcell_volume
    return cells.area, cells.subcell_area
