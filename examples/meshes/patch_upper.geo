// Upper block [0, 1] x [0, 0.4] in quadrilaterals; its bottom edge (y = 0) is the contact
// boundary, with Round(1 / (0.7 h)) segments: not the nodes of the lower block
// (patch_lower.geo), so the two contact meshes do not match.
DefineConstant[ h = 0.1 ];
n = Round(1 / (0.7 * h)) + 1;
m = Round(0.4 / h) + 1;

Point(1) = {0, 0,   0, h};
Point(2) = {1, 0,   0, h};
Point(3) = {1, 0.4, 0, h};
Point(4) = {0, 0.4, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Transfinite Curve{1, 3} = n;
Transfinite Curve{2, 4} = m;
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Surface{1};
Recombine Surface{1};

Physical Curve("contact") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
