"""Node sets and their nodal domains: particles from grids, point clouds and gmsh models; median-dual and grid cells."""
