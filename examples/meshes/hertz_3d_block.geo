// A quarter of a block for the three-dimensional Hertz problem (examples/hertz_3d.toml),
// included by hertz_3d_lower.geo (depth = -1) and hertz_3d_upper.geo (depth = 1):
// [0, L] x [0, L] in the plane of contact, z from 0 to `depth`, in 8-node hexahedra
// (structured). The contact face z = 0 has square cells of size h on [0, c] x [0, c], which
// holds the contact zone, growing by `growth` per cell beyond; the layers grow the same way
// away from the contact face. Both bodies use the same grid on the contact face (matching
// meshes, node-to-node contact).
DefineConstant[ h = 0.01 ];
L = 1.0;
c = 0.15;
growth = 1.2;

inner = Round(c / h) > 2 ? Round(c / h) : 2;
// Cells from c to L (and layers over |depth|): the first of size h, each `growth` times larger.
outer = Ceil(Log(1 + (L - c) * (growth - 1) / h) / Log(growth));
layers = Ceil(Log(1 + Fabs(depth) * (growth - 1) / h) / Log(growth));

Point(1) = {0, 0, 0};
Point(2) = {c, 0, 0};
Point(3) = {L, 0, 0};
Point(4) = {0, c, 0};
Point(5) = {c, c, 0};
Point(6) = {L, c, 0};
Point(7) = {0, L, 0};
Point(8) = {c, L, 0};
Point(9) = {L, L, 0};
Line(1) = {1, 2};  // along x
Line(2) = {2, 3};
Line(3) = {4, 5};
Line(4) = {5, 6};
Line(5) = {7, 8};
Line(6) = {8, 9};
Line(7) = {1, 4};  // along y
Line(8) = {4, 7};
Line(9) = {2, 5};
Line(10) = {5, 8};
Line(11) = {3, 6};
Line(12) = {6, 9};
Transfinite Line{1, 3, 5, 7, 9, 11} = inner + 1;
// Every outer line runs away from the square [0, c]^2, so one progression grades them all.
Transfinite Line{2, 4, 6, 8, 10, 12} = outer + 1 Using Progression growth;
Curve Loop(1) = {1, 9, -3, -7};
Curve Loop(2) = {2, 11, -4, -9};
Curve Loop(3) = {3, 10, -5, -8};
Curve Loop(4) = {4, 12, -6, -10};
For face In {1:4}
  Plane Surface(face) = {face};
EndFor
Transfinite Surface{1:4};
Recombine Surface{1:4};

// Layers of thickness h growth^k, k = 0 .. layers - 1, scaled to span |depth| exactly.
total = h * (growth^layers - 1) / (growth - 1);
For k In {1:layers}
  counts[k - 1] = 1;
  heights[k - 1] = h * (growth^k - 1) / (growth - 1) / total;
EndFor
Extrude {0, 0, depth} { Surface{1:4}; Layers{counts[], heights[]}; Recombine; }

low = depth < 0 ? depth : 0;
high = depth < 0 ? 0 : depth;
e = 1e-6;
Physical Volume("body") = Volume{:};
Physical Surface("contact") = {1:4};
Physical Surface("far") = Surface In BoundingBox{-e, -e, depth - e, L + e, L + e, depth + e};
Physical Surface("symmetry_x") = Surface In BoundingBox{-e, -e, low - e, e, L + e, high + e};
Physical Surface("symmetry_y") = Surface In BoundingBox{-e, -e, low - e, L + e, e, high + e};
Physical Surface("side_x") = Surface In BoundingBox{L - e, -e, low - e, L + e, L + e, high + e};
Physical Surface("side_y") = Surface In BoundingBox{-e, L - e, low - e, L + e, L + e, high + e};
