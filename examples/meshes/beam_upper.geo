// Cantilever beam [-1, 1] x [0, 0.25] lying on the lower block; its bottom edge (y = 0) is
// the contact boundary (same nodes as block_lower.geo for the same h).
DefineConstant[ h = 0.1 ];
n = Round(2 / h) + 1;

Point(1) = {-1, 0, 0, h};
Point(2) = { 1, 0, 0, h};
Point(3) = { 1, 0.25, 0, h};
Point(4) = {-1, 0.25, 0, h};
Line(1) = {1, 2};   // contact edge, oriented -x to +x
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Transfinite Curve{1} = n;
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Physical Curve("contact") = {1};
Physical Curve("free_end") = {2};
Physical Curve("top") = {3};
Physical Curve("clamped_end") = {4};
Physical Surface("beam") = {1};
