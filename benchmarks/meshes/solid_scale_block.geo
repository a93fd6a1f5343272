// A quarter block for the 3D scale benchmark (benchmarks/solid_scale_benchmark.py): the sphere
// on a flat of examples/hertz_3d.toml, but with the number of cells set directly, so that the
// DOFs can be chosen (the graded mesh of examples/meshes/hertz_3d_block.geo grows only with
// log(1/h)). Included by solid_scale_lower.geo (depth = -1) and solid_scale_upper.geo
// (depth = 1): [0, L] x [0, L] in the plane of contact, z from 0 to `depth`.
//
// `h` is the nominal cell size: n = Round(L / h) cells along x, along y and along z, so a body
// has n^3 structured (transfinite) 8-node hexahedra and (n + 1)^3 nodes. The cells are mildly
// graded towards the origin, where the contact zone is, and towards the contact face z = 0:
// along every line the largest cell is `grading` times the smallest (a geometric progression
// of ratio grading^(1 / (n - 1))). Both bodies use the same grid on z = 0 (matching meshes,
// node-to-node contact).
DefineConstant[ h = 0.1 ];
DefineConstant[ grading = 8 ];
L = 1.0;

n = Round(L / h);
If (n < 2)
  n = 2;
EndIf
ratio = grading^(1 / (n - 1));

Point(1) = {0, 0, 0};
Point(2) = {L, 0, 0};
Point(3) = {L, L, 0};
Point(4) = {0, L, 0};
Point(5) = {0, 0, depth};
Point(6) = {L, 0, depth};
Point(7) = {L, L, depth};
Point(8) = {0, L, depth};
// In-plane lines run away from the origin's axes, vertical lines away from the contact face,
// so that one progression grades every one of them the same way.
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
Transfinite Line{1:12} = n + 1 Using Progression ratio;

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
