// A quarter of a block for the three-dimensional Hertz problem (examples/hertz_3d.toml),
// included by hertz_3d_lower.geo (depth = -1) and hertz_3d_upper.geo (depth = 1):
// [0, L] x [0, L] in the plane of contact, z from 0 to `depth`. The contact face z = 0 is
// graded towards the origin, where the contact zone is; both bodies use the same grading, so
// their contact faces are the same grid of quadrilaterals (matching meshes). Structured
// (transfinite) 8-node hexahedra. `h` is the size of the cells at the origin.
DefineConstant[ h = 0.01 ];
L = 1.0;
growth = 1.2;

// Cells along x and y: the first of size h, growing by `growth` until they span L.
cells = Ceil(Log(1 + L * (growth - 1) / h) / Log(growth));
// Cells along z: the same first size and growth, over |depth|.
layers = Ceil(Log(1 + Fabs(depth) * (growth - 1) / h) / Log(growth));

Point(1) = {0, 0, 0};
Point(2) = {L, 0, 0};
Point(3) = {L, L, 0};
Point(4) = {0, L, 0};
Point(5) = {0, 0, depth};
Point(6) = {L, 0, depth};
Point(7) = {L, L, depth};
Point(8) = {0, L, depth};
// In-plane lines run away from the origin's axes (x and y from 0 to L), vertical lines away
// from the contact face, so that one progression grades every one of them the same way.
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {4, 3};
Line(4) = {1, 4};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {8, 7};
Line(8) = {5, 8};
Line(9) = {1, 5};
Line(10) = {2, 6};
Line(11) = {3, 7};
Line(12) = {4, 8};
Transfinite Line{1, 2, 3, 4, 5, 6, 7, 8} = cells + 1 Using Progression growth;
Transfinite Line{9, 10, 11, 12} = layers + 1 Using Progression growth;

Curve Loop(1) = {1, 2, -3, -4};    // z = 0, the contact face
Curve Loop(2) = {5, 6, -7, -8};    // z = depth, the far face
Curve Loop(3) = {4, 12, -8, -9};   // x = 0
Curve Loop(4) = {1, 10, -5, -9};   // y = 0
Curve Loop(5) = {2, 11, -6, -10};  // x = L
Curve Loop(6) = {3, 11, -7, -12};  // y = L
For face In {1:6}
  Plane Surface(face) = {face};
EndFor
Transfinite Surface{1:6};
Recombine Surface{1:6};
Surface Loop(1) = {1:6};
Volume(1) = {1};
Transfinite Volume{1};
Recombine Volume{1};

Physical Volume("body") = {1};
Physical Surface("contact") = {1};
Physical Surface("far") = {2};
Physical Surface("symmetry_x") = {3};
Physical Surface("symmetry_y") = {4};
Physical Surface("side_x") = {5};
Physical Surface("side_y") = {6};
