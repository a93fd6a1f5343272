// The bottom block of a vertical stack of three unit squares (floating_body_test): [0, 1] x [0, 0 + 1],
// a structured quadrilateral mesh of n x n cells, so that neighbouring blocks have the same nodes
// on their common edges (node-to-node contact).
// Boundaries: bottom (y = 0), top (y = 0 + 1), left (x = 0), right (x = 1).
DefineConstant[ h = 0.125 ];
n = Round(1 / h) + 1;
y0 = 0;
Point(1) = {0, y0, 0, h};
Point(2) = {1, y0, 0, h};
Point(3) = {1, y0 + 1, 0, h};
Point(4) = {0, y0 + 1, 0, h};
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
