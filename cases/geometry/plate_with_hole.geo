// Quarter of a square plate [0, L] x [0, L] with a quarter hole of radius a at the origin.
//
// The geometry of the Kirsch benchmark (python -m rkfx.cases.plate_with_hole builds the same
// model with the gmsh Python API). Physical curves: "left" (x = 0) and "bottom" (y = 0), the
// symmetry planes; "right" (x = L) and "top" (y = L), loaded by the exact Kirsch tractions;
// "hole" (r = a), traction free. Physical surface: "domain".
//
// Mesh size lc [m] at the outer corners, lc / 3 on the hole (graded in between). Override on
// the command line (gmsh -setnumber lc 0.2 ...) or cap the sizes with Mesh.MeshSizeMax, which is
// what rkfx.geometry.gmsh_nodes.from_geo(path, mesh_size=h) does: sizes below h (the hole) are kept.
DefineConstant[
  a = {1.0, Name "Parameters/hole radius a [m]"},
  L = {5.0, Name "Parameters/plate half-width L [m]"},
  lc = {0.5, Name "Parameters/mesh size lc [m]"}
];

Point(1) = {0, 0, 0, lc};        // hole centre (arc centre only)
Point(2) = {a, 0, 0, lc / 3};
Point(3) = {L, 0, 0, lc};
Point(4) = {L, L, 0, lc};
Point(5) = {0, L, 0, lc};
Point(6) = {0, a, 0, lc / 3};

Line(1) = {2, 3};                // bottom
Line(2) = {3, 4};                // right
Line(3) = {4, 5};                // top
Line(4) = {5, 6};                // left
Circle(5) = {6, 1, 2};           // hole

Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("hole") = {5};
Physical Surface("domain") = {1};

Mesh.ElementOrder = 1;
Mesh.RecombineAll = 0;
