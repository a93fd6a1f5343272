// The bottom of a cup around a floating block (floating_body_test): [1, 2] x [-1, 0] below the
// middle block of row_block_middle.geo ([1, 2] x [0, 1]), a structured quadrilateral mesh of
// n x n cells with the same nodes on their common edge.
// Boundaries: bottom (y = -1), top (y = 0), left (x = 1), right (x = 2).
DefineConstant[ h = 0.125 ];
n = Round(1 / h) + 1;
Point(1) = {1, -1, 0, h};
Point(2) = {2, -1, 0, h};
Point(3) = {2, 0, 0, h};
Point(4) = {1, 0, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Transfinite Curve{1, 2, 3, 4} = n;
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Surface{1};
Recombine Surface{1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
