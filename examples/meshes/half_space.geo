// A block [-2, 2] x [-2, 0] standing for the half-space under the cylinder: its top edge is the
// contact boundary where |x| <= 0.5 ("contact", refined to h / 14, so its nodes are not those
// of cylinder.geo), free elsewhere ("top_free"); clamped at the bottom.
DefineConstant[ h = 0.1 ];
fine = h / 14;
c = 0.5;

Point(1) = {-2, -2, 0, 4 * h};
Point(2) = { 2, -2, 0, 4 * h};
Point(3) = { 2,  0, 0, 2 * h};
Point(4) = { c,  0, 0, fine};
Point(5) = {-c,  0, 0, fine};
Point(6) = {-2,  0, 0, 2 * h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};

Physical Curve("bottom") = {1};
Physical Curve("sides") = {2, 6};
Physical Curve("contact") = {4};
Physical Curve("top_free") = {3, 5};
Physical Surface("half_space") = {1};
