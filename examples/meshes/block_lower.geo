// Lower block [-1, 1] x [-1, 0]; its top edge (y = 0) is the contact boundary.
// h: element size (refine with mesh_size in the case file). The contact edge is a
// transfinite curve so that the upper block (block_upper.geo) has the same nodes on it.
DefineConstant[ h = 0.1 ];
n = Round(2 / h) + 1;

Point(1) = {-1, -1, 0, h};
Point(2) = { 1, -1, 0, h};
Point(3) = { 1,  0, 0, h};
Point(4) = {-1,  0, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {4, 3};   // contact edge, oriented -x to +x in both blocks
Line(4) = {4, 1};
Transfinite Curve{3} = n;
Curve Loop(1) = {1, 2, -3, 4};
Plane Surface(1) = {1};

Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("contact") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
