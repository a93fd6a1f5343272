// Lower block [0, 1] x [-0.5, 0] in triangles; its top edge (y = 0) is the contact boundary,
// with Round(1 / h) segments: the upper block (patch_upper.geo) has other nodes on it.
DefineConstant[ h = 0.1 ];
n = Round(1 / h) + 1;

Point(1) = {0, -0.5, 0, h};
Point(2) = {1, -0.5, 0, h};
Point(3) = {1,  0,   0, h};
Point(4) = {0,  0,   0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {4, 3};
Line(4) = {4, 1};
Transfinite Curve{3} = n;
Curve Loop(1) = {1, 2, -3, 4};
Plane Surface(1) = {1};

Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("contact") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
