"""A field of a ParaView time series rendered to a PNG, off-screen (no display needed).

    python -m rkfx.output.render FILE.pvd --field damage [--time T] [--clim LO HI] [--out FILE.png]
                                 [--title TEXT] [--segment X0 Y0 X1 Y1] [--view xy|iso|iso-]

Reads the ``.pvd`` index that ``--vtk`` writes (``rkfx.output.paraview``, dolfinx's VTK files),
picks the step at ``--time`` (default: the last), colours the cells (or points) by the field and
writes the picture, viewed from +z with the mesh's x-y extent filling the frame (``--view xy``),
or, for a solid, from the direction (1, 1, 1) (``--view iso``) or (-1, -1, -1) (``--view iso-``:
e.g. the symmetry planes of an octant) with its feature edges drawn.
"""
import argparse
import sys
from pathlib import Path

from rkfx.errors import InputError

VIEWS = ("xy", "iso", "iso-")


def render(pvd: Path, field: str, out: Path, time: float | None = None, clim=None, cmap: str = "magma_r",
           title: str | None = None, size=(1200, 1000), segments=(), view: str = "xy") -> Path:
    """Render ``field`` of the series ``pvd`` at ``time`` [s] (default: the last) to ``out``;
    ``segments`` ``((x0, y0), (x1, y1))`` [m] are drawn as black lines (e.g. a pre-existing crack);
    ``view``: ``xy`` (from +z), ``iso`` or ``iso-`` (a solid from (1, 1, 1) or (-1, -1, -1)).

    Raises:
        InputError: No such file, or the step holds no field of that name.
    """
    import pyvista as pv  # noqa: PLC0415  (an output dependency)

    pv.OFF_SCREEN = True
    from vtkmodules.vtkCommonCore import vtkLogger  # noqa: PLC0415

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # no "bad X server" note: no display is needed
    pvd = Path(pvd)
    if view not in VIEWS:
        raise InputError(f"view {view!r}: choose xy (from +z), iso or iso- (a solid from (1, 1, 1) or (-1, -1, -1))")
    if not pvd.is_file():
        raise InputError(f"{pvd}: no such file; give the .pvd a --vtk run wrote (OUT/vtk/*.pvd)")
    reader = pv.get_reader(str(pvd))
    times = reader.time_values
    reader.set_active_time_value(times[-1] if time is None else min(times, key=lambda t: abs(t - time)))
    mesh = reader.read()[0]
    names = list(mesh.cell_data.keys()) + list(mesh.point_data.keys())
    if field not in names:
        raise InputError(f"{pvd.name} has no field {field!r}; choose from {', '.join(names)}")
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    plotter.add_mesh(mesh, scalars=field, cmap=cmap, clim=clim, show_edges=False, lighting=False,
                     scalar_bar_args={"title": field, "color": "black", "vertical": True})
    outline = mesh.extract_surface(algorithm="dataset_surface").clean().extract_feature_edges(
        boundary_edges=view == "xy", feature_edges=view != "xy", manifold_edges=False, non_manifold_edges=False)
    plotter.add_mesh(outline, color="black", line_width=2)
    for a, b in segments:
        plotter.add_mesh(pv.Line((*a, 0.01), (*b, 0.01)), color="black", line_width=4)
    if title:
        plotter.add_text(title, font_size=12, color="black")
    if view == "xy":
        plotter.view_xy()
    else:
        plotter.view_vector((1, 1, 1) if view == "iso" else (-1, -1, -1), viewup=(0, 0, 1))
    plotter.enable_parallel_projection()
    plotter.camera.zoom(1.05 if view == "xy" else 0.9)  # a solid's corners stay clear of the title
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(out))
    plotter.close()
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rkfx.output.render", description=__doc__.splitlines()[0])
    parser.add_argument("pvd", type=Path, help="the .pvd time index")
    parser.add_argument("--field", required=True, help="cell or point field, e.g. damage")
    parser.add_argument("--time", type=float, default=None, help="time [s] (default: the last step)")
    parser.add_argument("--clim", type=float, nargs=2, default=None, metavar=("LO", "HI"), help="colour range")
    parser.add_argument("--cmap", default="magma_r", help="matplotlib colour map")
    parser.add_argument("--title", default=None, help="text in the upper left corner")
    parser.add_argument("--segment", type=float, nargs=4, action="append", default=[],
                        metavar=("X0", "Y0", "X1", "Y1"), help="draw a line [m], e.g. a pre-existing crack")
    parser.add_argument("--view", choices=VIEWS, default="xy",
                        help="from +z (xy, default), or a solid from (1, 1, 1) (iso) or (-1, -1, -1) (iso-)")
    parser.add_argument("--out", type=Path, default=None, help="PNG file (default: beside the .pvd)")
    args = parser.parse_args(argv)
    out = args.out or args.pvd.with_name(f"{args.pvd.stem}_{args.field}.png")
    try:
        path = render(args.pvd, args.field, out, args.time, args.clim, args.cmap, args.title,
                      segments=[((x0, y0), (x1, y1)) for x0, y0, x1, y1 in args.segment], view=args.view)
    except InputError as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 2
    print(f"figure:  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
