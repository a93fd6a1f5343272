// The left block of a row of three unit squares along x (many_bodies_test): [0, 0 + 1] x [0, 1],
// a structured quadrilateral mesh of n x n cells, so that the row is mirror symmetric about
// x = 1.5 and neighbouring blocks have the same nodes on their common edges.
// Boundaries: bottom (y = 0), top (y = 1), left (x = 0), right (x = 0 + 1).
DefineConstant[ h = 0.125 ];
n = Round(1 / h) + 1;
x0 = 0;
Point(1) = {x0, 0, 0, h};
Point(2) = {x0 + 1, 0, 0, h};
Point(3) = {x0 + 1, 1, 0, h};
Point(4) = {x0, 1, 0, h};
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
